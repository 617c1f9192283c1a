// The exit codes of qdot and of the executables it builds: one list for every command.
#pragma once

namespace qdot {

enum class ExitCode : int {
  Success = 0,
  ModelError = 1,        ///< the model has errors (diagnostics on stderr)
  Usage = 2,             ///< a bad command line, or a file that cannot be read or written
  SimulationFailed = 3,  ///< the solver or the model failed during the run (rows so far are kept)
  Internal = 4,          ///< a bug in qdot
};

constexpr int toInt(ExitCode code) { return static_cast<int>(code); }

}  // namespace qdot
