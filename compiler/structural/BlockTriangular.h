// Block lower triangular (BLT) ordering: given a perfect matching, the strongly connected
// components of the equation dependency graph in the order they can be solved (iterative Tarjan,
// O(E + |edges|)).
#pragma once

#include <vector>

#include "structural/BipartiteGraph.h"
#include "structural/Matching.h"

namespace qdot::structural {

/// The equations of a square, structurally nonsingular system grouped into blocks, in solve order.
///
/// Orientation. With a perfect matching, equation e "computes" its matched variable
/// matchOfEquation[e]. Equation e depends on equation f (f != e) iff e mentions the variable
/// matched to f. The blocks are the strongly connected components of that dependency graph, and
///
///   * blocks come in solve order: every variable mentioned by an equation of blocks[k] is matched
///     to an equation of blocks[j] with j <= k. Solve blocks[0] first, then blocks[1], ...;
///   * the variables of a block are the matched variables of its equations; a block of one
///     equation is solved for one variable, a larger block is an algebraic loop solved jointly;
///   * permuting rows by block order and columns by the matched variables in the same order gives
///     a block LOWER triangular incidence matrix with square diagonal blocks.
///
/// Equations inside a block are listed ascending. Blocks are emitted deterministically: the order
/// depends only on the graph and the matching. The partition into blocks (not the order) is the
/// same for every perfect matching.
struct BlockTriangularOrder {
  std::vector<std::vector<int>> blocks;  ///< equation ids; every equation in exactly one block
};

/// Computes the BLT order of `g` under the perfect matching `m`. Iterative Tarjan, O(E + |edges|)
/// time and O(E) extra memory. Throws std::invalid_argument if `m` is not a valid perfect
/// matching of `g`.
BlockTriangularOrder blockTriangularOrder(const BipartiteGraph& g, const Matching& m);

/// The variables solved for in `block`: the matched variable of each equation, in the same order.
std::vector<int> variablesOfBlock(const std::vector<int>& block, const Matching& m);

}  // namespace qdot::structural
