// The JIT's compile plan (internal to compiler/llvm), plain data without LLVM types: how each
// program is cut into parts (functions of bounded size that pass values through a spill array)
// and how the parts are grouped into compile units (one LLVM module each, compiled in parallel).
// Codegen.h lowers the parts; Jit.cpp compiles the units and links them.
#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "kernel/Kernel.h"
#include "llvm/JitModel.h"

namespace qdot::llvmbackend {

/// How a program is cut into parts of about `maxInstructions` kernel instructions (part k =
/// instructions [starts[k], starts[k+1])), never inside a loop (a loop stays whole in one function,
/// however long), and which values cross from one part to a later one through the spill array.
/// Computed once per program; every part's lowering reads it, so parts can be lowered
/// independently (in different modules and threads).
struct ProgramSplit {
  uint32_t parts = 0;
  std::vector<uint32_t> starts;     ///< per part: its first instruction
  std::vector<uint32_t> spillSlot;  ///< per instruction: its slot, or kNoSlot
  uint32_t spillSlots = 0;          ///< doubles of spill memory the program needs
  static constexpr uint32_t kNoSlot = UINT32_MAX;

  size_t begin(uint32_t part) const { return starts[part]; }
  size_t end(uint32_t part, size_t size) const { return part + 1 < parts ? starts[part + 1] : size; }
};

/// Loads and constants: cheaper to redo in a later part than to pass through the spill array.
bool rematerialisable(kernel::Op op);

/// Splits `p` into parts of at most `maxInstructions` (>= 1) instructions, except that a loop is
/// never cut (a part holding one may be longer).
ProgramSplit splitProgram(const kernel::Program& p, uint32_t maxInstructions);

/// The LLVM function name of a program's entry ("qdot_residual").
std::string entryName(const kernel::Program& p, ModelProgram program);
/// "qdot_residual.3": the function of part `k` of the program whose entry is `name`.
std::string partName(const std::string& name, uint32_t k);

/// One program: whether it is compiled, how it is split, at which code generator level.
struct ProgramPlan {
  bool compiled = false;
  std::string name;  ///< entryName; part k is partName(name, k)
  ProgramSplit split;
  int level = 0;
};

/// Consecutive parts [first, last) of one program.
struct Segment {
  ModelProgram program{};
  uint32_t first = 0, last = 0;
};

/// Segments compiled at one level into one module and one object.
struct PlannedUnit {
  int level = 0;
  std::vector<Segment> segments;
  size_t instructions = 0;
};

struct CompilePlan {
  PerProgram<ProgramPlan> programs;
  std::vector<PlannedUnit> units;
};

/// The code generator level of `program` under `options` (before the large-model rule).
int levelOf(ModelProgram program, const JitOptions& options);

/// Splits each program `options.compiledPrograms` names and groups parts of the same level into
/// units of about `budget` instructions: big enough that the per-module cost (a pass pipeline, an
/// object to link) stays small (a small model is one unit per level), small enough that `threads`
/// threads share the work evenly (about two units per thread on a large model). Every part of a
/// compiled program is in exactly one unit.
CompilePlan planCompile(const kernel::KernelModule& k, const JitOptions& options, unsigned threads);

}  // namespace qdot::llvmbackend
