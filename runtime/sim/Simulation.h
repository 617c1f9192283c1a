// The simulation loop: an IdaSession integrated across the output grid, one row per output time
// written to a ResultSink (time, then the selected columns). Failures become a result with the
// time and the message; the rows written before a failure stay written.
#pragma once

#include <chrono>

#include <cstddef>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "arkode/SolverChoice.h"
#include "ida/IdaSession.h"
#include "output/ResultSink.h"
#include "qdot/model_abi.h"

namespace qdot::rt {

/// One result column after time: a variable (y), an output definition, or an invariant.
struct Column {
  enum class Source { Variable, Output, Invariant };
  Source source = Source::Variable;
  uint32_t index = 0;  ///< index within its source
  std::string name;
};

/// All variables in model order, then all outputs, then (if invariants) all invariants.
std::vector<Column> defaultColumns(const QdotModel& model, bool invariants);

/// The named columns (variables, outputs or invariants) in the order given, then, if invariants,
/// the invariants not named. Throws UsageError for an unknown or repeated name.
std::vector<Column> selectColumns(const QdotModel& model, const std::vector<std::string>& names, bool invariants);

/// The output times: start + k*interval while below stop (a point closer than 1e-9 intervals to
/// stop is dropped), then stop itself. Computed on demand, never accumulated.
class OutputGrid {
 public:
  /// Requires stop > start and interval > 0.
  OutputGrid(double start, double stop, double interval);
  std::size_t size() const { return regular_ + 1; }  ///< number of output times, stop included
  double operator[](std::size_t k) const;            ///< the k-th output time

 private:
  double start_, stop_, interval_;
  std::size_t regular_;  // number of times start + k*interval before stop
};

/// Everything one run needs (already validated, see RunOptions).
struct SimulationSettings {
  double start = 0;
  double stop = 1;
  double interval = 0.002;
  double rtol = 1e-6;
  std::optional<double> atol;  ///< user's atol before scaling; none = rtol
  LinearSolverKind linearSolver = LinearSolverKind::Auto;
  std::vector<double> parameters;  ///< values from QdotModel::parameters
  std::vector<Column> columns;     ///< empty = defaultColumns(model, invariants)
  bool invariants = false;         ///< with empty columns: add the invariant columns
  long maxStepsPerOutput = 100000;
  std::optional<long> maxSteps;        ///< steps allowed over the whole run (--max-steps); none = no limit
  std::ostream* progress = nullptr;    ///< a terminal: progress once the run is longer than kProgressAfter
  // --solver (issue 11, section 3): which integrator; Auto picks from the linearization at the start.
  SolverKind solver = SolverKind::Ida;
  bool preserveInvariants = false;  ///< --preserve invariants: project onto their start values (arkode)
  bool eliminateTwoEntryRows = true;  ///< false with --no-row-elimination (SessionOptions)
};

/// Seconds of solving after which progress is shown (when SimulationSettings::progress is set).
inline constexpr double kProgressAfter = 3.0;

/// How a run went.
struct SimulationResult {
  bool success = false;
  double failureTime = 0;  ///< when !success: simulation time of the failure
  std::string message;     ///< when !success: what failed and why
  std::size_t rows = 0;    ///< rows written (header not counted)
  double lastRowTime = 0;  ///< time of the last row written
  SolverStats stats;
  ToleranceSummary tolerances;
  LinearSolverKind linearSolver = LinearSolverKind::Auto;  ///< as resolved (Auto if setup failed)
  bool linearSolverChosenAutomatically = false;            ///< --linear-solver auto
  bool blockTriangular = true;  ///< KLU: permuted to block triangular form first (IdaSession::blockTriangular)
  std::optional<int64_t> bandwidth;  ///< KLU: ordered as a band of this half width (IdaSession::bandwidth), else COLAMD
  int64_t eliminatedRows = 0;        ///< KLU: two-entry rows eliminated before the LU (IdaSession::eliminatedRows)
  bool reducedAsBand = false;        ///< and the rest factored as a band (IdaSession::reducedAsBand)
  bool computedInitialValues = false;
  InitialValueMethod initialValues = InitialValueMethod::AsGiven;
  std::vector<std::string> warnings;
  SolverKind solver = SolverKind::Ida;  ///< the integrator that ran (never Auto)
  double setupSeconds = 0;  ///< wall time: session setup and consistent initial values
  double solveSeconds = 0;  ///< wall time: integration and writing
  /// Wall time from the start of the solve to IDA's first completed step (its first matrix
  /// factorization included); the whole solve if that was not seen (ARKODE, a run of one step).
  double firstStepSeconds = 0;
  /// When IDA's first step was seen done (steady clock), if it was: `--stats` says how long after
  /// the process started that was (sim/ProcessClock.h), the way from the file to the first step.
  std::optional<std::chrono::steady_clock::time_point> firstStepDone;
  /// The process's peak resident memory when the run ended (compiling included, for `qdot run`),
  /// in bytes; 0 where the system does not say.
  size_t peakMemoryBytes = 0;
  size_t prefaultedBytes = 0;  ///< heap populated ahead of use by the prefaulter (sim/MemoryReuse.h)
};

/// Runs the model over the grid, writing into sink (begin, rows, finish). Never throws for
/// solver or model failures; those are in the result.
SimulationResult simulate(const QdotModel& model, const SimulationSettings& settings, ResultSink& sink);

}  // namespace qdot::rt
