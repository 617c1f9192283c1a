// The tiering policy of qdot run (see Backends.h).
#include "driver/Backends.h"

#include <algorithm>
#include <chrono>
#include <ostream>
#include <thread>

#include <fmt/format.h>

#include "kernel/Kernel.h"
#include "vm/Vm.h"

namespace qdot::driver {
namespace {

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// The JIT before the first step; false (with out.error) if it failed.
bool compileNativeFirst(Compilation& c, bool invariants, RunnableModel& out) {
  c.options.jit = llvmbackend::jitOptionsForRun(invariants);
  out.what = "llvm";
  out.waited = true;
  if (continueTo(c, Stage::Native)) {
    out.model = std::move(c.native);
    out.jit->stats = c.jitStats;
    out.codegenSeconds = c.times.native;
    return true;
  }
  out.jit->error = c.internalError;
  return false;
}

// The VM model; false (with out.error) if the bytecode does not load, which is a bug.
bool loadBytecode(Compilation& c, RunnableModel& out) {
  if (!continueTo(c, Stage::Bytecode)) return false;
  // qdot run needs the module only in the model: moved, not copied (releaseStages, Pipeline.h).
  Result<ModelPtr> model = c.options.releaseStages ? vm::createModel(std::move(*c.bytecode)) : vm::createModel(*c.bytecode);
  if (c.options.releaseStages) c.bytecode.reset();
  if (model) out.model = std::move(model).value();
  else out.error = model.error();
  out.what = "bytecode";
  out.waited = false;
  out.codegenSeconds = c.times.bytecode;
  return out.model != nullptr;
}

// What the background JIT compiles: what the run calls per step or per output row — the residual,
// the Jacobian, the outputs and (when asked for) the invariants; the tiered model sends only those
// to it — on one thread fewer than cores so the solver keeps a core. The outputs count: a rigid
// body's (rotation matrices, angles) written every 0.5 ms took a third of the VM's time in
// residuals (fast_top, 4 001 rows).
llvmbackend::JitOptions backgroundJitOptions(bool invariants) {
  llvmbackend::JitOptions options = llvmbackend::jitOptionsForRun(invariants);
  options.compiledPrograms &= llvmbackend::programBit(ModelProgram::Residual) | llvmbackend::programBit(ModelProgram::Jacobian) |
                              llvmbackend::programBit(ModelProgram::Outputs) | llvmbackend::programBit(ModelProgram::Invariants);
  options.compileRunOnceFrom = UINT64_MAX;  // the VM has run them before this compile is asked for
  options.threads = std::max(2u, std::thread::hardware_concurrency()) - 1;
  return options;
}

// The tiering policy's trigger for a compile estimated at `estimate` (TieringPolicy.h).
rt::TierTrigger policyTrigger(const CompileEstimate& estimate) {
  return [seconds = estimate.cpuSeconds](const rt::TierObservation& seen) {
    return decideTiering(seen, seconds).compile;
  };
}

// Wraps out.model (the VM) in a tiered model whose second tier the JIT compiles in the background
// once `trigger` says so (at once without one). The compile thread holds the kernels and its own
// copy of the sources, so nothing it reads can go away while it runs.
void addBackgroundJit(const Compilation& c, bool invariants, rt::TierTrigger trigger, RunnableModel& out,
                      double compileSeconds = 0) {
  llvmbackend::JitOptions options = backgroundJitOptions(invariants);
  auto sources = std::make_shared<const SourceManager>(c.sources);
  out.what = "bytecode then llvm";
  out.model = rt::createTieredModel(
      std::move(out.model),
      [kernels = c.kernels, sources, options, jit = out.jit](const std::atomic<bool>& cancel) {
        llvmbackend::JitOptions withCancel = options;
        withCancel.cancel = &cancel;
        Result<ModelPtr> model = llvmbackend::createJitModel(kernels, *sources, withCancel, &jit->stats);
        if (!model) jit->error = model.error();
        return model ? std::move(model).value() : ModelPtr();
      },
      std::move(trigger), compileSeconds);
}

}  // namespace

RunnableModel makeRunnableModel(Compilation& c, Backend backend, bool invariants) {
  RunnableModel out;
  auto t0 = std::chrono::steady_clock::now();
  if (backend == Backend::Tiered) {
    llvmbackend::JitOptions background = backgroundJitOptions(invariants);
    out.jitEstimate = estimateCompile(*c.kernels, background, background.threads);
    double vmCall = vmCallSeconds(*c.kernels);
    if (compileFirst(out.jitEstimate, vmCall)) {
      backend = Backend::Native;
      out.decision = fmt::format(
          "tiering: compiled before the run: a residual call on the VM (~{:.3g} ms, {} kernel instructions) is "
          "expected to take longer than the whole compile (~{:.3g} ms of CPU)\n",
          vmCall * 1e3, kernel::executedInstructions(c.kernels->program(ModelProgram::Residual)),
          out.jitEstimate.cpuSeconds * 1e3);
    }
  }
  if (backend == Backend::Native) {
    if (compileNativeFirst(c, invariants, out)) {
      out.codegenSeconds = secondsSince(t0);
      return out;
    }
    out.warning = "the LLVM JIT failed (" + out.jit->error + "); running on the bytecode VM instead";
  }
  if (loadBytecode(c, out) && backend == Backend::Tiered) {
    // The estimate errs long (TieringPolicy.cpp): a call waits for native code only when even
    // that is shorter than a call on the VM.
    addBackgroundJit(c, invariants, policyTrigger(out.jitEstimate), out, out.jitEstimate.cpuSeconds);
  } else if (out.model && backend == Backend::Background) {
    addBackgroundJit(c, invariants, {}, out);
  }
  out.codegenSeconds = secondsSince(t0);
  return out;
}

namespace {

// --stats: what the tiering policy weighed and decided.
void printTieringDecision(const RunnableModel& m, const rt::TierReport& tiers, std::ostream& log) {
  const CompileEstimate& e = m.jitEstimate;
  const rt::TierObservation& seen = tiers.startedAt;
  log << "tiering: the JIT of the residual, Jacobian and outputs (" << e.optimisedInstructions << " kernel instructions at level 2, "
      << e.plainInstructions << " at level 0, " << e.units << " modules) is estimated at " << e.cpuSeconds * 1e3
      << " ms of CPU on " << e.threads << " thread(s)\n";
  TierVerdict v = decideTiering(seen, e.cpuSeconds);
  if (tiers.started && v.oneCallPays) {
    log << "tiering: compile started " << seen.elapsedSeconds * 1e3 << " ms into the run, at " << seen.progress * 100
        << " % of the horizon: the VM had spent " << seen.firstTierSeconds * 1e3 << " ms in " << seen.firstTierCalls
        << " residual/Jacobian/output calls; native code saves ~" << v.savingSeconds * 1e3
        << " ms of each, more than the whole compile\n";
  } else if (tiers.started) {
    log << "tiering: compile started " << seen.elapsedSeconds * 1e3 << " ms into the run, at " << seen.progress * 100
        << " % of the horizon: the VM had spent " << seen.firstTierSeconds * 1e3 << " ms in " << seen.firstTierCalls
        << " residual/Jacobian/output calls, projecting " << v.remainingVmSeconds * 1e3 << " ms more, of which native code saves ~"
        << v.savingSeconds * 1e3 << " ms ("
        << (seen.idleCores >= TieringRule{}.idleCore
                ? fmt::format(">= {:g} x the compile at an idle machine's speed, {:g} x the estimate: {:.2g} cores idle",
                              v.payback, TieringRule{}.idleCompileShare, seen.idleCores)
                : fmt::format(">= {:g} x the compile", v.payback))
        << ")\n";
  } else {
    log << "tiering: stayed on the VM: its " << seen.firstTierCalls << " residual/Jacobian/output calls took "
        << seen.firstTierSeconds * 1e3 << " ms of the run's " << seen.elapsedSeconds * 1e3
        << " ms; native code would never have saved "
        << (seen.idleCores >= TieringRule{}.idleCore ? fmt::format("{:g} x the compile at an idle machine's speed",
                                                                   TieringRule{}.idlePayback)
                                                     : fmt::format("{:g} x the compile", TieringRule{}.payback))
        << "\n";
  }
}

}  // namespace

std::optional<rt::TierReport> reportTiers(const RunnableModel& m, bool stats, std::ostream& log) {
  if (stats) log << m.decision;
  std::optional<rt::TierReport> tiers = rt::tierReport(m.model.get());
  if (!tiers) return tiers;
  const JitOutcome& jit = *m.jit;
  bool failed = !tiers->compiling && !tiers->ready && !jit.error.empty() && jit.error != "cancelled";
  if (failed) log << "qdot: warning: the LLVM JIT failed (" << jit.error << "); the run stayed on the bytecode VM\n";
  if (!stats) return tiers;
  if (m.jitEstimate.units > 0) printTieringDecision(m, *tiers, log);
  if (tiers->ready) {
    log << "jit: native code ready " << tiers->readySeconds * 1e3 << " ms after the VM started; "
        << tiers->firstTierCalls << " residual/Jacobian/output calls on the VM, " << tiers->secondTierCalls
        << " on native code";
    if (tiers->callsThatWaited > 0)
      log << " (" << tiers->callsThatWaited << " waited for it: a call on the VM took longer than what was left of the compile)";
    log << "\n";
    printJitStats(jit.stats, log);
  } else if (tiers->started && !failed) {
    log << "jit: the run ended before the native code was ready (all " << tiers->firstTierCalls
        << " residual/Jacobian/output calls on the VM)\n";
  }
  return tiers;
}

void printJitStats(const llvmbackend::JitStats& jit, std::ostream& log) {
  uint32_t functions = 0;
  for (uint32_t f : jit.functions) functions += f;
  log << "jit: " << functions << " functions in " << jit.units << " modules on " << jit.threads << " threads in "
      << jit.wallSeconds * 1e3 << " ms; lower " << jit.lowerSeconds * 1e3 << " ms, machine code "
      << jit.codegenSeconds * 1e3 << " ms (summed over threads), link " << jit.linkSeconds * 1e3 << " ms\n";
}

}  // namespace qdot::driver
