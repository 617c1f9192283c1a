// Text form of the equations of motion (`--emit=eom`, golden tests): the energy totals, one
// Euler–Lagrange row per coordinate with its generalized momentum, the multipliers of the
// constraints and the first integrals, each with the line it came from.
#pragma once

#include <iosfwd>

#include "mechanics/EulerLagrange.h"
#include "support/SourceManager.h"

namespace qdot::mech {

/// Writes `eom`, derived from `model` (whose variables and constraints it names).
void printEquationsOfMotion(std::ostream& os, const EquationsOfMotion& eom, const flat::FlatModel& model,
                            const sym::Context& ctx, const SourceManager& sm);

}  // namespace qdot::mech
