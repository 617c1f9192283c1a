// qdot wp: configurations × tolerances, each run in memory, its error against the reference on
// the output grid. The reference is computed once on that grid (all runs share it).
#include "driver/WorkPrecision.h"

#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>

#include "arkode/SolverChoice.h"
#include "driver/Backends.h"
#include "driver/WorkPrecisionExact.h"
#include "driver/WorkPrecisionReference.h"
#include "driver/WorkPrecisionReport.h"
#include "ida/ModelCheck.h"
#include "sim/Names.h"

namespace qdot::driver {
namespace {

/// The default ladder: 1e-2 … 1e-10, one rtol per decade.
std::vector<double> defaultLadder() {
  std::vector<double> rtols;
  for (int e = 2; e <= 10; ++e) rtols.push_back(std::pow(10.0, -e));
  return rtols;
}

struct Configuration {
  std::string backend, solver;
  std::string label() const { return backend + "/" + solver; }
};

/// Every backend × every solver, in the order given.
std::vector<Configuration> configurations(const WorkPrecisionOptions& o) {
  std::vector<std::string> backends = o.backends.empty() ? std::vector<std::string>{"llvm"} : o.backends;
  std::vector<std::string> solvers = o.solvers.empty() ? std::vector<std::string>{"ida"} : o.solvers;
  std::vector<Configuration> list;
  for (const std::string& b : backends)
    for (const std::string& s : solvers) list.push_back({b, s});
  return list;
}

Backend backendNamed(const std::string& name) { return name == "bytecode" ? Backend::Bytecode : Backend::Native; }

ErrorMeasure measureNamed(const std::string& name) {
  return name == "final" ? ErrorMeasure::Final : name == "scd" ? ErrorMeasure::Scd : ErrorMeasure::MaxAbs;
}

rt::ExperimentDefaults experimentOf(const dae::Dae& d) {
  return {d.experiment.startTime, d.experiment.stopTime, d.experiment.interval, d.experiment.tolerance};
}

/// Keeps every row in memory.
class MemorySink : public rt::ResultSink {
 public:
  void begin(std::span<const std::string>) override {}
  void row(double, std::span<const double> values) override { rows.emplace_back(values.begin(), values.end()); }
  void finish() override {}
  std::vector<std::vector<double>> rows;
};

/// One run of a compiled model at one tolerance.
struct Run {
  rt::SimulationResult result;
  std::vector<std::vector<double>> rows;
};

Run simulateAt(const QdotModel& model, rt::SimulationSettings settings, double rtol, std::optional<double> atol) {
  settings.rtol = rtol;
  settings.atol = atol;
  MemorySink sink;
  Run run;
  run.result = rt::simulate(model, settings, sink);
  run.rows = std::move(sink.rows);
  return run;
}

/// The error of one run against the reference (on the same grid), by the chosen measure.
double errorOf(const Run& run, const ReferenceValues& ref, ErrorMeasure measure) {
  std::size_t last = ref.values.front().size() - 1;
  double error = 0;
  for (std::size_t c = 0; c < ref.columns.size(); ++c) {
    std::size_t first = measure == ErrorMeasure::MaxAbs ? 0 : last;
    for (std::size_t k = first; k <= last; ++k) {
      double want = ref.values[c][k], got = run.rows[k][ref.columns[c]];
      double e = std::abs(got - want);
      if (measure == ErrorMeasure::Scd && want != 0) e /= std::abs(want);  // absolute where the reference is 0
      error = std::max(error, std::isnan(e) ? INFINITY : e);
    }
  }
  return error;
}

std::string errorDefinition(ErrorMeasure m, const std::vector<std::string>& columns) {
  std::string list;
  for (const std::string& c : columns) list += (list.empty() ? "" : ", ") + c;
  switch (m) {
    case ErrorMeasure::MaxAbs: return "max |y - y_ref| over the output grid and the columns " + list;
    case ErrorMeasure::Final: return "max |y - y_ref| at the final time over the columns " + list;
    case ErrorMeasure::Scd:
      return "scd = -log10(max |y - y_ref| / |y_ref| at the final time) over the columns " + list +
             " (significant correct digits, as in the IVP test set of Mazzia and Magherini; absolute where y_ref = 0)";
  }
  return "";
}

std::string outputPath(const WorkPrecisionOptions& o, const std::string& modelPath, const std::string& given,
                        const char* extension) {
  if (!given.empty()) return given;
  if (!o.outputPrefix.empty()) return o.outputPrefix + extension;
  if (modelPath == kStandardInput) return std::string("stdin.wp") + extension;
  std::filesystem::path p(modelPath);
  return (p.parent_path() / p.stem()).string() + ".wp" + extension;
}

bool writeText(const std::string& path, const std::string& text, std::ostream& log) {
  std::ofstream file(path, std::ios::binary);
  file << text;
  if (file.flush()) return true;
  log << "error: cannot write " << path << "\n";
  return false;
}

/// The settings every run shares, from the run options (rtol is set per run).
std::optional<rt::SimulationSettings> sharedSettings(const QdotModel& model, const WorkPrecisionOptions& o,
                                                     const rt::ExperimentDefaults& experiment, std::ostream& log) {
  try {
    rt::RunOptions run = o.run;
    run.rtol = 1e-6;  // checked per rung below
    return rt::resolveRunOptions(run, experiment, model).settings;
  } catch (const std::exception& e) {
    log << "error: " << e.what() << "\n";
    return std::nullopt;
  }
}

bool checkLadder(const std::vector<double>& rtols, std::ostream& log) {
  for (double r : rtols)
    if (!(r > 0 && r < 1)) {
      log << fmt::format("error: --rtols: every tolerance must lie between 0 and 1 (got {})\n", r);
      return false;
    }
  return true;
}

NameValues parameterValues(const QdotModel& model, const std::vector<double>& values) {
  NameValues names;
  auto list = rt::nameList(model.parameterNames, model.nParameters);
  for (std::size_t i = 0; i < list.size(); ++i) names.emplace(std::string(list[i]), values[i]);
  return names;
}

/// A compiled model per backend, and what compiling it cost.
struct Compiled {
  RunnableModel runnable;
  double compileSeconds = 0;
};

std::optional<Compiled> compileFor(Compilation& c, const std::string& backend, std::ostream& log) {
  Compiled out;
  out.runnable = makeRunnableModel(c, backendNamed(backend), false);
  if (!out.runnable.model) {
    log << "qdot: internal error: " << out.runnable.error << "\n";
    return std::nullopt;
  }
  if (!out.runnable.warning.empty()) log << "qdot: warning: " << out.runnable.warning << "\n";
  out.compileSeconds = c.times.frontEnd() + out.runnable.codegenSeconds;
  return out;
}

WpPoint measure(const Compiled& compiled, const rt::SimulationSettings& settings, double rtol,
                std::optional<double> atol, const ReferenceValues& ref, ErrorMeasure m) {
  Run run = simulateAt(*compiled.runnable.model, settings, rtol, atol);
  WpPoint p;
  p.rtol = rtol;
  p.atol = atol;
  p.success = run.result.success;
  p.failure = run.result.success ? "" : fmt::format("at t = {:.6g}: {}", run.result.failureTime, run.result.message);
  p.error = run.result.success ? errorOf(run, ref, m) : 0;
  p.compileSeconds = compiled.compileSeconds;
  p.setupSeconds = run.result.setupSeconds;
  p.solveSeconds = run.result.solveSeconds;
  p.stats = run.result.stats;
  return p;
}

/// The reference in the order of preference: --exact, --reference, a run 100× tighter than the
/// tightest rung. nullopt after an error (printed); `code` says which exit code.
std::optional<ReferenceValues> referenceFor(Compilation& c, const WorkPrecisionOptions& o, const Compiled& first,
                                            const rt::SimulationSettings& settings, const std::vector<double>& rtols,
                                            const std::vector<double>& times, std::ostream& log, ExitCode& code) {
  const QdotModel& model = *first.runnable.model;
  std::vector<std::string> columns;
  for (const rt::Column& column : rt::defaultColumns(model, false)) columns.push_back(column.name);
  if (!o.exact.empty()) {
    auto ref = exactReference(o.exact, columns, parameterValues(model, settings.parameters), times, c.sources, c.diags);
    if (!ref) c.diags.render(log, c.sources, isatty(2));
    code = ExitCode::Usage;
    return ref;
  }
  if (!o.reference.empty()) {
    try {
      return csvReference(o.reference, columns, times);
    } catch (const std::exception& e) {
      log << "error: " << e.what() << "\n";
      code = ExitCode::Usage;
      return std::nullopt;
    }
  }
  double rtol = rtols.back() / 100;
  std::optional<double> atol = o.run.atol ? std::optional<double>(*o.run.atol / 100) : std::nullopt;
  Run run = simulateAt(model, settings, rtol, atol);
  if (!run.result.success) {
    log << fmt::format("error: the reference run at rtol {:g} failed at t = {:.6g}: {}\nhelp: give the reference with "
                       "--exact or --reference, or a ladder that ends at a looser rtol\n",
                       rtol, run.result.failureTime, run.result.message);
    code = ExitCode::SimulationFailed;
    return std::nullopt;
  }
  std::string atolText = atol ? fmt::format("atol {:g}", *atol) : "automatic atol";
  return runReference(run.rows, columns,
                      fmt::format("a run at rtol {:g} ({}; 100x below the tightest rtol; backend {}); its own error "
                                  "shows as a floor",
                                  rtol, atolText, first.runnable.what));
}

std::vector<double> ladderOf(const WorkPrecisionOptions& o) {
  std::vector<double> rtols = o.rtols.empty() ? defaultLadder() : o.rtols;
  std::sort(rtols.begin(), rtols.end(), std::greater<>());
  rtols.erase(std::unique(rtols.begin(), rtols.end()), rtols.end());
  return rtols;
}

}  // namespace

void addWorkPrecisionOptions(CLI::App& cmd, WorkPrecisionOptions& o) {
  cmd.add_option("--rtols", o.rtols, "the relative tolerances, comma-separated (default 1e-2,1e-3,...,1e-10)")
      ->delimiter(',');
  cmd.add_option("--atol", o.run.atol, "absolute tolerance of every run (default: automatic scales, as qdot run)");
  cmd.add_option("--exact", o.exact, "an exact solution NAME = EXPRESSION of time and the parameters (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--reference", o.reference, "a CSV file with the reference solution (header: time, then names)");
  cmd.add_option("--error", o.error, "error measure: maxabs (default; over the output grid), final, or scd")
      ->check(CLI::IsMember({"maxabs", "final", "scd"}));
  cmd.add_option("--backend", o.backends, "backends to compare, comma-separated: llvm (default), bytecode")
      ->delimiter(',')
      ->check(CLI::IsMember({"llvm", "bytecode"}));
  cmd.add_option("--solver", o.solvers, "solvers to compare, comma-separated: ida (default), arkode, auto")
      ->delimiter(',')
      ->check(CLI::IsMember({"ida", "arkode", "auto"}));
  cmd.add_option("-o,--output", o.outputPrefix,
                 "write PREFIX.csv and PREFIX.svg (default: next to the model, MODEL.wp.csv and MODEL.wp.svg)");
  cmd.add_option("--csv", o.csvPath, "write the table as CSV to this file (overrides -o)");
  cmd.add_option("--svg", o.svgPath, "write the work-precision diagram to this SVG file (overrides -o)");
  cmd.add_option("--start", o.run.start, "start time (default: experiment annotation, else 0)");
  cmd.add_option("--stop", o.run.stop, "stop time (default: experiment annotation, else 1)");
  cmd.add_option("--interval", o.run.interval, "output interval: the grid the error is measured on");
  cmd.add_option("-p,--parameter", o.run.parameters, "set a parameter: -p NAME=VALUE (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--linear-solver", o.run.linearSolver, "dense, klu or auto (default auto)")
      ->check(CLI::IsMember({"auto", "dense", "klu"}));
  cmd.add_option("--max-steps", o.run.maxSteps, "steps allowed per run (a run beyond is a failed row)");
}

ExitCode workPrecision(Compilation& c, const std::string& modelPath, const WorkPrecisionOptions& o, std::ostream& out,
                       std::ostream& log) {
  std::vector<double> rtols = ladderOf(o);
  if (!checkLadder(rtols, log)) return ExitCode::Usage;
  std::vector<Configuration> configs = configurations(o);
  std::map<std::string, Compiled> compiled;
  for (const Configuration& config : configs) {
    if (compiled.count(config.backend)) continue;
    std::optional<Compiled> model = compileFor(c, config.backend, log);
    if (!model) return ExitCode::Internal;
    compiled.emplace(config.backend, std::move(*model));
  }
  const Compiled& first = compiled.at(configs.front().backend);
  std::optional<rt::SimulationSettings> settings = sharedSettings(*first.runnable.model, o, experimentOf(*c.dae), log);
  if (!settings) return ExitCode::Usage;
  rt::OutputGrid grid(settings->start, settings->stop, settings->interval);
  std::vector<double> times;
  for (std::size_t k = 0; k < grid.size(); ++k) times.push_back(grid[k]);
  ExitCode failure = ExitCode::Usage;
  std::optional<ReferenceValues> ref = referenceFor(c, o, first, *settings, rtols, times, log, failure);
  if (!ref) return failure;

  WpStudy study;
  study.model = c.dae->name;
  study.file = modelPath;
  study.measure = measureNamed(o.error);
  study.errorDefinition = errorDefinition(study.measure, ref->names);
  study.reference = ref->description;
  study.start = settings->start;
  study.stop = settings->stop;
  study.outputTimes = times.size();
  for (const Configuration& config : configs) {
    WpSeries& series = study.series.emplace_back();
    series.label = config.label();
    series.backend = config.backend;
    series.solver = config.solver;
    rt::SimulationSettings configured = *settings;
    configured.solver = *rt::parseSolver(config.solver);  // checked by the option
    for (double rtol : rtols)
      series.points.push_back(measure(compiled.at(config.backend), configured, rtol, o.run.atol, *ref, study.measure));
    series.fit = fitProportionality(series.points);
  }
  printTable(study, out);
  std::string csv = outputPath(o, modelPath, o.csvPath, ".csv"), svg = outputPath(o, modelPath, o.svgPath, ".svg");
  if (!writeText(csv, studyCsv(study), log) || !writeText(svg, studySvg(study), log)) return ExitCode::Usage;
  out << "\nwrote " << csv << " and " << svg << "\n";
  return ExitCode::Success;
}

}  // namespace qdot::driver
