// reference_sim: the hand-written reference programs of the simulation benchmark — the N-link
// pendulum (dense), the spring–damper chain (KLU) and n free rigid bodies (KLU), residual and Jacobian coded by hand
// (bench/reference/), integrated by SUNDIALS IDA exactly as `qdot run` integrates the .qd models.
//   reference_sim nlink|chain|bodies --n N [--stop S] [--interval I] [--rtol R] [--atol A] [-o FILE]
//                 [--outputs a,b] [--stats] [--repeat R] [--breakdown] [--json FILE]
// --repeat runs the whole simulation R times and reports the fastest solve; --breakdown adds one
// more run with the residual and Jacobian timed; --json writes the counters and times for
// bench/sim_bench.py.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>

#include "reference/FreeBodies.h"
#include "reference/IdaRun.h"
#include "reference/NLinkPendulum.h"
#include "reference/SpringChain.h"
#include "reference/TimedModel.h"

namespace {

using namespace qdot::bench;

struct Options {
  std::string model;
  int n = 0;
  std::optional<double> stop, interval, atol;
  double rtol = 1e-6;
  std::string output;
  std::vector<std::string> columns;
  bool stats = false;
  int repeat = 1;
  bool breakdown = false;
  std::string json;
};

std::unique_ptr<ReferenceModel> makeModel(const Options& o) {
  if (o.model == "nlink") return std::make_unique<NLinkPendulum>(o.n > 0 ? o.n : 8);
  if (o.model == "bodies") return std::make_unique<FreeBodies>(o.n > 0 ? o.n : 100);
  return std::make_unique<SpringChain>(o.n > 0 ? o.n : 10);
}

/// qdot's defaults: the experiment annotation (nlink.qd: StopTime 5, Interval 0.01;
/// spring_chain.qd: StopTime 1, Interval 0.01) unless the stop is given, then 500 intervals.
RunSettings settingsFor(const Options& o, const ReferenceModel& model) {
  RunSettings s;
  s.stop = o.stop.value_or(o.model == "nlink" ? 5.0 : 1.0);  // bodies: rigid_bench.py gives --stop
  s.interval = o.interval.value_or(o.stop ? (s.stop - s.start) / 500 : 0.01);
  s.rtol = o.rtol;
  s.atol = o.atol;
  s.outputPath = o.output;
  std::vector<std::string> names = model.variableNames();
  for (const std::string& name : o.columns) {
    auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw std::runtime_error("--outputs: no variable named " + name);
    s.columns.push_back(static_cast<uint32_t>(it - names.begin()));
  }
  return s;
}

void writeJson(const std::string& path, const RunResult& r, const std::vector<double>& solves, const TimedModel* timed,
               double breakdownSolve) {
  std::ofstream out(path);
  out.precision(17);
  out << "{\"solve\": " << *std::min_element(solves.begin(), solves.end()) << ", \"solves\": [";
  for (std::size_t i = 0; i < solves.size(); ++i) out << (i ? ", " : "") << solves[i];
  out << "], \"setup\": " << r.setupSeconds << ", \"steps\": " << r.steps
      << ", \"residuals\": " << r.residualEvaluations << ", \"jacobians\": " << r.jacobianEvaluations
      << ", \"iterations\": " << r.nonlinearIterations << ", \"errorTestFailures\": " << r.errorTestFailures
      << ", \"convergenceFailures\": " << r.convergenceFailures << ", \"rows\": " << r.rows
      << ", \"calcIC\": " << (r.computedInitialValues ? "true" : "false") << ", \"atolMin\": " << r.tolerances.atolMin
      << ", \"atolMedian\": " << r.tolerances.atolMedian << ", \"atolMax\": " << r.tolerances.atolMax;
  if (timed) {
    out << ", \"breakdown\": {\"solve\": " << breakdownSolve << ", \"residualSeconds\": " << timed->residualSeconds
        << ", \"residualCalls\": " << timed->residualCalls << ", \"jacobianSeconds\": " << timed->jacobianSeconds
        << ", \"jacobianCalls\": " << timed->jacobianCalls << "}";
  }
  out << "}\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Hand-written IDA reference programs for bench/ (N-link pendulum, spring chain)"};
  Options o;
  app.add_option("model", o.model, "nlink, chain or bodies")->required()->check(CLI::IsMember({"nlink", "chain", "bodies"}));
  app.add_option("--n", o.n, "links (nlink, default 8) or masses (chain, default 10)");
  app.add_option("--stop", o.stop, "stop time [s]");
  app.add_option("--interval", o.interval, "output interval [s]");
  app.add_option("--rtol", o.rtol, "relative tolerance (default 1e-6)");
  app.add_option("--atol", o.atol, "absolute tolerance before scaling (default: rtol)");
  app.add_option("-o", o.output, "CSV file (default: standard output)");
  app.add_option("--outputs", o.columns, "columns after time (default: all variables)")->delimiter(',');
  app.add_flag("--stats", o.stats, "print the counters and wall times to standard error");
  app.add_option("--repeat", o.repeat, "simulate this many times, report the fastest solve")
      ->check(CLI::PositiveNumber);
  app.add_flag("--breakdown", o.breakdown, "one more run timing the residual and Jacobian");
  app.add_option("--json", o.json, "write the counters and times as JSON to this file");
  CLI11_PARSE(app, argc, argv);
  try {
    std::unique_ptr<ReferenceModel> model = makeModel(o);
    RunSettings settings = settingsFor(o, *model);
    RunResult result;
    std::vector<double> solves;
    for (int r = 0; r < o.repeat; ++r) {
      result = simulateReference(*model, settings);
      solves.push_back(result.solveSeconds);
    }
    TimedModel timed(*model);
    double breakdownSolve = o.breakdown ? simulateReference(timed, settings).solveSeconds : 0;
    if (o.stats) std::cerr << formatStats(result);
    if (!o.json.empty()) writeJson(o.json, result, solves, o.breakdown ? &timed : nullptr, breakdownSolve);
  } catch (const std::exception& e) {
    std::cerr << "reference_sim: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
