// The `--stats` report: solver counters, the linear solver, the tolerance vector summary and the
// wall time of setup and solve, as aligned text for standard error.
#pragma once

#include <string>

#include "sim/Simulation.h"

namespace qdot::rt {

/// Several lines, each "  label  value", ending in a newline.
std::string formatStats(const SimulationResult& result);

}  // namespace qdot::rt
