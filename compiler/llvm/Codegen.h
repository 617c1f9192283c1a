// Kernel IR -> LLVM IR (internal to compiler/llvm). Every kernel::Program becomes one external
// function `qdot_<program>` with the C signature ProgramFn (Jit.h); a program longer than the
// split bound becomes several internal functions `qdot_<program>.<k>` called in order by it, which
// pass the values one part computes for a later part through the `spill` array.
#pragma once

#include <array>
#include <memory>
#include <string>

#include "kernel/Kernel.h"

namespace llvm {
class LLVMContext;
class Module;
}  // namespace llvm

namespace qdot::llvmbackend {

/// The LLVM module of a KernelModule and how each program was split.
struct LoweredModule {
  std::unique_ptr<llvm::Module> module;
  std::array<std::string, kernel::kProgramCount> entryNames;  ///< "qdot_residual", ...
  std::array<uint32_t, kernel::kProgramCount> functions{};    ///< parts per program
  std::array<uint32_t, kernel::kProgramCount> spillSlots{};   ///< doubles of spill memory it needs
};

/// Lowers every program of `k` into a new module in `ctx`, splitting programs into functions of
/// at most `maxInstructions` kernel instructions each (>= 1).
LoweredModule lowerKernels(const kernel::KernelModule& k, llvm::LLVMContext& ctx, uint32_t maxInstructions);

/// The LLVM function name of a program's entry ("qdot_residual").
std::string entryName(const kernel::Program& p, kernel::ProgramId id);

}  // namespace qdot::llvmbackend
