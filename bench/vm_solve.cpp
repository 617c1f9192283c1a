// vm_solve: `qdot run --backend bytecode|llvm` in one process, for timing the solve. It makes the calls
// qdot's command line makes (compiler/driver/main.cpp runSimulate, runtime/sim/Run.cpp runModel):
// compile through the driver (driver::compileFile, driver::makeRunnableModel: the VM model with
// --backend bytecode, the default, or the JIT model compiled first with --backend llvm, as
// qdot run --jit-wait), then rt::resolveRunOptions, rt::CsvWriter and
// rt::simulate — but repeats the simulation and reports the solve's wall time at full precision
// (`qdot run --stats` rounds it to milliseconds) together with IDA's counters. --breakdown adds
// one more run with the model's residual and Jacobian timed (their function pointers wrapped).
//   vm_solve MODEL.qd [--backend bytecode|llvm] [--repeat R] [--breakdown] [--json FILE] [the options of qdot run: --stop, -o, ...]
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <fstream>
#include <iostream>
#include <memory>

#include "driver/Backends.h"
#include "output/CsvWriter.h"
#include "sim/RunOptions.h"
#include "sim/StatsReport.h"

namespace {

using namespace qdot;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// The VM model of a file and the compile time in seconds (front end, kernels, bytecode).
struct Compiled {
  std::unique_ptr<QdotModel, void (*)(QdotModel*)> model{nullptr, nullptr};
  rt::ExperimentDefaults experiment;
  double compileSeconds = 0;
  double kernelSeconds = 0, codegenSeconds = 0;  ///< the last two stages of compileSeconds
  driver::StageTimes times;                      ///< parse .. kernel
};

Compiled compile(const std::string& file, const std::string& backend, bool invariants) {
  driver::Compilation c;
  c.options.eliminateAlgebraics = true;  // the system qdot run integrates (dae/ExplicitAlgebraics.h)
  if (!driver::compileFile(c, file, "", driver::Stage::Kernel)) {
    c.diags.render(std::cerr, c.sources);
    throw std::runtime_error("the model has errors");
  }
  // As qdot run --backend llvm --jit-wait or --backend bytecode: compile time before the first step.
  driver::Backend chosen = backend == "llvm" ? driver::Backend::Native : driver::Backend::Bytecode;
  driver::RunnableModel runnable = driver::makeRunnableModel(c, chosen, invariants);
  if (!runnable.model) throw std::runtime_error(runnable.error);
  if (!runnable.warning.empty()) throw std::runtime_error(runnable.warning);
  Compiled out;
  out.kernelSeconds = c.times.kernel;
  out.codegenSeconds = runnable.codegenSeconds;
  QdotModel* model = runnable.model.release();
  out.model = {model, model->destroy};
  out.times = c.times;
  out.compileSeconds = c.times.frontEnd() + out.codegenSeconds;
  const auto& e = c.dae->experiment;
  out.experiment = {e.startTime, e.stopTime, e.interval, e.tolerance};
  return out;
}

/// Wall time inside the model's residual and Jacobian. The ABI's functions carry no user data of
/// their own, so the originals and the sums live here.
struct CallbackClock {
  decltype(QdotModel::residual) residual = nullptr;
  decltype(QdotModel::jacobian) jacobian = nullptr;
  double residualSeconds = 0, jacobianSeconds = 0;
  long residualCalls = 0, jacobianCalls = 0;
} callbackClock;

int timedResidual(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double* F) {
  auto t0 = Clock::now();
  int rc = callbackClock.residual(self, t, y, yp, p, F);
  callbackClock.residualSeconds += secondsSince(t0);
  ++callbackClock.residualCalls;
  return rc;
}

int timedJacobian(const QdotModel* self, double t, const double* y, const double* yp, const double* p, double cj,
                  double* values) {
  auto t0 = Clock::now();
  int rc = callbackClock.jacobian(self, t, y, yp, p, cj, values);
  callbackClock.jacobianSeconds += secondsSince(t0);
  ++callbackClock.jacobianCalls;
  return rc;
}

/// Routes the model's residual and Jacobian through the timing wrappers.
void timeCallbacks(QdotModel& model) {
  callbackClock.residual = model.residual;
  callbackClock.jacobian = model.jacobian;
  model.residual = timedResidual;
  model.jacobian = timedJacobian;
}

rt::SimulationResult simulateOnce(const QdotModel& model, const rt::ResolvedRun& run) {
  std::unique_ptr<rt::CsvWriter> writer =
      run.outputPath.empty() ? std::make_unique<rt::CsvWriter>(std::cout, run.csvNames)
                             : rt::CsvWriter::openFile(run.outputPath, run.csvNames);
  rt::SimulationResult result = rt::simulate(model, run.settings, *writer);
  if (!result.success) throw std::runtime_error(result.message);
  return result;
}

void writeJson(const std::string& path, const Compiled& c, const rt::SimulationResult& r,
               const std::vector<double>& solves, double breakdownSolve) {
  const rt::SolverStats& s = r.stats;
  std::ofstream out(path);
  out.precision(17);
  out << "{\"solve\": " << *std::min_element(solves.begin(), solves.end()) << ", \"solves\": [";
  for (std::size_t i = 0; i < solves.size(); ++i) out << (i ? ", " : "") << solves[i];
  const auto& t = c.times;
  out << "], \"setup\": " << r.setupSeconds << ", \"compile\": " << c.compileSeconds << ", \"stages\": {\"parse\": "
      << t.parse << ", \"check\": " << t.check << ", \"flatten\": " << t.flatten << ", \"derive\": " << t.derive
      << ", \"dae\": " << t.dae << ", \"kernel\": " << c.kernelSeconds << ", \"codegen\": " << c.codegenSeconds << "}" << ", \"steps\": " << s.steps
      << ", \"residuals\": " << s.residualEvaluations << ", \"jacobians\": " << s.jacobianEvaluations
      << ", \"iterations\": " << s.nonlinearIterations << ", \"errorTestFailures\": " << s.errorTestFailures
      << ", \"convergenceFailures\": " << s.convergenceFailures << ", \"rows\": " << r.rows
      << ", \"calcIC\": " << (r.computedInitialValues ? "true" : "false") << ", \"atolMin\": " << r.tolerances.atolMin
      << ", \"atolMedian\": " << r.tolerances.atolMedian << ", \"atolMax\": " << r.tolerances.atolMax;
  if (breakdownSolve > 0) {
    const CallbackClock& b = callbackClock;
    out << ", \"breakdown\": {\"solve\": " << breakdownSolve << ", \"residualSeconds\": " << b.residualSeconds
        << ", \"residualCalls\": " << b.residualCalls << ", \"jacobianSeconds\": " << b.jacobianSeconds
        << ", \"jacobianCalls\": " << b.jacobianCalls << "}";
  }
  out << "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"qdot run --backend bytecode|llvm in-process, timing the solve at full precision (bench/)"};
  std::string file, json, backend = "bytecode";
  int repeat = 1;
  bool breakdown = false;
  rt::RunOptions options;
  app.add_option("file", file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  app.add_option("--backend", backend, "bytecode (the VM, default) or llvm (the JIT), as qdot run")
      ->check(CLI::IsMember({"bytecode", "llvm"}));
  app.add_option("--repeat", repeat, "simulate this many times, report the fastest solve")->check(CLI::PositiveNumber);
  app.add_flag("--breakdown", breakdown, "one more run timing the model's residual and Jacobian");
  app.add_option("--json", json, "write the counters and times as JSON to this file");
  rt::addRunOptions(app, options);
  CLI11_PARSE(app, argc, argv);
  try {
    Compiled c = compile(file, backend, options.invariants);
    rt::ResolvedRun run = rt::resolveRunOptions(options, c.experiment, *c.model);
    rt::SimulationResult result;
    std::vector<double> solves;
    for (int r = 0; r < repeat; ++r) {
      result = simulateOnce(*c.model, run);
      solves.push_back(result.solveSeconds);
    }
    double breakdownSolve = 0;
    if (breakdown) {
      timeCallbacks(*c.model);
      breakdownSolve = simulateOnce(*c.model, run).solveSeconds;
    }
    if (run.stats) std::cerr << rt::formatStats(result);
    if (!json.empty()) writeJson(json, c, result, solves, breakdownSolve);
  } catch (const std::exception& e) {
    std::cerr << "vm_solve: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
