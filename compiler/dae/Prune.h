// Prune: keeps only what the requested results need (issue 10 §4, `qdot run --outputs a,b`).
// On the equation–unknown graph with a perfect matching (each equation computes its matched
// unknown: a state's derivative or an algebraic unknown), a requested variable needs its matched
// equation, and that equation needs every variable it contains (their values, states included),
// transitively. Everything else is dropped before the kernels are built: a model with two
// uncoupled subsystems asked for one computes that one only.
#pragma once

#include <string>
#include <vector>

#include "dae/Dae.h"

namespace qdot::dae {

/// What pruning kept, for `qdot equations --outputs` and the notes of a run.
struct PruneReport {
  size_t variablesBefore = 0, variablesKept = 0;
  size_t equationsBefore = 0, equationsKept = 0;
  std::vector<std::string> unknownNames;  ///< requested names that are no variable, output or invariant
};

/// Removes from `dae` the unknowns and equations that the named results (variables, `der(x)` of a
/// state, outputs, invariants) do not depend on, and the outputs and invariants not named.
/// Names that match nothing are reported and the model is left whole (the run then reports them as
/// unknown columns). Needs a balanced DAE (buildDae has checked it).
PruneReport pruneToResults(Dae& dae, const std::vector<std::string>& names, sym::Context& ctx);

}  // namespace qdot::dae
