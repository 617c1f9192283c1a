// Run options: CLI11 registration, defaults from the experiment annotation, validation with
// clear sentences, and the -p list turned into the parameters() arrays.
#include "sim/RunOptions.h"

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "ida/ModelCheck.h"

namespace qdot::rt {

void addRunOptions(CLI::App& app, RunOptions& o) {
  app.add_option("--start", o.start, "start time (default: experiment annotation, else 0)");
  app.add_option("--stop", o.stop, "stop time (default: experiment annotation, else 1)");
  app.add_option("--interval", o.interval, "output interval (default: (stop - start) / 500)");
  app.add_option("--rtol", o.rtol, "relative tolerance (default: experiment annotation, else 1e-6)");
  app.add_option("--atol", o.atol,
                 "absolute tolerance in each variable's units (times its nominal, if it has one); default: "
                 "automatic per-variable scales (docs/accuracy.md)");
  app.add_option("-p,--parameter", o.parameters, "set a parameter: -p NAME=VALUE (repeatable)")
      ->type_name("NAME=VALUE")
      ->allow_extra_args(false);
  app.add_option("--outputs", o.outputs, "only these result columns, comma-separated")
      ->delimiter(',')
      ->allow_extra_args(false);
  app.add_option("-o,--output", o.outputPath, "write the CSV results to this file (default: standard output)");
  app.add_flag("--stats", o.stats, "print solver statistics and timing to standard error");
  app.add_flag("--invariants", o.invariants, "add the model's invariants (energy, momenta) as columns");
  app.add_option("--linear-solver", o.linearSolver, "dense, klu or auto (default auto)")
      ->check(CLI::IsMember({"auto", "dense", "klu"}));
  app.add_flag("!--no-row-elimination", o.rowElimination,
               "klu: factor IDA's whole Newton matrix, without first solving its two-entry rows (the kinematic rows "
               "der(q) = v) for one of their unknowns");
  // --solver (issue 11, section 3)
  app.add_option("--solver", o.solver,
                 "ida (BDF, any model; default), arkode (an L-stable ESDIRK method: models that are ODEs in their "
                 "derivatives, e.g. stiff oscillations) or auto (chosen from the linearization at the start)")
      ->check(CLI::IsMember({"ida", "arkode", "auto"}));
  app.add_option("--preserve", o.preserve,
                 "invariants: after every step, project the state onto the start values of the model's invariants "
                 "(energy, momenta); needs --solver arkode")
      ->check(CLI::IsMember({"invariants"}));
  app.add_option("--csv-names", o.csvNames,
                 "CSV header: modelica (der(x), x[1]; default) or identifier (der_x, x_1: for numpy and other "
                 "tools that take identifiers only)")
      ->check(CLI::IsMember({"modelica", "identifier"}));
  app.add_option("--max-steps", o.maxSteps, "stop with an error after this many solver steps (the rows so far are kept)");
  app.add_flag("--force", o.force, "write the output even if it has more than 10^7 rows");
  app.add_flag("!--no-progress", o.progress, "never show progress (otherwise shown on a terminal for runs of more than 3 s)");
}

std::optional<double> parseNumber(std::string_view text) {
  double value = 0;
  const char* end = text.data() + text.size();
  auto [stop, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || stop != end || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::string numberRejection(std::string_view text) {
  double value = 0;
  const char* end = text.data() + text.size();
  auto [stop, ec] = std::from_chars(text.data(), end, value);
  if (ec == std::errc::result_out_of_range && stop == end) {  // a number, but not a double's
    bool tooLarge = std::fabs(std::strtod(std::string(text).c_str(), nullptr)) > 1;
    return tooLarge ? fmt::format("is out of range: '{}' is larger than the largest number (about 1.8e308)", text)
                    : fmt::format("is out of range: '{}' is closer to zero than the smallest number (about 4.9e-324); "
                                  "write 0 if zero is meant",
                                  text);
  }
  return fmt::format("is not a number: '{}'", text);
}

namespace {

std::size_t parameterIndex(const QdotModel& model, std::string_view name) {
  auto names = nameList(model.parameterNames, model.nParameters);
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return i;
  throw UsageError(unknownNameMessage("parameter", name, names));
}

void requireFinite(std::string_view option, double value) {
  if (!std::isfinite(value)) throw UsageError(fmt::format("{} must be a finite number", option));
}

void checkTolerances(double rtol, std::optional<double> atol) {
  requireFinite("--rtol", rtol);
  if (rtol <= 0) throw UsageError(fmt::format("--rtol must be positive (got {})", rtol));
  if (rtol >= 1) throw UsageError(fmt::format("--rtol must be below 1 (got {}); e.g. 1e-6", rtol));
  if (atol) {
    requireFinite("--atol", *atol);
    if (*atol <= 0) throw UsageError(fmt::format("--atol must be positive (got {})", *atol));
  }
}

// issue 11, section 5: below a few ulps no integrator can deliver the relative accuracy asked for
// (each step's rounding alone is larger), so the request is refused before anything runs.
void checkRoundOffFloor(double rtol) {
  if (rtol >= kRoundOffFloor) return;
  throw UsageError(fmt::format("--rtol {:g} is below the round-off floor of double precision ({:.2g} = 10 × machine "
                               "epsilon): every step's rounding is larger than that, so no solver can deliver it; use "
                               "--rtol 1e-14 or larger (1e-10 already gives a tight reference solution)",
                               rtol, kRoundOffFloor));
}

void checkTimes(double start, double stop, double interval) {
  requireFinite("--start", start);
  requireFinite("--stop", stop);
  requireFinite("--interval", interval);
  if (stop <= start)
    throw UsageError(fmt::format("the stop time ({}) must be greater than the start time ({})", stop, start));
  if (interval <= 0) throw UsageError(fmt::format("--interval must be positive (got {})", interval));
  if (interval > stop - start)
    throw UsageError(fmt::format("--interval ({}) is longer than the simulated span [{}, {}]", interval, start, stop));
}

// The row count is computed as a double first: an interval of 1e-300 must be refused, not overflow.
void checkRowCount(double start, double stop, double interval, bool force) {
  double rows = std::floor((stop - start) / interval) + 1;
  if (rows <= kMaxRowsWithoutForce || force) return;
  std::string count = rows < 1e15 ? fmt::format("{:.0f}", rows) : fmt::format("{:.3g}", rows);
  throw UsageError(fmt::format("--interval {} would write {} rows over [{}, {}] (more than {:.0e}); give a longer "
                               "--interval, or --force if that many rows are meant",
                               interval, count, start, stop, kMaxRowsWithoutForce));
}

}  // namespace

ParameterOverrides parameterOverrides(const QdotModel& model, const std::vector<std::string>& assignments) {
  ParameterOverrides result{std::vector<double>(model.nParameters, 0.0), std::vector<uint8_t>(model.nParameters, 0)};
  std::vector<std::string> givenAs(model.nParameters);
  for (const std::string& assignment : assignments) {
    std::size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
      throw UsageError(fmt::format("-p expects NAME=VALUE, got '{}'", assignment));
    std::string_view name = std::string_view(assignment).substr(0, eq);
    std::string_view text = std::string_view(assignment).substr(eq + 1);
    std::size_t i = parameterIndex(model, name);
    std::optional<double> value = parseNumber(text);
    if (!value) throw UsageError(fmt::format("the value of parameter '{}' {}", name, numberRejection(text)));
    if (result.overridden[i])
      throw UsageError(fmt::format("parameter '{}' is given twice (-p {} and -p {})", name, givenAs[i], assignment));
    result.given[i] = *value;
    result.overridden[i] = 1;
    givenAs[i] = assignment;
  }
  return result;
}

std::vector<double> evaluateParameters(const QdotModel& model, const ParameterOverrides& overrides) {
  std::vector<double> p(model.nParameters, 0.0);
  if (model.parameters(&model, overrides.given.data(), overrides.overridden.data(), p.data()) != 0)
    throw std::runtime_error(fmt::format("the parameter values could not be computed: {}", modelLastError(model)));
  auto names = nameList(model.parameterNames, model.nParameters);
  for (std::size_t i = 0; i < p.size(); ++i)
    if (!std::isfinite(p[i])) throw std::runtime_error(fmt::format("parameter '{}' evaluates to {}", names[i], p[i]));
  return p;
}

ResolvedRun resolveRunOptions(const RunOptions& o, const ExperimentDefaults& e, const QdotModel& model) {
  ResolvedRun run;
  SimulationSettings& s = run.settings;
  s.start = o.start.value_or(e.start.value_or(0.0));
  s.stop = o.stop.value_or(e.stop.value_or(kDefaultStop));
  bool spanChanged = o.start.has_value() || o.stop.has_value();
  double fallback = (s.stop - s.start) / kDefaultIntervals;
  s.interval = o.interval.value_or(spanChanged ? fallback : e.interval.value_or(fallback));
  checkTimes(s.start, s.stop, s.interval);
  checkRowCount(s.start, s.stop, s.interval, o.force);
  if (o.maxSteps && *o.maxSteps <= 0) throw UsageError(fmt::format("--max-steps must be positive (got {})", *o.maxSteps));
  s.maxSteps = o.maxSteps;
  s.rtol = o.rtol.value_or(e.tolerance.value_or(kDefaultRtol));
  s.atol = o.atol;
  checkTolerances(s.rtol, s.atol);
  checkRoundOffFloor(s.rtol);
  auto solver = parseLinearSolver(o.linearSolver);
  if (!solver) throw UsageError(fmt::format("--linear-solver must be dense, klu or auto (got '{}')", o.linearSolver));
  s.linearSolver = *solver;
  s.eliminateTwoEntryRows = o.rowElimination;
  s.invariants = o.invariants;
  // --solver (issue 11, section 3)
  auto integrator = parseSolver(o.solver);
  if (!integrator) throw UsageError(fmt::format("--solver must be ida, arkode or auto (got '{}')", o.solver));
  s.solver = *integrator;
  if (!o.preserve.empty() && o.preserve != "invariants")
    throw UsageError(fmt::format("--preserve must be invariants (got '{}')", o.preserve));
  s.preserveInvariants = o.preserve == "invariants";
  if (s.preserveInvariants && s.solver != SolverKind::Arkode)
    throw UsageError("--preserve invariants needs --solver arkode: the projection changes the state after every "
                     "step, which a one-step method takes in its stride but which would invalidate IDA's multistep "
                     "history");
  if (s.preserveInvariants && model.nInvariants == 0)
    throw UsageError("--preserve invariants: the model has no invariants (no energy or momentum is conserved: it is "
                     "damped, forced or driven)");
  if (!o.outputs.empty()) s.columns = selectColumns(model, o.outputs, o.invariants);
  s.parameters = evaluateParameters(model, parameterOverrides(model, o.parameters));
  run.outputPath = o.outputPath;
  if (o.csvNames != "modelica" && o.csvNames != "identifier")
    throw UsageError(fmt::format("--csv-names must be modelica or identifier (got '{}')", o.csvNames));
  run.csvNames = o.csvNames == "identifier" ? ColumnNaming::Identifier : ColumnNaming::Modelica;
  run.stats = o.stats;
  run.progress = o.progress;
  return run;
}

}  // namespace qdot::rt
