// Test-only helpers for the structural tests: a deliberately simple O(V*E) augmenting-path matcher
// (Kuhn's algorithm) used as an independent oracle, seeded random sparse graphs, and checks that a
// BLT order respects the dependencies. Small graphs only (the oracle recurses).
#pragma once

#include <algorithm>
#include <random>
#include <vector>

#include "structural/BipartiteGraph.h"
#include "structural/BlockTriangular.h"
#include "structural/Matching.h"

namespace qdot::structural::test {

/// Kuhn's algorithm over equations in the given order; returns matchOfEquation.
class ReferenceMatcher {
 public:
  explicit ReferenceMatcher(const BipartiteGraph& g) : g_(g), owner_(g.numVariables(), -1) {}

  /// Matches the equations in `order` (skipping `excludedEquation`); returns the matching size.
  int run(const std::vector<int>& order, int excludedEquation = -1) {
    int size = 0;
    for (int e : order) {
      if (e == excludedEquation) continue;
      seen_.assign(g_.numVariables(), false);
      size += tryAugment(e);
    }
    return size;
  }

  /// The matching found by run() as a Matching.
  Matching matching() const {
    Matching m = Matching::empty(g_.numEquations(), g_.numVariables());
    m.matchOfVariable = owner_;
    for (int v = 0; v < g_.numVariables(); ++v)
      if (owner_[v] != -1) m.matchOfEquation[owner_[v]] = v;
    return m;
  }

 private:
  bool tryAugment(int e) {
    for (int v : g_.variablesOf(e)) {
      if (seen_[v]) continue;
      seen_[v] = true;
      if (owner_[v] == -1 || tryAugment(owner_[v])) {
        owner_[v] = e;
        return true;
      }
    }
    return false;
  }

  const BipartiteGraph& g_;
  std::vector<int> owner_;
  std::vector<bool> seen_;
};

inline std::vector<int> identityOrder(int n) {
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  return order;
}

/// Size of a maximum matching computed by the oracle, optionally without one equation.
inline int referenceMatchingSize(const BipartiteGraph& g, int excludedEquation = -1) {
  return ReferenceMatcher(g).run(identityOrder(g.numEquations()), excludedEquation);
}

/// A graph in which each equation has each variable with probability `density`.
inline BipartiteGraph randomGraph(std::mt19937& rng, int numEquations, int numVariables, double density) {
  std::vector<Edge> edges;
  std::uniform_real_distribution<double> coin(0.0, 1.0);
  for (int e = 0; e < numEquations; ++e)
    for (int v = 0; v < numVariables; ++v)
      if (coin(rng) < density) edges.push_back({e, v});
  return BipartiteGraph(numEquations, numVariables, edges);
}

/// A square graph with a planted random perfect matching plus about `extraPerEquation` random
/// extra variables per equation (so it always has a perfect matching).
inline BipartiteGraph randomNonsingularGraph(std::mt19937& rng, int n, int extraPerEquation) {
  std::vector<int> perm = identityOrder(n);
  std::shuffle(perm.begin(), perm.end(), rng);
  std::vector<Edge> edges;
  for (int e = 0; e < n; ++e) {
    edges.push_back({e, perm[e]});
    for (int k = 0; k < extraPerEquation; ++k) edges.push_back({e, static_cast<int>(rng() % n)});
  }
  return BipartiteGraph(n, n, edges);
}

/// blockOf[e] = index of the block containing e, or -1 if e is in none; -2 if in several.
inline std::vector<int> blockIndexOfEquation(const BlockTriangularOrder& order, int numEquations) {
  std::vector<int> blockOf(numEquations, -1);
  for (std::size_t k = 0; k < order.blocks.size(); ++k)
    for (int e : order.blocks[k]) blockOf[e] = blockOf[e] == -1 ? static_cast<int>(k) : -2;
  return blockOf;
}

/// True iff every equation is in exactly one block and every dependency points to an earlier or
/// the same block.
inline bool respectsDependencies(const BipartiteGraph& g, const Matching& m, const BlockTriangularOrder& order) {
  std::vector<int> blockOf = blockIndexOfEquation(order, g.numEquations());
  for (int e = 0; e < g.numEquations(); ++e) {
    if (blockOf[e] < 0) return false;
    for (int v : g.variablesOf(e))
      if (blockOf[m.matchOfVariable[v]] > blockOf[e]) return false;
  }
  return true;
}

}  // namespace qdot::structural::test
