// TieringPolicy: whether, when and how much qdot run compiles with the LLVM JIT while the VM runs
// (Backend::Tiered, Backends.h). Plain functions of numbers, so tests check the decisions.
//   How much: only the residual and the Jacobian (the calls IDA repeats; the rest runs once per run
//     or per output row and stays on the VM), on one thread fewer than cores (the solver keeps one).
//   Whether and when: the run starts on the VM, which times its residual and Jacobian calls. Every
//     few calls the policy extrapolates from the recent progress through the horizon how much VM time in
//     those calls is still to come, and starts the compile once native code (rule.nativeSpeedup
//     times faster) would save rule.payback times the estimated compile time. The compile competes
//     with the solver for the machine, so on a loaded two-core machine its whole CPU time may add
//     to the run: the payback factor keeps a run from ever losing more than a fraction of what it
//     gains, and a run whose model calls are cheap (most of its time in the linear solver, or short)
//     never compiles. Why and when is printed by --stats (reportTiers).
//   Before the run: a model whose every residual call on the VM is expected to take longer than
//     the whole compile (vmCallSeconds >= the estimate: the spring chain from about 10⁶ masses)
//     is compiled first, as --jit-wait does: the VM would only make the run wait, and the bytecode
//     module cost memory.
#pragma once

#include <cstddef>

#include "llvm/JitModel.h"
#include "sim/TieredModel.h"

namespace qdot::kernel {
struct KernelModule;
}

namespace qdot::driver {

/// The JIT work of one model under one set of JIT options.
struct CompileEstimate {
  size_t optimisedInstructions = 0;  ///< kernel instructions compiled at code generator level 2
  size_t plainInstructions = 0;      ///< at level 0
  size_t units = 0;                  ///< LLVM modules (each has a fixed cost)
  unsigned threads = 1;
  double cpuSeconds = 0;  ///< expected CPU time on this machine when idle (summed over threads)
};

/// The compile plan's work for `k` (llvmbackend::planCompile) priced at the rates measured on the
/// benchmark models (compiler/driver/README.md).
CompileEstimate estimateCompile(const kernel::KernelModule& k, const llvmbackend::JitOptions& options,
                                unsigned threads);

/// The constants of the decision; the defaults are the measured ones (compiler/driver/README.md).
struct TieringRule {
  double nativeSpeedup = 4;  ///< VM / native time of a residual or Jacobian call (measured 5.7-17)
  double payback = 2;        ///< the projected saving must exceed this many compile CPU times
  double minObserved = 0.1;  ///< decide only once the VM calls took this fraction of the compile
  double minProgress = 0.01;  ///< and the run got this far (past the solver's first, tiny steps)
  /// Idle cores on average (TierObservation::idleCores) from which the compile is taken to cost
  /// the run nothing: it runs on a core the run leaves idle, at an idle machine's speed, taking
  /// `idleCompileShare` of the estimate (which was measured under load: car_axis 19 ms of CPU
  /// against 40 ms estimated on one machine, 14-16 ms on another; eight models there 0.31-0.57 of
  /// their estimates, typically 0.4; taken too low it only starts a compile that, on the idle
  /// core, comes later than foreseen). A compile that comes too late
  /// to help then loses the run nothing (qdot run does not wait for it), so the saving need only
  /// be `idlePayback` of that (a tenth: anything worth having), the VM calls need only have taken
  /// `idleMinObserved` of the estimate, and the run need not be past `minProgress`: an early
  /// extrapolation overstates what is left, which on an idle core costs nothing either. (Compiling
  /// at once whatever the run was measured: the small models 5-25 % slower than the VM alone.)
  double idleCore = 0.75;
  double idleCompileShare = 0.4;
  double idlePayback = 0.1;
  double idleMinObserved = 0.03;
};

struct TierVerdict {
  bool compile = false;
  double remainingVmSeconds = 0;  ///< VM time in residual and Jacobian calls still to come
  double savingSeconds = 0;       ///< what native code would save of it, after the compile
  /// Decided on one call's cost: native code saves more of a single call than the compile takes.
  bool oneCallPays = false;
  double payback = 0;  ///< the payback asked for (rule.payback, or rule.idlePayback with an idle core)
};

/// What one residual call of `k` is expected to take on the VM: its executed instructions
/// (kernel::executedInstructions) at a rate below the VM's measured one, so that compileFirst
/// errs towards the VM.
double vmCallSeconds(const kernel::KernelModule& k);

/// Whether native code is compiled before the run (above): one VM call is expected to cost more
/// than the whole compile.
bool compileFirst(const CompileEstimate& e, double vmCallSeconds);

/// The decision on what the run has shown so far (`seen`), for a compile of `compileSeconds`.
TierVerdict decideTiering(const rt::TierObservation& seen, double compileSeconds, const TieringRule& rule = {});

}  // namespace qdot::driver
