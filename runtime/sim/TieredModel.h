// TieredModel: start simulating at once on a model that needs no compile time (the bytecode VM)
// while a faster one (the LLVM JIT) is compiled on a background thread, and switch to the faster
// one at the first call after it is ready. Both must compute bit-identical results (the JIT and
// the VM do: tests/unit/llvm, tests/cli/backends_test.sh), so where the switch falls changes
// nothing in the results, only in the time they take: short runs never wait for the compiler and
// long ones run on native code for all but their first moments.
// Whether and when the compile starts is a trigger's decision (the tiering policy, driver/
// TieringPolicy.h): it sees what the first tier has cost so far and how far the run has got, so a
// run whose model calls are cheap never pays for a compiler competing with the solver.
// The calls a run repeats go to the second tier: the residual and the Jacobian (per step), the
// outputs and invariants (per output row: a rigid body's, written every 0.5 ms, cost a third of
// its residuals on the VM); parameters and start values (once per run) stay on the first.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "qdot/model_abi.h"
#include "qdot/result.hpp"

namespace qdot::rt {

/// Builds the second tier; may return null (the run stays on the first). Should give up early,
/// returning null, once `cancel` is set (the run ended before it was done).
using TierCompiler = std::function<ModelPtr(const std::atomic<bool>& cancel)>;

/// What a trigger sees: the run so far, on the first tier.
struct TierObservation {
  double progress = 0;          ///< fraction of the horizon simulated (0 until setTierHorizon)
  double elapsedSeconds = 0;    ///< wall time since the tiered model was created
  double firstTierSeconds = 0;  ///< wall time inside residual, Jacobian, output and invariant calls on the first tier (sampled)
  uint64_t firstTierCalls = 0;  ///< those calls on the first tier
  /// The same over the recent part of the run (the last half to three quarters of the progress):
  /// the solver's steps grow from a tiny first one, so the rate since the start would understate
  /// the progress, and a few calls alone say little on a busy machine.
  double recentProgress = 0;
  double recentFirstTierSeconds = 0;
  /// The machine's idle cores on average since the tiered model was created (Linux: /proc/stat,
  /// read at most every few milliseconds); -1 where unknown or too early to tell.
  double idleCores = -1;
};

/// Decides, on the solver thread, whether the compile starts now. Asked every few residual calls
/// until it says yes; a null trigger starts the compile at once.
using TierTrigger = std::function<bool(const TierObservation&)>;

/// What happened to the second tier so far.
struct TierReport {
  bool started = false;         ///< the trigger started the compile
  TierObservation startedAt;    ///< what the trigger saw when it did (if it never did: the run so far)
  bool compiling = false;       ///< the compile thread is still running
  bool ready = false;           ///< the second tier was compiled and is in use
  double readySeconds = 0;      ///< when, after the tiered model was created (wall)
  uint64_t firstTierCalls = 0;  ///< residual, Jacobian, output and invariant calls on the first tier (all if never ready)
  uint64_t secondTierCalls = 0;
  uint64_t callsThatWaited = 0;  ///< calls that waited for the second tier (createTieredModel's compileSeconds)
  double firstTierSeconds = 0;  ///< wall time inside them
};

/// Creates the tiered model; owns `first` and whatever `compile` returns. compile runs on its own
/// thread once `trigger` says so (at once without a trigger). destroy() cancels and joins it (a
/// program about to exit need not wait for it: qdot run ends with _Exit when the compile is still
/// running, tierReport().compiling).
/// `compileSeconds`, what the compile is expected to take (0: unknown): once it runs, a residual
/// or Jacobian call waits for the second tier instead of running on the first when the first
/// tier's calls take longer on average than the compile has left by that estimate (a model of 10⁶
/// masses: 57 ms a call on the VM against a 25 ms compile) — the call is then answered sooner.
ModelPtr createTieredModel(ModelPtr first, TierCompiler compile, TierTrigger trigger = {}, double compileSeconds = 0);

/// Tells a tiered model the simulated interval [start, stop], from which it reports the progress
/// of a run (the largest time of a residual call); does nothing for any other model.
void setTierHorizon(const QdotModel* model, double start, double stop);

/// The report of a model made by createTieredModel, without waiting; nullopt for any other model.
/// Call it from the thread that calls the model. Once `compiling` is false, whatever the compile
/// function wrote before returning may be read.
std::optional<TierReport> tierReport(const QdotModel* model);

}  // namespace qdot::rt
