// Text form of the DAE alone (`--emit=dae`, golden tests): its unknowns with their kind, every
// equation F = 0 with where it came from, parameters, invariants and the experiment; one item per
// line, in the DAE's own order (the order of the result columns and of the residual vector).
#pragma once

#include <iosfwd>

#include "dae/Dae.h"

namespace qdot::dae {

/// Writes `dae` (`qdot equations` prints the same system for reading; this shows its structure).
void printDae(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm);

}  // namespace qdot::dae
