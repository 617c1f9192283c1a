// Balance: checks that the DAE's equations determine its unknowns, with a maximum matching on the
// equation–unknown graph (the unknown of a state is its derivative y', of an algebraic variable y
// itself). When they don't, the Dulmage–Mendelsohn decomposition names exactly the equations that
// are too many and the unknowns that nothing determines.
#pragma once

#include "dae/Dae.h"

namespace qdot::dae {

/// Reports E0501 (more unknowns than equations), E0502 (more equations than unknowns) or
/// E0503 (as many, but structurally singular) naming the culprits. Returns true if balanced.
bool checkBalance(const Dae& dae, sym::Context& ctx, DiagnosticEngine& diags);

}  // namespace qdot::dae
