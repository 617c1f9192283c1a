// runModel: everything `qdot run` and a standalone model executable do after parsing the command
// line — resolve the options against the model, write the CSV, report failure, warnings and
// statistics — returning the process exit code.
#pragma once

#include <ostream>

#include "qdot/exit_code.hpp"
#include "qdot/model_abi.h"
#include "sim/RunOptions.h"

namespace qdot::rt {

/// Runs model with the parsed options. CSV goes to options.outputPath, or to csvOut when it is
/// empty; errors ("error: ..."), warnings and --stats go to log. Returns Success, SimulationFailed
/// when the run failed (rows so far are written), Usage for a bad option. Progress is shown on log
/// when log is std::cerr, standard error is a terminal and the run is long (kProgressAfter).
ExitCode runModel(const QdotModel& model, const RunOptions& options, const ExperimentDefaults& experiment,
             std::ostream& csvOut, std::ostream& log);

}  // namespace qdot::rt
