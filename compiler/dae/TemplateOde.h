// `for` equations kept as templates (flat::EquationTemplate, issue 15, docs/loops.md) reach the
// DAE only in a model whose rows are each matched to an unknown of their own: a state's row names
// its derivative and no other (`der(x) = f`, `m*der(v) = f`), an algebraic unknown's row names no
// derivative and no other algebraic unknown (`f = k*(x - x0)`). That matching is perfect with the
// matched block of ∂F/∂(y', z) diagonal: balanced, and of index 1 where that diagonal is non-zero
// (the runtime checks it at the start), so the structural passes that need a plain graph of scalars
// have nothing to do, and none runs.
#pragma once

#include "dae/Dae.h"

namespace qdot::dae {

/// Whether the DAE of the flat model can keep its equation templates: it has some, and every row is
/// matched to an unknown of its own — unknowns only (no coordinates, energies, forces, constraints,
/// components, aliases, initial equations other than start values); every state's derivative the only derivative of exactly
/// one row, a scalar equation (`der(x) = rhs`, `m*der(v) = f`) or one point of a template
/// (`der(x)[%1,…] = rhs`, `c*der(T)[%1] = f`); every algebraic unknown the only algebraic unknown of
/// exactly one row without derivative (`f = …`, `f[%1] = k*(x[%1] - x[%1-1])`); a template reads,
/// besides its own unknown, parameters, time and arrays of parameters, only arrays of unknowns
/// declared element by element (consecutive unknowns), subscripted by its iterators in order
/// (`x[%1+1,%2]`), of the shape of its own array (any length in one dimension).
bool isTemplatedOde(const flat::FlatModel& model, const sym::Context& ctx);

/// Whether every initial equation of the model gives a state its start value: `s = value` or
/// `value = s`, s a state (a coordinate, its velocity, an unknown whose der() appears), value over
/// parameters and time — what the kernels take as start values, the only initial equations a
/// templated model may have (the others are rows of an initialization system the structural passes
/// solve on scalars).
bool initialEquationsAreStartValues(const flat::FlatModel& model, const sym::Context& ctx);

/// Adds the unknowns and rows of such a model to `dae` (whose header and parameters are set):
/// every unknown in declaration order (a state, or algebraic), and row j the equation matched to
/// unknown j. A template's rows are its elements' (TemplateBlock, firstRow the row of its array's
/// first element, origin Equation), with Equation::residual null in `equations`; the initial
/// equations (start values) as they are.
void addTemplatedOde(const flat::FlatModel& model, sym::Context& ctx, Dae& dae);

}  // namespace qdot::dae
