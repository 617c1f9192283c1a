// The run options shared by `qdot run` and standalone model executables: registered on a
// CLI::App, then resolved against the model (experiment defaults, parameter and column names)
// into SimulationSettings. Every mistake is a UsageError with a clear sentence (exit code 2).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "output/ColumnNames.h"
#include "qdot/model_abi.h"
#include "sim/Names.h"
#include "sim/Simulation.h"

namespace CLI {
class App;
}

namespace qdot::rt {

/// The options as the user gave them; unset optionals take defaults in resolveRunOptions.
struct RunOptions {
  std::optional<double> start, stop, interval, rtol, atol;
  std::vector<std::string> parameters;  ///< -p NAME=VALUE, in the order given
  std::vector<std::string> outputs;     ///< --outputs a,b,...: column names
  std::string outputPath;               ///< -o FILE; empty = standard output
  bool stats = false;                   ///< --stats
  bool invariants = false;              ///< --invariants
  std::string linearSolver = "auto";    ///< --linear-solver dense|klu|auto
  std::string csvNames = "modelica";    ///< --csv-names modelica|identifier
  // Guards against runs that cannot end well (issue 11 §5).
  std::optional<long> maxSteps;  ///< --max-steps N: solver steps allowed over the whole run
  bool force = false;            ///< --force: write more than kMaxRowsWithoutForce rows
  bool progress = true;          ///< false with --no-progress; shown only on a terminal, see Run.h
  // --solver (issue 11, section 3)
  std::string solver = "ida";  ///< --solver ida|arkode|auto
  std::string preserve;        ///< --preserve invariants (issue 11, section 4); "" = none
  bool rowElimination = true;  ///< false with --no-row-elimination
};

/// The model's experiment annotation, as far as it gives values.
struct ExperimentDefaults {
  std::optional<double> start, stop, interval, tolerance;
};

inline constexpr double kDefaultStop = 1.0;       ///< s, without an experiment annotation
inline constexpr double kDefaultIntervals = 500;  ///< output intervals over [start, stop]
inline constexpr double kDefaultRtol = 1e-6;
/// More output rows than this (a CSV of about a gigabyte) need --force: an --interval typed with a
/// wrong exponent is refused before it fills the disk.
inline constexpr double kMaxRowsWithoutForce = 1e7;
/// The smallest --rtol accepted: 10 × DBL_EPSILON (issue 11, section 5).
inline constexpr double kRoundOffFloor = 10 * 2.220446049250313e-16;

/// Adds --start --stop --interval --rtol --atol -p --outputs -o --stats --invariants
/// --linear-solver --no-row-elimination --csv-names --max-steps --force --no-progress to app, storing into options (which must outlive the parse).
void addRunOptions(CLI::App& app, RunOptions& options);

/// The whole of text as a finite number (std::from_chars, no trailing characters), or nullopt.
std::optional<double> parseNumber(std::string_view text);

/// Why parseNumber rejects text, as the end of a sentence about it: "is not a number: 'x'", or
/// "is out of range: …" for a number too large (1e400) or too close to zero (1e-400) for a double.
/// (An underflow is refused rather than taken as 0: a value the user wrote is never changed silently.)
std::string numberRejection(std::string_view text);

/// The given/overridden arrays of QdotModel::parameters.
struct ParameterOverrides {
  std::vector<double> given;        ///< [nParameters]; 0 where not overridden
  std::vector<uint8_t> overridden;  ///< [nParameters]; 1 where -p gave a value
};

/// Parses the -p NAME=VALUE list against the model's parameter names. Throws UsageError for a
/// missing '=', an unknown name (suggesting the closest), a value that is not a finite number (or
/// out of a double's range),
/// or a parameter given twice.
ParameterOverrides parameterOverrides(const QdotModel& model, const std::vector<std::string>& assignments);

/// Calls QdotModel::parameters. Throws std::runtime_error with the model's lastError if it fails
/// or yields a non-finite value.
std::vector<double> evaluateParameters(const QdotModel& model, const ParameterOverrides& overrides);

/// A validated run: what simulate() needs plus where the rows go.
struct ResolvedRun {
  SimulationSettings settings;
  std::string outputPath;  ///< empty = standard output
  ColumnNaming csvNames = ColumnNaming::Modelica;
  bool stats = false;
  bool progress = true;  ///< the user did not turn progress off
};

/// Applies defaults (user value, else experiment annotation, else stop 1 s, 500 intervals, rtol
/// 1e-6; the annotation's interval is used only when start and stop are not overridden), checks
/// everything (more than kMaxRowsWithoutForce rows without --force is a UsageError) and evaluates the parameters. Throws UsageError for a bad option,
/// std::runtime_error when the model's parameter function fails.
ResolvedRun resolveRunOptions(const RunOptions& options, const ExperimentDefaults& experiment, const QdotModel& model);

}  // namespace qdot::rt
