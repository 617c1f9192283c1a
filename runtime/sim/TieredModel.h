// TieredModel: start simulating at once on a model that needs no compile time (the bytecode VM)
// while a faster one (the LLVM JIT) is compiled on a background thread, and switch to the faster
// one at the first call after it is ready. Both must compute bit-identical results (the JIT and
// the VM do: tests/unit/llvm, tests/cli/backends_test.sh), so where the switch falls changes
// nothing in the results, only in the time they take: short runs never wait for the compiler and
// long ones run on native code for all but their first moments.
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

/// What happened to the second tier so far.
struct TierReport {
  bool compiling = false;       ///< the compile thread is still running
  bool ready = false;           ///< the second tier was compiled and is in use
  double readySeconds = 0;      ///< when, after the tiered model was created (wall)
  uint64_t firstTierCalls = 0;  ///< calls made on the first tier (all calls if never ready)
  uint64_t secondTierCalls = 0;
};

/// Creates the tiered model; owns `first` and whatever `compile` returns. compile runs on its own
/// thread at once. destroy() cancels and joins it (a program about to exit need not wait for it:
/// qdot run ends with _Exit when the compile is still running, tierReport().compiling).
ModelPtr createTieredModel(ModelPtr first, TierCompiler compile);

/// The report of a model made by createTieredModel, without waiting; nullopt for any other model.
/// Call it from the thread that calls the model. Once `compiling` is false, whatever the compile
/// function wrote before returning may be read.
std::optional<TierReport> tierReport(const QdotModel* model);

}  // namespace qdot::rt
