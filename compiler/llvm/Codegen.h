// Kernel IR -> LLVM IR (internal to compiler/llvm). Every kernel::Program becomes one external
// function with the C signature ProgramFn (Jit.h); a program longer than the split bound becomes
// several functions `qdot_<program>.<k>` run in order, which pass the values one part computes for
// a later part through the `spill` array. The JIT compiles parts in separate modules (in parallel)
// and calls them in order itself; object files get one module with an entry calling the parts.
// How programs are split is the compile plan's (CompilePlan.h).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "kernel/Kernel.h"
#include "llvm/CompilePlan.h"

namespace llvm {
class LLVMContext;
class Module;
}  // namespace llvm

namespace qdot::llvmbackend {

/// Where compiled loops find a program's index table (kernel::Program::indexTable): through the
/// call (ModelCall::indexTable: object files, whose executable holds the table in its embedded
/// module), or read in place at its address — for the JIT, whose code never outlives the
/// KernelModule it was compiled from. Either way a table of millions of Jacobian positions is not
/// machine-code data: JIT time and executable size would grow with n.
enum class IndexTables { FromCall, InPlace };

/// Emits parts [first, last) of `p` into `m`, part k as the function `partName(name, k)` with the
/// ProgramFn signature (Jit.h) and the given linkage. Running parts 0..parts-1 in order, with one
/// spill array of `split.spillSlots` doubles, computes the program.
void lowerParts(const kernel::Program& p, const ProgramSplit& split, uint32_t first, uint32_t last,
                const std::string& name, llvm::Module& m, bool internal, IndexTables tables = IndexTables::FromCall);

/// The LLVM module of a whole KernelModule (for object files): one external entry per program.
struct LoweredModule {
  std::unique_ptr<llvm::Module> module;
  PerProgram<std::string> entryNames;  ///< "qdot_residual", ...; "" for a program not lowered
  PerProgram<uint32_t> functions{};    ///< parts per program
  PerProgram<uint32_t> spillSlots{};   ///< doubles of spill memory it needs
};

/// Lowers the programs of `k` that `programs` names (bits 1 << programIndex, all by default) into
/// a new module in `ctx`: each program's parts become internal functions called in order by its
/// external entry `qdot_<program>` (a one-part program is its entry).
LoweredModule lowerKernels(const kernel::KernelModule& k, llvm::LLVMContext& ctx, uint32_t maxInstructions,
                           uint32_t programs = ~0u);

}  // namespace qdot::llvmbackend
