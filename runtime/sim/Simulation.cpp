// simulate(): set up an IdaSession, make the start consistent, then IDASolve (IDA_NORMAL) towards
// each output time with the stop time set, writing a row after each. Model outputs and invariants
// are evaluated only when a selected column needs them.
#include <cstdlib>
#include <cstdio>
#include "sim/Simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <set>

#include "arkode/ArkodeSession.h"
#include "ida/ModelCheck.h"
#include "output/AngleUnwrap.h"
#include "sim/Names.h"
#include "sim/MemoryReuse.h"
#include "sim/PeakMemory.h"

namespace qdot::rt {
namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void appendColumns(std::vector<Column>& columns, Column::Source source, const char* const* names, uint32_t count) {
  auto list = nameList(names, count);
  for (uint32_t i = 0; i < count; ++i)
    columns.push_back({source, i, std::string(list[i])});
}

/// Evaluates the selected columns at one time: y directly, outputs and invariants via the model.
class RowBuilder {
 public:
  RowBuilder(const QdotModel& model, const std::vector<Column>& columns, std::span<const double> p)
      : model_(model), columns_(columns), p_(p), values_(columns.size()),
        unwrap_(model.outputKinds ? std::span<const int32_t>(model.outputKinds, model.nOutputs) : std::span<const int32_t>()) {
    for (const Column& c : columns) {
      needOutputs_ |= c.source == Column::Source::Output;
      needInvariants_ |= c.source == Column::Source::Invariant;
    }
    outputs_.resize(model.nOutputs);
    invariants_.resize(model.nInvariants);
  }

  /// Whether outputs are unwrapped (then every solver step should be observed).
  bool unwraps() const { return needOutputs_ && unwrap_.active(); }

  /// Follows the angle outputs through one solver step (no row is written).
  void observe(double t, std::span<const double> y, std::span<const double> yp) {
    evaluate(model_.outputs, "outputs", t, y, yp, outputs_);
    unwrap_.apply(outputs_);
  }

  std::span<const double> build(double t, std::span<const double> y, std::span<const double> yp) {
    if (needOutputs_) {
      evaluate(model_.outputs, "outputs", t, y, yp, outputs_);
      unwrap_.apply(outputs_);
    }
    if (needInvariants_) evaluate(model_.invariants, "invariants", t, y, yp, invariants_);
    for (std::size_t i = 0; i < columns_.size(); ++i)
      values_[i] = value(columns_[i], y);
    return values_;
  }

 private:
  using Function = int (*)(const QdotModel*, double, const double*, const double*, const double*, double*);

  void evaluate(Function f, const char* what, double t, std::span<const double> y, std::span<const double> yp,
                std::vector<double>& out) {
    if (f(&model_, t, y.data(), yp.data(), p_.data(), out.data()) != 0)
      throw IdaError(
          fmt::format("the model's {} could not be evaluated at t = {:.10g}: {}", what, t, modelLastError(model_)), t);
  }

  double value(const Column& c, std::span<const double> y) const {
    switch (c.source) {
      case Column::Source::Variable:
        return y[c.index];
      case Column::Source::Output:
        return outputs_[c.index];
      case Column::Source::Invariant:
        return invariants_[c.index];
    }
    return 0;
  }

  const QdotModel& model_;
  const std::vector<Column>& columns_;
  std::span<const double> p_;
  std::vector<double> values_, outputs_, invariants_;
  AngleUnwrapper unwrap_;  ///< angle outputs continuous from row to row
  bool needOutputs_ = false, needInvariants_ = false;
};

/// "t = 3.2 of 10 (32 %)" on one terminal line, rewritten at most twice a second once the solve has
/// taken kProgressAfter seconds, and erased at the end so the terminal shows only the result.
class ProgressLine {
 public:
  ProgressLine(std::ostream* out, double start, double stop) : out_(out), start_(start), stop_(stop) {}
  ~ProgressLine() {
    if (shown_) *out_ << "\r\033[K" << std::flush;
  }
  void update(double t) {
    if (!out_) return;
    double elapsed = secondsSince(began_);
    if (elapsed < kProgressAfter || elapsed - lastShown_ < 0.5) return;
    lastShown_ = elapsed;
    shown_ = true;
    double percent = 100 * (t - start_) / (stop_ - start_);
    *out_ << fmt::format("\r\033[Kt = {:.6g} of {:.6g} ({:.0f} %), {:.0f} s", t, stop_, percent, elapsed) << std::flush;
  }

 private:
  std::ostream* out_;
  double start_, stop_;
  Clock::time_point began_ = Clock::now();
  double lastShown_ = 0;
  bool shown_ = false;
};

/// --max-steps: IDA counts steps per call (IDASetMaxNumSteps), so the limit over the run is
/// checked after every output time, and IDA's own limit per call is lowered to it.
template <class Session>
void checkStepLimit(const SimulationSettings& s, const Session& session) {
  if (!s.maxSteps) return;
  long steps = session.stats().steps;
  if (steps >= *s.maxSteps && session.time() < s.stop)
    throw IdaError(fmt::format("the run reached --max-steps {} ({} steps taken); allow more steps or loosen --rtol",
                               *s.maxSteps, steps),
                   session.time());
}

SessionOptions sessionOptions(const SimulationSettings& s) {
  SessionOptions o;
  o.t0 = s.start;
  o.rtol = s.rtol;
  o.atol = s.atol;
  o.linearSolver = s.linearSolver;
  o.maxStepsPerOutput = s.maxSteps ? std::min(s.maxStepsPerOutput, *s.maxSteps) : s.maxStepsPerOutput;
  o.preserveInvariants = s.preserveInvariants;
  o.eliminateTwoEntryRows = s.eliminateTwoEntryRows;
  return o;
}

/// advanceTo; a failure caused by the --max-steps limit (IDA_TOO_MUCH_WORK within one interval)
/// is reported as that limit, not as the solver's generic message.
template <class Session>
double advanceWithin(const SimulationSettings& s, Session& session, double tout) {
  try {
    return session.advanceTo(tout);
  } catch (const IdaError&) {
    checkStepLimit(s, session);
    throw;
  }
}

template <class Session>
void collect(SimulationResult& r, const Session& session) {
  r.tolerances = session.tolerances();
  r.linearSolver = session.linearSolver();
  r.computedInitialValues = session.computedInitialValues();
  r.initialValues = session.initialValueMethod();
  if constexpr (requires { session.blockTriangular(); }) r.blockTriangular = session.blockTriangular();
  if constexpr (requires { session.bandwidth(); }) r.bandwidth = session.bandwidth();
  if constexpr (requires { session.eliminatedRows(); }) r.eliminatedRows = session.eliminatedRows();
  if constexpr (requires { session.reducedAsBand(); }) r.reducedAsBand = session.reducedAsBand();
  r.warnings = session.warnings();
  try {
    r.stats = session.stats();
  } catch (const IdaError&) {
    // the counters are informative only
  }
}

}  // namespace

std::vector<Column> defaultColumns(const QdotModel& model, bool invariants) {
  std::vector<Column> columns;
  appendColumns(columns, Column::Source::Variable, model.variableNames, model.nVariables);
  appendColumns(columns, Column::Source::Output, model.outputNames, model.nOutputs);
  if (invariants) appendColumns(columns, Column::Source::Invariant, model.invariantNames, model.nInvariants);
  return columns;
}

// Looks the names up without copying every column (a model of 10^6 unknowns asked for x[1]);
// the list of every name is made only for the message when a name is unknown.
std::vector<Column> selectColumns(const QdotModel& model, const std::vector<std::string>& names, bool invariants) {
  struct Source {
    Column::Source source;
    const char* const* names;
    uint32_t count;
  };
  const Source sources[] = {{Column::Source::Variable, model.variableNames, model.nVariables},
                            {Column::Source::Output, model.outputNames, model.nOutputs},
                            {Column::Source::Invariant, model.invariantNames, model.nInvariants}};
  auto find = [&](std::string_view name) -> std::optional<Column> {
    for (const Source& s : sources)
      for (uint32_t i = 0; i < s.count; ++i)
        if (s.names && s.names[i] && name == s.names[i]) return Column{s.source, i, std::string(name)};
    return std::nullopt;
  };
  std::vector<Column> chosen;
  std::set<std::string> seen;
  for (const std::string& name : names) {
    std::optional<Column> column = find(name);
    if (!column) {
      std::vector<Column> all = defaultColumns(model, true);
      std::vector<std::string_view> candidates;
      for (const Column& c : all) candidates.push_back(c.name);
      throw UsageError(unknownNameMessage("output column", name, candidates));
    }
    if (!seen.insert(name).second) throw UsageError(fmt::format("output column '{}' is selected twice", name));
    chosen.push_back(*column);
  }
  if (invariants)
    for (const Column& c : defaultColumns(model, true))
      if (c.source == Column::Source::Invariant && seen.insert(c.name).second) chosen.push_back(c);
  return chosen;
}

OutputGrid::OutputGrid(double start, double stop, double interval)
    : start_(start), stop_(stop), interval_(interval), regular_(0) {
  double last = stop - 1e-9 * interval;  // a regular time must lie below this
  double estimate = std::ceil((last - start) / interval);
  regular_ = estimate > 0 ? static_cast<std::size_t>(estimate) : 0;
  while (regular_ > 0 && start + static_cast<double>(regular_ - 1) * interval >= last)
    --regular_;
  while (start + static_cast<double>(regular_) * interval < last)
    ++regular_;
}

// k·interval carries binary rounding (3 × 0.1 = 0.30000000000000004). The nearest 15-digit decimal
// is the time the user asked for; it differs by less than 1e-15 relative, and the CSV shows 0.3.
double OutputGrid::operator[](std::size_t k) const {
  if (k >= regular_) return stop_;
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", start_ + static_cast<double>(k) * interval_);
  return std::strtod(text, nullptr);
}

namespace {

// The loop over the output grid with either integrator (IdaSession or ArkodeSession: the same face).
template <class Session>
SimulationResult simulateWith(const QdotModel& model, const SimulationSettings& settings, ResultSink& sink,
                              SimulationResult result) {
  std::vector<Column> columns =
      settings.columns.empty() ? defaultColumns(model, settings.invariants) : settings.columns;
  std::vector<std::string> names;
  for (const Column& c : columns)
    names.push_back(c.name);
  std::unique_ptr<Session> session;
  Clock::time_point clock = Clock::now();
  bool solving = false;
  try {
    if (!(settings.stop > settings.start) || !(settings.interval > 0))
      throw IdaError(fmt::format("invalid time span [{}, {}] or interval {}", settings.start, settings.stop,
                                 settings.interval),
                     settings.start);
    OutputGrid grid(settings.start, settings.stop, settings.interval);
    sink.begin(names);  // the header is written even if the setup fails
    SessionOptions options = sessionOptions(settings);
    RowBuilder rows(model, columns, settings.parameters);
    // Angle outputs follow every internal step where the session can show them (IDA); ARKODE's
    // rows alone are unwrapped (an output interval must then resolve the rotation).
    constexpr bool observable = requires(Session& s) { s.setStepObserver({}); };
    options.observeSteps = observable && rows.unwraps();
    session = std::make_unique<Session>(model, settings.parameters, options);
    if constexpr (observable)
      if (rows.unwraps())
        session->setStepObserver([&rows](double t, std::span<const double> y, std::span<const double> yp) { rows.observe(t, y, yp); });
    session->initialize(grid[1]);
    session->setStopTime(settings.stop);
    result.setupSeconds = secondsSince(clock);
    clock = Clock::now();
    solving = true;
    ProgressLine progress(settings.progress, settings.start, settings.stop);
    for (std::size_t k = 0; k < grid.size(); ++k) {
      double t = k == 0 ? session->time() : advanceWithin(settings, *session, grid[k]);
      sink.row(t, rows.build(t, session->y(), session->yp()));
      // The setup and the first steps have allocated what the solver needs, reusing what the
      // process freed before (sim/MemoryReuse.h): the rest goes back to the system.
      if (k == 1) returnFreedMemory();
      ++result.rows;
      result.lastRowTime = t;
      checkStepLimit(settings, *session);
      progress.update(t);
    }
    result.success = true;
  } catch (const IdaError& e) {
    result.failureTime = e.time();
    result.message = e.what();
  } catch (const std::exception& e) {  // writing failed, or out of memory
    result.failureTime = session ? session->time() : settings.start;
    result.message = e.what();
  }
  (solving ? result.solveSeconds : result.setupSeconds) = secondsSince(clock);
  result.firstStepSeconds = result.solveSeconds;
  if constexpr (requires(Session& s) { s.firstStepDone(); })
    if (solving && session->firstStepDone()) {
      result.firstStepSeconds = std::chrono::duration<double>(*session->firstStepDone() - clock).count();
      result.firstStepDone = session->firstStepDone();
    }
  result.peakMemoryBytes = peakResidentBytes();
  result.prefaultedBytes = heapPrefaultedBytes();
  try {
    sink.finish();
  } catch (const std::exception& e) {
    if (result.success) result.message = e.what();
    result.success = false;
  }
  std::vector<std::string> notes = std::move(result.warnings);
  if (session) collect(result, *session);
  result.warnings.insert(result.warnings.begin(), notes.begin(), notes.end());
  return result;
}

}  // namespace

SimulationResult simulate(const QdotModel& model, const SimulationSettings& settings, ResultSink& sink) {
  SimulationResult result;
  result.failureTime = settings.start;
  result.linearSolverChosenAutomatically = settings.linearSolver == LinearSolverKind::Auto;
  result.solver = settings.solver;
  if (settings.solver == SolverKind::Auto) {
    SolverChoice choice = chooseSolver(model, settings.parameters, settings.start, settings.stop);
    result.solver = choice.kind;
    result.warnings.push_back("note: --solver auto " + choice.reason);
  }
  if (result.solver == SolverKind::Arkode) return simulateWith<ArkodeSession>(model, settings, sink, std::move(result));
  return simulateWith<IdaSession>(model, settings, sink, std::move(result));
}

}  // namespace qdot::rt
