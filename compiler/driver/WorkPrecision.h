// `qdot wp FILE.qd`: the work–precision study of one model — the model solved at a ladder of
// tolerances in every configuration asked for (backend × solver), each run's error against a
// reference and its cost (time, steps, evaluations), as a table, a CSV file and an SVG diagram,
// with the fitted tolerance proportionality and the round-off floor (WorkPrecisionReport.h).
//
// The runs are in-process: the model is compiled once per backend (the front end once), the
// compile time is measured and added to each run's setup and solve time for the "whole process"
// column, so a ladder of 9 tolerances does not compile 9 times; docs/accuracy.md says why.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "qdot/exit_code.hpp"
#include "sim/RunOptions.h"

namespace CLI {
class App;
}

namespace qdot::driver {

/// The options of `qdot wp` as given.
struct WorkPrecisionOptions {
  std::vector<double> rtols;          ///< --rtols; empty: 1e-2 … 1e-10, one per decade
  std::vector<std::string> exact;     ///< --exact 'NAME = EXPR' (repeatable)
  std::string reference;              ///< --reference FILE.csv
  std::string error = "maxabs";       ///< --error maxabs|final|scd
  std::vector<std::string> backends;  ///< --backend llvm,bytecode; empty: llvm
  std::vector<std::string> solvers;   ///< --solver ida,arkode,auto; empty: ida
  std::string outputPrefix;           ///< -o PREFIX: PREFIX.csv and PREFIX.svg
  std::string csvPath, svgPath;       ///< --csv, --svg: override the prefix's files
  rt::RunOptions run;                 ///< --start --stop --interval --atol -p --linear-solver --max-steps
};

/// Registers the options of `qdot wp` (all but the file) on cmd.
void addWorkPrecisionOptions(CLI::App& cmd, WorkPrecisionOptions& options);

/// Runs the study on a compilation that reached Stage::Kernel (modelPath names the model file, for
/// the default output names and the report). Table on out; errors and notes on log. Returns
/// Usage for a bad option, reference or --exact expression (a located diagnostic),
/// SimulationFailed when the tight reference run fails, Success otherwise (a run of the ladder that
/// fails is a row of the table, not a failure of the study).
ExitCode workPrecision(Compilation& c, const std::string& modelPath, const WorkPrecisionOptions& options,
                       std::ostream& out, std::ostream& log);

}  // namespace qdot::driver
