// Explicit algebraic unknowns solved out of the DAE (what Modelica tools call trivial tearing).
// A component model's connector flows are algebraic unknowns each defined by one row in which it
// appears alone with a constant coefficient (`-links[1].b.f + k*(s1 - s0) + c*(v1 - v0) = 0`): such
// an unknown z, row r = c·z + g with c a non-zero number, is z = −g/c. It leaves the system (with
// its row) and becomes an output of that value, still a result column; every other row, initial
// equation, output and invariant that contains it gets the value instead. The system is the same
// (its Jacobian is the Schur complement about the pivot c), with fewer unknowns for IDA to
// factor and fewer algebraic variables in its error test: a chain of n components becomes the 2n
// states of the Lagrangian chain instead of 4n unknowns.
#pragma once

#include <cstddef>

#include "dae/Dae.h"

namespace qdot::dae {

struct EliminationReport {
  size_t eliminated = 0;  ///< unknowns (and rows) that left the system
};

/// Solves out the algebraic unknowns (UnknownRole::Algebraic, start not fixed) that some row
/// defines explicitly, as above. The row of each is chosen among those where it has a constant
/// coefficient: first a row without any derivative y', then the smallest. An unknown whose value
/// would exceed a bounded size (a long chain of definitions) stays. Leaves a templated DAE, or one
/// index reduction changed, as it is. The unknowns keep their order, and so do the rows.
EliminationReport eliminateExplicitAlgebraics(Dae& dae, sym::Context& ctx);

}  // namespace qdot::dae
