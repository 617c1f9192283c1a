// Modes: `qdot modes` and `qdot linearize` — the model linearized about its static equilibrium or
// its start state (compiler/linear): its state-space matrices, or its natural frequencies,
// damping ratios and mode shapes.
#pragma once

#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "linear/Linearize.h"
#include "qdot/exit_code.hpp"

namespace qdot::driver {

struct LinearizeResult {
  ExitCode code = ExitCode::Success;  ///< Usage: a bad -p; ModelError: cannot be linearized there
  std::string error;                  ///< why not (a sentence)
  linear::LinearModel model;
};

struct ModesResult {
  ExitCode code = ExitCode::Success;  ///< as LinearizeResult::code
  std::string error;
  linear::LinearModel system;
  std::vector<linear::Mode> modes;
};

/// For a compilation that reached Stage::Kernel: evaluates the parameters (with the run-time
/// `NAME=VALUE` assignments, as qdot run -p; inputs are parameters) and the start values on the
/// VM, and linearizes about `at`.
LinearizeResult linearizeModel(Compilation& c, const std::vector<std::string>& parameters, linear::OperatingPoint at);

/// linearizeModel, then the modes.
ModesResult computeModes(Compilation& c, const std::vector<std::string>& parameters, linear::OperatingPoint at);

}  // namespace qdot::driver
