// estimateCompile and decideTiering: see TieringPolicy.h.
#include "driver/TieringPolicy.h"

#include <algorithm>

#include "kernel/Kernel.h"
#include "llvm/CompilePlan.h"

namespace qdot::driver {
namespace {

// CPU seconds per kernel instruction at each code generator level and per module (a pass
// pipeline, an object file to link), measured by `qdot run --stats` on the spring chain (n = 1 000
// ... 100 000) and the N-link pendulum while the solver runs beside the compile thread on the two
// cores (compiler/driver/README.md): two to ten times what an idle machine takes, so the policy
// errs towards staying on the VM.
constexpr double kSecondsPerOptimisedInstruction = 80e-6;
constexpr double kSecondsPerPlainInstruction = 4e-6;
constexpr double kSecondsPerUnit = 10e-3;
// VM seconds per executed kernel instruction: 1.8 ns measured on the spring chain's residual at
// 10⁶ masses (2.5·10⁷ instructions, 45 ms, the run's first call); taken lower, so that a model is
// compiled first only when its VM calls are surely longer than the compile.
constexpr double kVmSecondsPerInstruction = 1.5e-9;

}  // namespace

CompileEstimate estimateCompile(const kernel::KernelModule& k, const llvmbackend::JitOptions& options,
                                unsigned threads) {
  CompileEstimate e;
  e.threads = std::max(1u, threads);
  llvmbackend::CompilePlan plan = llvmbackend::planCompile(k, options, e.threads);
  for (const llvmbackend::PlannedUnit& unit : plan.units)
    (unit.level >= 2 ? e.optimisedInstructions : e.plainInstructions) += unit.instructions;
  e.units = plan.units.size();
  e.cpuSeconds = double(e.optimisedInstructions) * kSecondsPerOptimisedInstruction +
                 double(e.plainInstructions) * kSecondsPerPlainInstruction + double(e.units) * kSecondsPerUnit;
  return e;
}

double vmCallSeconds(const kernel::KernelModule& k) {
  return double(kernel::executedInstructions(k.program(ModelProgram::Residual))) * kVmSecondsPerInstruction;
}

bool compileFirst(const CompileEstimate& e, double vmCallSeconds) { return e.cpuSeconds > 0 && vmCallSeconds >= e.cpuSeconds; }

TierVerdict decideTiering(const rt::TierObservation& seen, double compileSeconds, const TieringRule& rule) {
  TierVerdict v;
  // A call whose saving on native code exceeds the whole compile (a model of 10⁶ masses: 57 ms a
  // call on the VM against a 25 ms compile): a run that is not over makes another, which alone pays
  // the compile back, and every one after it is gain (the margin that `payback` asks of the
  // extrapolation below). So it starts now, before the solver's tiny first steps show any progress.
  if (seen.firstTierCalls > 0 && seen.progress < 1) {
    double perCall = seen.firstTierSeconds / static_cast<double>(seen.firstTierCalls);
    v.savingSeconds = perCall * (1 - 1 / rule.nativeSpeedup);
    if (seen.firstTierSeconds >= rule.minObserved * compileSeconds && v.savingSeconds >= compileSeconds) {
      v.compile = v.oneCallPays = true;
      v.remainingVmSeconds = perCall;  // at least the next call
      return v;
    }
    v.savingSeconds = 0;
  }
  // Nothing to extrapolate from yet (the start values are still being solved, or no horizon).
  if (seen.recentProgress <= 0 || seen.elapsedSeconds <= 0) return v;
  v.remainingVmSeconds = seen.recentFirstTierSeconds * (1 - seen.progress) / seen.recentProgress;
  // A core the run has left idle takes the compile without taking the solver's time, at an idle
  // machine's speed (the estimate was measured under load): the compile is expected to take
  // idleCompileShare of it, and since a compile that comes too late costs the run nothing there,
  // the saving need only be idlePayback of that, and the progress need not be past the first steps.
  bool idle = seen.idleCores >= rule.idleCore;
  double compile = idle ? rule.idleCompileShare * compileSeconds : compileSeconds;
  v.payback = idle ? rule.idlePayback : rule.payback;
  // While it compiles the run stays on the VM, spending the share of its time it spent so far.
  double duringCompile = compile * std::min(1.0, seen.firstTierSeconds / seen.elapsedSeconds);
  double afterCompile = std::max(0.0, v.remainingVmSeconds - duringCompile);
  v.savingSeconds = afterCompile * (1 - 1 / rule.nativeSpeedup);
  double observed = idle ? rule.idleMinObserved : rule.minObserved;
  v.compile = (idle || seen.progress >= rule.minProgress) && seen.firstTierSeconds >= observed * compileSeconds &&
              v.savingSeconds >= v.payback * compile;
  return v;
}

}  // namespace qdot::driver
