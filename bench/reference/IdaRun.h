// The hand-written IDA driver of the reference programs: the same sequence of SUNDIALS calls as
// qdot's runtime (runtime/ida/IdaSession.cpp, runtime/sim/Simulation.cpp), so that a run of a
// ReferenceModel and `qdot run` of the same .qd model differ only in how F and J are evaluated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "ida/Tolerances.h"
#include "reference/ReferenceModel.h"

namespace qdot::bench {

/// What one run does (qdot's defaults where it has them).
struct RunSettings {
  double start = 0;
  double stop = 1;
  double interval = 0.002;
  double rtol = 1e-6;
  std::optional<double> atol;     ///< before scaling; none = rtol (qdot's rule)
  std::vector<uint32_t> columns;  ///< indices of y written after time; empty = all
  std::string outputPath;         ///< CSV file; empty = standard output
  long maxStepsPerOutput = 100000;
};

/// IDA's counters and the wall times of one run.
struct RunResult {
  long steps = 0;
  long residualEvaluations = 0;
  long jacobianEvaluations = 0;
  long nonlinearIterations = 0;
  long errorTestFailures = 0;
  long convergenceFailures = 0;
  double lastStep = 0;
  int lastOrder = 0;
  bool computedInitialValues = false;
  bool diagonalRates = false;  ///< y' made consistent by one division (else IDACalcIC), if computed
  bool sparse = false;
  std::optional<int64_t> bandwidth;  ///< KLU ordered as a band of this half width (qdot's rule), else COLAMD
  std::size_t rows = 0;
  rt::ToleranceSummary tolerances;
  double setupSeconds = 0;  ///< IDA set up, consistent start
  double solveSeconds = 0;  ///< IDASolve over the output grid, and writing the rows
  double firstStepSeconds = 0;  ///< from the start of the solve to IDA's first completed step
  std::optional<double> firstStepSinceProcessStart;  ///< the same instant, from the process's start
};

/// The output times: start + k·interval while below stop (closer than 1e-9 intervals counts as
/// reaching it), then stop itself — qdot's grid.
std::vector<double> outputTimes(double start, double stop, double interval);

/// Integrates model over the grid, writing CSV rows (time, then the columns). Throws
/// std::runtime_error naming the SUNDIALS call that failed.
RunResult simulateReference(const ReferenceModel& model, const RunSettings& settings);

/// The counters in the layout of `qdot run --stats`.
std::string formatStats(const RunResult& result);

}  // namespace qdot::bench
