// Backends: which compiled form of a model a run uses, and how it is made (the tiering policy).
//   Backend::Tiered   (qdot run's default) the run starts at once on the bytecode VM; the tiering
//                     policy (TieringPolicy.h) starts the LLVM JIT on a background thread once the
//                     VM's measured cost shows it pays, and the run continues on native code from the
//                     first residual or Jacobian call after it is ready (rt::TieredModel); JIT and VM
//                     are bit-identical.
//   Backend::Background the same, but the compile starts at once, whatever it costs (tests).
//   Backend::Native   (--backend llvm --jit-wait) the JIT compiles before the first step.
//   Backend::Bytecode (--backend bytecode) the VM only: no compile time.
// A JIT that fails leaves the run on the VM, with a warning.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "driver/Pipeline.h"
#include "driver/TieringPolicy.h"
#include "sim/TieredModel.h"

namespace qdot::driver {

enum class Backend { Tiered, Background, Native, Bytecode };

/// What the JIT reports; written by the compile thread when it runs in the background (read it
/// only once the tier report says it is no longer compiling).
struct JitOutcome {
  llvmbackend::JitStats stats;
  std::string error;  ///< why the JIT failed ("cancelled" when the run ended first)
};

/// The model a run simulates, and how it was made.
struct RunnableModel {
  ModelPtr model;       ///< null if none could be made (then `error` says why)
  std::string what;     ///< "bytecode", "llvm", "bytecode then llvm"
  bool waited = false;  ///< the JIT compiled before the run (its stats are in jit->stats)
  double codegenSeconds = 0;
  std::shared_ptr<JitOutcome> jit = std::make_shared<JitOutcome>();
  std::string error;    ///< why there is no model (a bug: valid kernels always load)
  std::string warning;  ///< e.g. the JIT failed and the VM runs instead
  CompileEstimate jitEstimate;  ///< Backend::Tiered: the JIT work the policy weighs
  std::string decision;  ///< Backend::Tiered compiled first (TieringPolicy.h): why (--stats)
};

/// Makes the runnable model of a compilation that reached Stage::Kernel (continuing it to the
/// stages the backend needs). `invariants`: compile the invariants program too (Backend::Native;
/// a tiered model runs the invariants on the VM). The background
/// compile of Backend::Tiered owns what it reads (the kernels and a copy of the sources), so the
/// model may outlive `c`.
RunnableModel makeRunnableModel(Compilation& c, Backend backend, bool invariants);

/// After a tiered run: warns if the JIT failed; with `stats`, what the tiering policy decided and
/// why, when the JIT was ready and how many calls each tier made. Returns the report (nullopt for a
/// model that is not tiered).
std::optional<rt::TierReport> reportTiers(const RunnableModel& m, bool stats, std::ostream& log);

/// How the JIT compiled (--stats).
void printJitStats(const llvmbackend::JitStats& jit, std::ostream& log);

}  // namespace qdot::driver
