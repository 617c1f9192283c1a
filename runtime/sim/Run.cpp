// runModel: resolve options (UsageError -> exit 2), open the sink, simulate, then print the
// failure, the warnings and the statistics.
#include "sim/Run.h"

#include <fmt/format.h>

#include <unistd.h>

#include <iostream>
#include <memory>

#include "output/CsvWriter.h"
#include "sim/StatsReport.h"
#include "sim/TieredModel.h"

namespace qdot::rt {
namespace {

void report(const SimulationResult& result, bool stats, std::ostream& log) {
  for (const std::string& warning : result.warnings)  // a line that is a note says so itself
    log << (warning.rfind("note: ", 0) == 0 ? "" : "warning: ") << warning << '\n';
  if (!result.success)
    log << fmt::format("error: the simulation failed at t = {:.10g}: {}\n", result.failureTime, result.message);
  if (!result.success && result.rows > 0)
    log << fmt::format("note: the {} rows up to t = {:.10g} were written\n", result.rows, result.lastRowTime);
  if (stats) log << formatStats(result);
}

}  // namespace

ExitCode runModel(const QdotModel& model, const RunOptions& options, const ExperimentDefaults& experiment,
             std::ostream& csvOut, std::ostream& log) {
  ResolvedRun run;
  try {
    run = resolveRunOptions(options, experiment, model);
  } catch (const UsageError& e) {
    log << "error: " << e.what() << '\n';
    return ExitCode::Usage;
  } catch (const std::exception& e) {
    log << "error: " << e.what() << '\n';
    return ExitCode::SimulationFailed;
  }
  std::unique_ptr<CsvWriter> writer;
  try {
    writer = run.outputPath.empty() ? std::make_unique<CsvWriter>(csvOut, run.csvNames)
                                    : CsvWriter::openFile(run.outputPath, run.csvNames);
  } catch (const std::exception& e) {  // nothing was simulated: the output the user named is wrong
    log << "error: " << e.what() << '\n';
    return ExitCode::Usage;
  }
  // Progress only where a person watches: standard error is a terminal (never into a log file).
  if (run.progress && &log == &std::cerr && isatty(STDERR_FILENO)) run.settings.progress = &log;
  setTierHorizon(&model, run.settings.start, run.settings.stop);  // the tiering policy's progress
  SimulationResult result = simulate(model, run.settings, *writer);
  report(result, run.stats, log);
  return result.success ? ExitCode::Success : ExitCode::SimulationFailed;
}

}  // namespace qdot::rt
