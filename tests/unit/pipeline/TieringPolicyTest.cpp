// The tiering policy (driver/TieringPolicy.h) on given observations: it compiles when the VM time
// still to come, extrapolated from the recent progress, repays the compile several times, and not
// before it has seen enough of the run; and the compile estimate follows the compile plan.
#include <gtest/gtest.h>

#include "driver/Pipeline.h"
#include "driver/TieringPolicy.h"
#include "unit/pipeline/CompiledModel.h"

namespace qdot::driver {
namespace {

// A run at `progress` after `elapsed` s, `vm` s of it in VM calls, all at a steady rate.
rt::TierObservation steadyRun(double progress, double elapsed, double vm) {
  rt::TierObservation seen;
  seen.progress = progress;
  seen.elapsedSeconds = elapsed;
  seen.firstTierSeconds = vm;
  seen.firstTierCalls = 1000;
  seen.recentProgress = progress / 2;  // the recent window: the second half of the VM time
  seen.recentFirstTierSeconds = vm / 2;
  return seen;
}

TEST(TieringPolicy, ALongRunSpentInModelCallsCompiles) {
  // 1 % of the horizon took 20 ms of VM calls: about 2 s more to come; a 50 ms compile repays.
  TierVerdict v = decideTiering(steadyRun(0.01, 0.025, 0.02), 0.05);
  EXPECT_TRUE(v.compile);
  EXPECT_NEAR(v.remainingVmSeconds, 1.98, 1e-9);
  EXPECT_GT(v.savingSeconds, 2 * 0.05);
  EXPECT_LT(v.savingSeconds, v.remainingVmSeconds);  // native code is not free
}

TEST(TieringPolicy, ARunWhoseModelCallsAreCheapStaysOnTheVm) {
  // Half the horizon, 1 s of wall but 50 ms in model calls (the rest in the linear solver): the
  // 50 ms still to come can never repay a 0.5 s compile.
  TierVerdict v = decideTiering(steadyRun(0.5, 1.0, 0.05), 0.5);
  EXPECT_FALSE(v.compile);
  EXPECT_NEAR(v.remainingVmSeconds, 0.05, 1e-9);
}

TEST(TieringPolicy, TheEndOfARunDoesNotCompile) {
  EXPECT_FALSE(decideTiering(steadyRun(0.999, 2.0, 1.9), 0.05).compile);
  EXPECT_TRUE(decideTiering(steadyRun(0.5, 2.0, 1.9), 0.05).compile);  // the same run halfway
}

TEST(TieringPolicy, DecidesOnlyOnceItHasSeenEnough) {
  TieringRule eager;
  eager.minObserved = 0;
  eager.minProgress = 0;
  // The projection repays the compile, but the VM calls so far (5 ms) are less than a tenth of it.
  rt::TierObservation fewCalls = steadyRun(0.01, 0.006, 0.005);
  EXPECT_FALSE(decideTiering(fewCalls, 0.1).compile);
  EXPECT_TRUE(decideTiering(fewCalls, 0.1, eager).compile);
  // The solver's first steps are tiny: below 1 % of the horizon the rate says little.
  rt::TierObservation early = steadyRun(0.005, 0.025, 0.02);
  EXPECT_FALSE(decideTiering(early, 0.05).compile);
  EXPECT_TRUE(decideTiering(early, 0.05, eager).compile);
  // No progress yet (the start values are being solved, or no horizon): nothing to extrapolate from.
  EXPECT_FALSE(decideTiering(steadyRun(0, 0.5, 0.4), 0.05, eager).compile);
}

// A very large model on the VM: a residual or Jacobian call would save more on native code than
// the whole compile takes (the chain of 10⁶ masses: 57 ms a call against ~25 ms of JIT), so the
// compile starts after the first calls, before the solver's tiny first steps show any progress.
// Cheaper calls wait for the progress, and a run that is over never compiles.
TEST(TieringPolicy, ACallDearerThanTheCompileCompilesAtOnce) {
  rt::TierObservation firstCalls;
  firstCalls.elapsedSeconds = 0.2;
  firstCalls.firstTierSeconds = 0.15;
  firstCalls.firstTierCalls = 3;  // 50 ms each; no progress yet
  TierVerdict v = decideTiering(firstCalls, 0.025);
  EXPECT_TRUE(v.compile);
  EXPECT_TRUE(v.oneCallPays);
  EXPECT_NEAR(v.savingSeconds, 0.05 * 0.75, 1e-12);  // a call, at the rule's native speed-up of 4
  EXPECT_TRUE(decideTiering(firstCalls, 0.037).compile);   // 37.5 ms saved a call >= 37 ms
  EXPECT_FALSE(decideTiering(firstCalls, 0.038).compile);  // < 38 ms: wait for progress
  EXPECT_FALSE(decideTiering(firstCalls, 0.025, {.nativeSpeedup = 4, .payback = 2, .minObserved = 10}).compile);  // seen too little
  rt::TierObservation cheap = firstCalls;
  cheap.firstTierSeconds = 0.003;  // 1 ms a call
  EXPECT_FALSE(decideTiering(cheap, 0.025).compile);
  rt::TierObservation over = firstCalls;
  over.progress = 1;
  EXPECT_FALSE(decideTiering(over, 0.025).compile);
}

TEST(TieringPolicy, TheRecentRateCountsNotTheRateSinceTheStart) {
  // 10 % of the horizon; the first 8 % took 90 ms of VM time in short steps, the last 2 % 10 ms:
  // 90 % to go at the recent rate is 0.45 s, not the 0.9 s the average would give.
  rt::TierObservation seen = steadyRun(0.1, 0.2, 0.1);
  seen.recentProgress = 0.02;
  seen.recentFirstTierSeconds = 0.01;
  TierVerdict v = decideTiering(seen, 0.1);
  EXPECT_NEAR(v.remainingVmSeconds, 0.45, 1e-9);
  EXPECT_TRUE(v.compile);
  EXPECT_FALSE(decideTiering(seen, 0.2).compile);  // what is left after the compile, x 3/4, < 2 x 0.2 s
}

// With a core left idle through the run so far, the compile takes nothing from the solver and runs
// at an idle machine's speed (0.4 of the estimate); one that comes too late costs the run nothing,
// so the saving need only be a tenth of that, and the run need not be past its first 1 %. Unknown
// (-1) or a busy machine keeps the estimate, the payback of 2 and the 1 %.
TEST(TieringPolicy, AnIdleCoreAsksLittleOfTheSaving) {
  rt::TierObservation seen = steadyRun(0.1, 0.2, 0.1);  // 0.9 s of VM calls to come, half of the run on the VM
  EXPECT_FALSE(decideTiering(seen, 0.4).compile);        // (0.9 - 0.4/2) x 3/4 = 0.525 < 2 x 0.4
  seen.idleCores = 0.9;
  TierVerdict v = decideTiering(seen, 0.4);  // a 0.16 s compile: (0.9 - 0.08) x 3/4 = 0.615 >= 0.016
  EXPECT_TRUE(v.compile);
  EXPECT_EQ(v.payback, 0.1);
  EXPECT_NEAR(v.savingSeconds, 0.615, 1e-12);
  // Half the horizon, 0.1 s of VM calls to come: a 0.15 s compile (estimate 0.375 s) saves
  // (0.1 - 0.075) x 3/4 = 18.75 ms >= 15 ms; a 0.18 s one (estimate 0.45 s) 7.5 ms < 18 ms.
  rt::TierObservation halfway = steadyRun(0.5, 0.2, 0.1);
  halfway.idleCores = 0.9;
  EXPECT_TRUE(decideTiering(halfway, 0.375).compile);
  EXPECT_FALSE(decideTiering(halfway, 0.45).compile);
  seen.idleCores = 0.5;
  EXPECT_FALSE(decideTiering(seen, 0.4).compile);
  EXPECT_EQ(decideTiering(seen, 0.4).payback, 2.0);
}

TEST(TieringPolicy, AnIdleCoreNeedNotWaitForTheFirstPercent) {
  // 0.5 % of the horizon, 20 ms of VM calls: the projection (about 4 s) is too early to trust,
  // which on a busy machine waits, and on an idle core costs nothing if it is wrong.
  rt::TierObservation early = steadyRun(0.005, 0.025, 0.02);
  EXPECT_FALSE(decideTiering(early, 0.05).compile);
  early.idleCores = 1;
  EXPECT_TRUE(decideTiering(early, 0.05).compile);
  // It still has to have seen 3 % of the estimate in VM calls (a tenth on a busy machine).
  EXPECT_FALSE(decideTiering(early, 1.0).compile);  // 20 ms < 30 ms
  rt::TierObservation fewCalls = steadyRun(0.05, 0.01, 0.006);
  fewCalls.idleCores = 1;
  EXPECT_TRUE(decideTiering(fewCalls, 0.1).compile);  // 6 ms >= 3 ms
  fewCalls.idleCores = 0;
  EXPECT_FALSE(decideTiering(fewCalls, 0.1).compile);  // 6 ms < 10 ms
}

TEST(TieringPolicy, TheEstimateFollowsTheCompilePlan) {
  Compilation c;
  ASSERT_TRUE(compileSource(c, "nlink.qd", test::readSource("examples/pendulum/nlink.qd"), "", Stage::Kernel));
  llvmbackend::JitOptions hot;
  hot.compiledPrograms = llvmbackend::programBit(ModelProgram::Residual) | llvmbackend::programBit(ModelProgram::Jacobian);
  CompileEstimate e = estimateCompile(*c.kernels, hot, 1);
  const auto& programs = c.kernels->programs;
  EXPECT_EQ(e.optimisedInstructions, programs[programIndex(ModelProgram::Residual)].code.size());
  EXPECT_EQ(e.plainInstructions, programs[programIndex(ModelProgram::Jacobian)].code.size());
  EXPECT_GT(e.cpuSeconds, 0);
  // Above the large-model size everything is compiled at level 0: cheaper per instruction.
  llvmbackend::JitOptions large = hot;
  large.largeModelInstructions = 1;
  CompileEstimate plain = estimateCompile(*c.kernels, large, 1);
  EXPECT_EQ(plain.optimisedInstructions, 0u);
  EXPECT_EQ(plain.plainInstructions, e.optimisedInstructions + e.plainInstructions);
  EXPECT_LT(plain.cpuSeconds, e.cpuSeconds);
}

// A residual call's VM time is estimated from the instructions it executes: the chain's loops run
// once per mass, so it grows with n while the compile does not; a model is compiled before the
// run exactly when one VM call is expected to cost at least the whole compile.
TEST(TieringPolicy, AModelWhoseVmCallOutweighsTheCompileIsCompiledFirst) {
  auto vmCall = [](int n, CompileEstimate* estimate) {
    Compilation c;
    c.options.keepLoops = c.options.rerollRows = true;  // as qdot run compiles
    EXPECT_TRUE(compileSource(c, "spring_chain.qd", test::readSource("examples/vibration/spring_chain.qd"), "", Stage::Check));
    std::vector<std::string> assignments{"n=" + std::to_string(n)};
    EXPECT_EQ(takeStructuralParameters(c, assignments), "");
    EXPECT_TRUE(continueTo(c, Stage::Kernel));
    llvmbackend::JitOptions hot;
    hot.compiledPrograms = llvmbackend::programBit(ModelProgram::Residual) | llvmbackend::programBit(ModelProgram::Jacobian);
    *estimate = estimateCompile(*c.kernels, hot, 1);
    return vmCallSeconds(*c.kernels);
  };
  CompileEstimate small, large;
  double atSmall = vmCall(2000, &small), atLarge = vmCall(20000, &large);
  EXPECT_NEAR(atLarge / atSmall, 10.0, 0.1);              // linear in n
  EXPECT_EQ(small.cpuSeconds, large.cpuSeconds);          // the loops compile once, whatever n
  EXPECT_FALSE(compileFirst(small, atSmall));             // ~0.1 ms a call against a ~25 ms compile
  EXPECT_TRUE(compileFirst(small, small.cpuSeconds));
  EXPECT_FALSE(compileFirst(small, 0.99 * small.cpuSeconds));
  EXPECT_FALSE(compileFirst(CompileEstimate{}, 1.0));     // nothing to compile: nothing first
}

}  // namespace
}  // namespace qdot::driver
