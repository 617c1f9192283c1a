// Kernel IR -> LLVM IR (internal to compiler/llvm). Every kernel::Program becomes one external
// function with the C signature ProgramFn (Jit.h); a program longer than the split bound becomes
// several functions `qdot_<program>.<k>` run in order, which pass the values one part computes for
// a later part through the `spill` array. The JIT compiles parts in separate modules (in parallel)
// and calls them in order itself; object files get one module with an entry calling the parts.
#pragma once

#include <algorithm>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "kernel/Kernel.h"

namespace llvm {
class LLVMContext;
class Module;
}  // namespace llvm

namespace qdot::llvmbackend {

/// How a program is cut into parts of at most `chunk` kernel instructions (part k = instructions
/// [k·chunk, (k+1)·chunk)) and which values cross from one part to a later one through the spill
/// array. Computed once per program; every part's lowering reads it, so parts can be lowered
/// independently (in different modules and threads).
struct ProgramSplit {
  uint32_t chunk = 1;
  uint32_t parts = 0;
  std::vector<uint32_t> spillSlot;  ///< per instruction: its slot, or kNoSlot
  uint32_t spillSlots = 0;          ///< doubles of spill memory the program needs
  static constexpr uint32_t kNoSlot = UINT32_MAX;

  size_t begin(uint32_t part) const { return size_t(part) * chunk; }
  size_t end(uint32_t part, size_t size) const { return std::min(size, size_t(part + 1) * chunk); }
};

/// Splits `p` into parts of at most `maxInstructions` (>= 1) instructions.
ProgramSplit splitProgram(const kernel::Program& p, uint32_t maxInstructions);

/// Emits parts [first, last) of `p` into `m`, part k as the function `partName(name, k)` with the
/// ProgramFn signature (Jit.h) and the given linkage. Running parts 0..parts-1 in order, with one
/// spill array of `split.spillSlots` doubles, computes the program.
void lowerParts(const kernel::Program& p, const ProgramSplit& split, uint32_t first, uint32_t last,
                const std::string& name, llvm::Module& m, bool internal);

/// "qdot_residual.3": the function of part `k` of the program whose entry is `name`.
std::string partName(const std::string& name, uint32_t k);

/// The LLVM module of a whole KernelModule (for object files): one external entry per program.
struct LoweredModule {
  std::unique_ptr<llvm::Module> module;
  std::array<std::string, kernel::kProgramCount> entryNames;  ///< "qdot_residual", ...
  std::array<uint32_t, kernel::kProgramCount> functions{};    ///< parts per program
  std::array<uint32_t, kernel::kProgramCount> spillSlots{};   ///< doubles of spill memory it needs
};

/// Lowers every program of `k` into a new module in `ctx`: each program's parts become internal
/// functions called in order by its external entry `qdot_<program>` (a one-part program is its entry).
LoweredModule lowerKernels(const kernel::KernelModule& k, llvm::LLVMContext& ctx, uint32_t maxInstructions);

/// The LLVM function name of a program's entry ("qdot_residual").
std::string entryName(const kernel::Program& p, kernel::ProgramId id);

}  // namespace qdot::llvmbackend
