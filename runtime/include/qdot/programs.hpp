// The programs of a compiled model (generated from qdot/programs.def) and the inputs of one call
// of a program. Shared by the kernel IR, the bytecode, the VM, the LLVM backend and the ABI
// adapter, so they all number and name the programs the same way.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace qdot {

/// The programs, in model-ABI order.
enum class ModelProgram : uint8_t {
#define QDOT_PROGRAM(Name, Spelling, Inputs) Name,
#include "qdot/programs.def"
};

inline constexpr const char* kModelProgramNames[] = {
#define QDOT_PROGRAM(Name, Spelling, Inputs) Spelling,
#include "qdot/programs.def"
};
inline constexpr size_t kModelProgramCount = std::size(kModelProgramNames);

/// An array with one entry per program, indexed by programIndex.
template <class T>
using PerProgram = std::array<T, kModelProgramCount>;

constexpr size_t programIndex(ModelProgram p) { return static_cast<size_t>(p); }
constexpr ModelProgram programAt(size_t i) { return static_cast<ModelProgram>(i); }
/// "parameters", "initialValues", ... (the ABI entry point).
constexpr const char* programName(ModelProgram p) { return kModelProgramNames[programIndex(p)]; }

/// The inputs a program may read (bits).
enum ProgramInput : uint32_t {
  InputTime = 1u << 0,
  InputCj = 1u << 1,
  InputY = 1u << 2,
  InputYp = 1u << 3,
  InputP = 1u << 4,
  InputGiven = 1u << 5,
  InputOverridden = 1u << 6,
};

/// The ProgramInput bits the ABI entry point of `p` passes.
constexpr uint32_t programInputs(ModelProgram p) {
  constexpr uint32_t inputs[] = {
#define QDOT_PROGRAM(Name, Spelling, Inputs) (Inputs),
#include "qdot/programs.def"
  };
  return inputs[programIndex(p)];
}

/// The inputs of one call of a program (those it does not read stay null/0). Sizes are the
/// model's: y, yp [nVariables]; p, given, overridden [nParameters].
struct ModelCall {
  double t = 0, cj = 0;
  const double* y = nullptr;
  const double* yp = nullptr;
  const double* p = nullptr;
  const double* given = nullptr;
  const uint8_t* overridden = nullptr;
  /// The program's index table X (loop offsets, Jacobian positions), for code that does not hold
  /// it itself: an executable's ahead-of-time code reads the table of the embedded module here, so
  /// that a table of millions of entries is not machine-code data (compiler/llvm/Codegen.h).
  const uint32_t* indexTable = nullptr;
};

}  // namespace qdot
