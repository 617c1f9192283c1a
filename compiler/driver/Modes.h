// Modes: `qdot modes` — the natural frequencies, damping ratios and mode shapes of a model,
// linearized about its static equilibrium or its start state (compiler/linear).
#pragma once

#include <string>
#include <vector>

#include "driver/Pipeline.h"
#include "linear/Linearize.h"
#include "qdot/exit_code.hpp"

namespace qdot::driver {

struct ModesResult {
  ExitCode code = ExitCode::Success;  ///< Usage: a bad -p; ModelError: cannot be linearized there
  std::string error;                  ///< why not (a sentence)
  linear::SecondOrderSystem system;
  std::vector<linear::Mode> modes;
};

/// For a compilation that reached Stage::Kernel: evaluates the parameters (with the run-time
/// `NAME=VALUE` assignments, as qdot run -p) and the start values on the VM, linearizes about
/// `at` and computes the modes.
ModesResult computeModes(Compilation& c, const std::vector<std::string>& parameters, linear::OperatingPoint at);

}  // namespace qdot::driver
