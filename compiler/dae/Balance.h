// Balance: checks that the DAE's equations determine its unknowns, with a maximum matching on the
// equation–unknown graph (the unknown of a state is its derivative y', of an algebraic variable y
// itself). When they don't, the Dulmage–Mendelsohn decomposition names exactly the equations that
// are too many and the unknowns that nothing determines.
#pragma once

#include "dae/Dae.h"
#include "structural/BipartiteGraph.h"

namespace qdot::dae {

/// The equation–unknown graph: equation e — unknown v where e contains v's unknown symbol (a
/// state's y', an algebraic variable's y). What the structural passes work on.
structural::BipartiteGraph incidence(const Dae& dae, const sym::Context& ctx);

/// Reports E0501 (more unknowns than equations), E0502 (more equations than unknowns) or
/// E0503 (as many, but structurally singular) naming the culprits. Returns true if balanced.
bool checkBalance(const Dae& dae, sym::Context& ctx, DiagnosticEngine& diags);

}  // namespace qdot::dae
