// The initialization system (issue 10 §2): at t0 the DAE's equations, the initial equations that
// are not plain start values, and the start values that are fixed together determine y and the
// derivatives of the states. Like the simulation system it is analysed on the plain
// equation–unknown graph (structural/): the initial equations take the place of start values
// that are fixed only by default (a state's start), which ones is decided by a matching that keeps
// every mandatory equation; what stays undetermined or over-determined is an error naming it.
#pragma once

#include <optional>
#include <vector>

#include "dae/Dae.h"

namespace qdot::dae {

/// Whose start value is an equation of the initialization system.
enum class StartUse : unsigned char {
  Guess,     ///< only the Newton iteration's first guess
  Default,   ///< an equation unless an initial equation takes its place (a state's start)
  Required,  ///< an equation (declared fixed = true, or set by an explicit initial equation)
};

/// Per variable: whether its start value is kept as an equation (true) or computed (false).
/// `initialRows` are the initial equations that are not start values (residuals over y, y', p,
/// time). Reports E0605 (under-determined: names the unknowns nothing determines) or E0606
/// (over-determined: names the equations) and returns nullopt.
std::optional<std::vector<char>> planInitialization(const Dae& dae, const std::vector<Equation>& initialRows,
                                                    const std::vector<StartUse>& starts, const sym::Context& ctx,
                                                    DiagnosticEngine& diags);

}  // namespace qdot::dae
