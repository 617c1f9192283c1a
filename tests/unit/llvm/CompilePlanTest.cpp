// The JIT's compile plan as plain data (no LLVM involved): which values a split passes through the
// spill array, and that the units cover every part of every compiled program exactly once, each
// unit at one code generator level.
#include <gtest/gtest.h>

#include <map>

#include "llvm/CompilePlan.h"

namespace qdot::test {
namespace {

using kernel::Instr;
using kernel::Op;

// A chain: %0 = ldy 0, then %i = %i-1 * %0 (n - 1 times), then out[0] = %n-1.
kernel::Program chain(uint32_t n) {
  kernel::Program p;
  p.code.push_back(Instr{Op::LoadY, 0, 0, 0, 0});
  for (uint32_t i = 1; i < n; ++i) p.code.push_back(Instr{Op::Mul, i - 1, 0, 0, 0});
  p.code.push_back(Instr{Op::Store, n - 1, 0, 0, 0});
  p.outputCount = 1;
  return p;
}

TEST(CompilePlan, SplitSpillsComputedValuesAndRecomputesLoads) {
  // Parts of 3: [ldy, mul, mul] [mul, mul, mul] [st]. %2 crosses into part 1, %5 into part 2;
  // %0 (a load) is read by every part but is recomputed there, never spilled.
  llvmbackend::ProgramSplit s = llvmbackend::splitProgram(chain(6), 3);
  EXPECT_EQ(s.parts, 3u);
  EXPECT_EQ(s.spillSlots, 2u);
  EXPECT_EQ(s.spillSlot[0], llvmbackend::ProgramSplit::kNoSlot);
  EXPECT_EQ(s.spillSlot[2], 0u);
  EXPECT_EQ(s.spillSlot[5], 1u);
  EXPECT_EQ(s.end(2, 7), 7u);
}

TEST(CompilePlan, SplitsNeverCutALoop) {
  // ldy; loop (ldyl, mul x6, stl) endloop; then a chain; parts of 3 would cut the loop anywhere.
  kernel::Program p;
  p.loops = {kernel::Loop{.count = 4}};
  p.code.push_back(Instr{Op::LoadY, 0, 0, 0, 0});
  p.code.push_back(Instr{Op::LoopBegin, 0, 0, 0, 0});
  p.code.push_back(Instr{Op::LoadYLooped, 0, 0, 0, 0});
  for (uint32_t i = 3; i < 9; ++i) p.code.push_back(Instr{Op::Mul, i - 1, 0, 0, 0});
  p.code.push_back(Instr{Op::StoreLooped, 8, 0, 0, 0});
  p.code.push_back(Instr{Op::LoopEnd, 0, 0, 0, 0});
  for (uint32_t i = 0; i < 5; ++i) p.code.push_back(Instr{Op::Mul, 0, 0, 0, 0});
  p.outputCount = 4;
  for (uint32_t chunk : {1u, 2u, 3u, 5u, 11u}) {
    llvmbackend::ProgramSplit s = llvmbackend::splitProgram(p, chunk);
    size_t covered = 0;
    for (uint32_t k = 0; k < s.parts; ++k) {
      size_t b = s.begin(k), e = s.end(k, p.code.size());
      EXPECT_EQ(b, covered) << chunk;
      EXPECT_LT(b, e) << chunk;
      EXPECT_FALSE(b > 1 && b <= 10) << "part " << k << " starts inside the loop, chunk " << chunk;
      EXPECT_TRUE(e - b <= chunk || (b <= 1 && e >= 11)) << "only a part holding the loop may be longer";
      covered = e;
    }
    EXPECT_EQ(covered, p.code.size());
  }
}

TEST(CompilePlan, UnitsCoverEveryPartOnceAtTheProgramsLevel) {
  kernel::KernelModule k;
  for (size_t i = 0; i < kModelProgramCount; ++i) k.programs[i] = chain(50 + 40 * static_cast<uint32_t>(i));
  llvmbackend::JitOptions o;
  o.maxInstructionsPerFunction = 16;
  o.optLevel = 2, o.jacobianOptLevel = 1, o.coldOptLevel = 0;
  llvmbackend::CompilePlan plan = llvmbackend::planCompile(k, o, 2);
  std::map<std::pair<size_t, uint32_t>, int> seen;  // (program, part) -> units holding it
  for (const llvmbackend::PlannedUnit& u : plan.units)
    for (const llvmbackend::Segment& s : u.segments) {
      EXPECT_EQ(u.level, plan.programs[programIndex(s.program)].level);
      for (uint32_t part = s.first; part < s.last; ++part) ++seen[{programIndex(s.program), part}];
    }
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    const llvmbackend::ProgramPlan& p = plan.programs[i];
    bool compiled = o.compiledPrograms & llvmbackend::programBit(programAt(i));
    EXPECT_EQ(p.compiled, compiled) << kModelProgramNames[i];
    if (!compiled) continue;
    EXPECT_EQ(p.level, llvmbackend::levelOf(programAt(i), o));
    for (uint32_t part = 0; part < p.split.parts; ++part) EXPECT_EQ((seen[{i, part}]), 1) << i << "." << part;
  }
  EXPECT_EQ(plan.programs[programIndex(ModelProgram::Residual)].name, "qdot_2");  // unnamed program: its number
}

TEST(CompilePlan, LargeModelsAreCompiledAtLevelZero) {
  kernel::KernelModule k;
  for (auto& p : k.programs) p = chain(100);
  llvmbackend::JitOptions o;
  o.largeModelInstructions = 150;
  llvmbackend::CompilePlan plan = llvmbackend::planCompile(k, o, 4);
  for (const llvmbackend::PlannedUnit& u : plan.units) EXPECT_EQ(u.level, 0);
  EXPECT_FALSE(plan.units.empty());
}

}  // namespace
}  // namespace qdot::test
