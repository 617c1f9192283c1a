// Index reduction by Pantelides' algorithm and the dummy derivative method (Mattsson–Söderlind).
// The DAE's variables form derivative chains through its link rows (x, der(x), der(der(x)));
// Pantelides' algorithm, on the plain chain structure, says which equations to differentiate and
// how often; this stage differentiates them symbolically along the chains and adds the
// derivatives they need as unknowns, each with its link row. Which links are dropped (which
// derivatives are dummies) is decided at run time from the values (runtime/ida/DummyDerivatives).
#pragma once

#include <vector>

#include "dae/Dae.h"
#include "structural/Pantelides.h"

namespace qdot::dae {

/// The DAE as Pantelides' algorithm sees it: chains of variables joined by link rows, and the rows
/// that are not links as its equations.
struct ChainStructure {
  std::vector<int> chainOf;               ///< per variable
  std::vector<int> orderOf;               ///< per variable: its place in its chain (0 = base)
  std::vector<std::vector<int>> chains;   ///< per chain: its variables, base first
  std::vector<int> equations;             ///< the DAE rows that are not links, ascending
  structural::DerivativeStructure structure;  ///< equation k of it is DAE row equations[k]
};

ChainStructure chainStructure(const Dae& dae, const sym::Context& ctx);

/// Leaves a DAE of index ≤ 1 unchanged (returns true). Otherwise differentiates the equations
/// Pantelides names, extends the chains they touch to the orders needed (a state's derivative
/// becomes an unknown "der(x)" of role Derivative, with a link row), records Dae::differentiatedRows
/// and adds the invariants constraint[k] and der(constraint[k]) for every constraint. Requires a
/// DAE that passed checkBalance. Returns false after reporting an error.
bool reduceIndex(Dae& dae, sym::Context& ctx, DiagnosticEngine& diags);

}  // namespace qdot::dae
