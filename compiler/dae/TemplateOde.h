// `for` equations kept as templates (flat::EquationTemplate, issue 15, docs/loops.md) reach the
// DAE only in a model that is an ODE with one derivative per row, F_j(t, y, y'_j) = 0 (`der(x) = f`,
// `m*der(v) = f`): its rows matched to their derivatives are then a perfect matching with ∂F/∂y'
// diagonal (index 1 where that diagonal is non-zero, which the runtime checks at the start;
// balanced), so the structural passes that need a plain graph of scalars have nothing to do, and
// none runs.
#pragma once

#include "dae/Dae.h"

namespace qdot::dae {

/// Whether the DAE of the flat model can keep its equation templates: it has some, and it is an
/// ODE with one derivative per row — unknowns only (no coordinates, energies, forces, constraints,
/// components, aliases, initial equations); every unknown a state whose derivative is the only
/// derivative of exactly one row, a scalar equation (`der(x) = rhs`, `m*der(v) = f`) or one point of
/// a template (`der(x)[%1,…] = rhs`, `c*der(T)[%1] = f`); a template reads, besides that derivative,
/// parameters and time, only arrays of unknowns declared element by element (consecutive
/// unknowns), subscripted by its iterators in order (`x[%1+1,%2]`), of the shape of the array it
/// defines (any length in one dimension).
bool isTemplatedOde(const flat::FlatModel& model, const sym::Context& ctx);

/// Adds the unknowns and rows of such a model to `dae` (whose header and parameters are set):
/// every unknown a state, in declaration order, and row j the equation of the derivative of
/// unknown j. A template's rows are its elements' (TemplateBlock, firstRow the row of its array's
/// first element, origin Equation), with Equation::residual null in `equations`.
void addTemplatedOde(const flat::FlatModel& model, sym::Context& ctx, Dae& dae);

}  // namespace qdot::dae
