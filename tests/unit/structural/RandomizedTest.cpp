// Randomized cross-checks against independent oracles: matching size against Kuhn's O(V*E)
// algorithm, Dulmage–Mendelsohn parts against "some maximum matching misses this vertex", and BLT
// blocks against mutual reachability in the dependency graph. Seeds are fixed.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <vector>

#include "Reference.h"
#include "structural/BlockTriangular.h"
#include "structural/Matching.h"

namespace qdot::structural {
namespace {

using test::randomGraph;
using test::randomNonsingularGraph;
using test::referenceMatchingSize;

BipartiteGraph transposed(const BipartiteGraph& g) {
  std::vector<Edge> edges;
  for (int e = 0; e < g.numEquations(); ++e)
    for (int v : g.variablesOf(e)) edges.push_back({v, e});
  return BipartiteGraph(g.numVariables(), g.numEquations(), edges);
}

// Equations of `g` left unmatched by at least one maximum matching (the oracle for the
// over-determined equations), computed by removing each equation in turn.
std::vector<int> missableEquations(const BipartiteGraph& g) {
  int full = referenceMatchingSize(g);
  std::vector<int> result;
  for (int e = 0; e < g.numEquations(); ++e)
    if (referenceMatchingSize(g, e) == full) result.push_back(e);
  return result;
}

std::vector<int> neighboursOfEquations(const BipartiteGraph& g, const std::vector<int>& equations) {
  std::set<int> vars;
  for (int e : equations) vars.insert(g.variablesOf(e).begin(), g.variablesOf(e).end());
  return {vars.begin(), vars.end()};
}

Matching shuffledReferenceMatching(const BipartiteGraph& g, std::mt19937& rng) {
  std::vector<int> order = test::identityOrder(g.numEquations());
  std::shuffle(order.begin(), order.end(), rng);
  test::ReferenceMatcher matcher(g);
  matcher.run(order);
  return matcher.matching();
}

// A maximal (not necessarily maximum) matching: first-free greedy in a random equation order.
// Starting Hopcroft–Karp from it leaves real augmenting work to do.
Matching randomMaximalMatching(const BipartiteGraph& g, std::mt19937& rng) {
  Matching m = Matching::empty(g.numEquations(), g.numVariables());
  std::vector<int> order = test::identityOrder(g.numEquations());
  std::shuffle(order.begin(), order.end(), rng);
  for (int e : order)
    for (int v : g.variablesOf(e))
      if (m.matchOfVariable[v] == kUnmatched) {
        m.matchOfEquation[e] = v, m.matchOfVariable[v] = e;
        break;
      }
  return m;
}

void expectMaximumExtension(const BipartiteGraph& g, const Matching& start, int expectedSize) {
  Matching m = maximumMatching(g, start);
  ASSERT_TRUE(isValidMatching(g, m));
  ASSERT_EQ(m.size(), expectedSize);
  for (int e = 0; e < g.numEquations(); ++e)
    ASSERT_TRUE(start.matchOfEquation[e] == kUnmatched || m.matchOfEquation[e] != kUnmatched);
  for (int v = 0; v < g.numVariables(); ++v)
    ASSERT_TRUE(start.matchOfVariable[v] == kUnmatched || m.matchOfVariable[v] != kUnmatched);
}

TEST(Randomized, MatchingIsMaximum) {
  std::mt19937 rng(12345);
  int augmentedRounds = 0;
  for (int round = 0; round < 400; ++round) {
    int numEquations = static_cast<int>(rng() % 40), numVariables = static_cast<int>(rng() % 40);
    double density = 0.01 + 0.2 * (rng() % 100) / 100.0;
    BipartiteGraph g = randomGraph(rng, numEquations, numVariables, density);
    int expected = referenceMatchingSize(g);
    Matching m = maximumMatching(g);
    ASSERT_TRUE(isValidMatching(g, m));
    ASSERT_EQ(m.size(), expected) << "round " << round;
    Matching start = randomMaximalMatching(g, rng);
    augmentedRounds += start.size() < expected;
    expectMaximumExtension(g, start, expected);
  }
  EXPECT_GT(augmentedRounds, 50);  // the warm starts did exercise augmenting paths
}

TEST(Randomized, MatchingIsMaximumOnLargerSparseGraphs) {
  std::mt19937 rng(777);
  for (int round = 0; round < 20; ++round) {
    int n = 500 + static_cast<int>(rng() % 1500);
    int numVariables = n + static_cast<int>(rng() % 21) - 10;
    BipartiteGraph g = randomGraph(rng, n, numVariables, 1.5 / n);
    int expected = referenceMatchingSize(g);
    Matching m = maximumMatching(g);
    ASSERT_TRUE(isValidMatching(g, m));
    ASSERT_EQ(m.size(), expected) << "round " << round;
    expectMaximumExtension(g, randomMaximalMatching(g, rng), expected);
  }
}

TEST(Randomized, DulmageMendelsohnMatchesOracle) {
  std::mt19937 rng(2024);
  for (int round = 0; round < 150; ++round) {
    int numEquations = 1 + static_cast<int>(rng() % 18), numVariables = 1 + static_cast<int>(rng() % 18);
    BipartiteGraph g = randomGraph(rng, numEquations, numVariables, 0.05 + 0.15 * (rng() % 100) / 100.0);
    Matching m = maximumMatching(g);
    DulmageMendelsohn dm = dulmageMendelsohn(g, m);
    int size = m.size();
    // Sizes: each rectangular part carries exactly the deficiency on its side.
    ASSERT_EQ(dm.overEquations.size() - dm.overVariables.size(), std::size_t(numEquations - size));
    ASSERT_EQ(dm.underVariables.size() - dm.underEquations.size(), std::size_t(numVariables - size));
    ASSERT_EQ(dm.wellEquations.size(), dm.wellVariables.size());
    // Oracle: the over part is the missable equations and their neighbours; dually for under.
    std::vector<int> overEquations = missableEquations(g);
    ASSERT_EQ(dm.overEquations, overEquations) << "round " << round;
    ASSERT_EQ(dm.overVariables, neighboursOfEquations(g, overEquations));
    BipartiteGraph t = transposed(g);
    std::vector<int> underVariables = missableEquations(t);
    ASSERT_EQ(dm.underVariables, underVariables) << "round " << round;
    ASSERT_EQ(dm.underEquations, neighboursOfEquations(t, underVariables));
    // Independent of the maximum matching used.
    DulmageMendelsohn other = dulmageMendelsohn(g, shuffledReferenceMatching(g, rng));
    ASSERT_EQ(other.overEquations, dm.overEquations);
    ASSERT_EQ(other.underVariables, dm.underVariables);
    ASSERT_EQ(other.wellEquations, dm.wellEquations);
    ASSERT_EQ(other.wellVariables, dm.wellVariables);
  }
}

// reach[a][b]: equation a transitively depends on equation b (or a == b).
std::vector<std::vector<bool>> dependencyClosure(const BipartiteGraph& g, const Matching& m) {
  int n = g.numEquations();
  std::vector<std::vector<bool>> reach(n, std::vector<bool>(n, false));
  for (int a = 0; a < n; ++a) {
    std::vector<int> queue = {a};
    reach[a][a] = true;
    for (std::size_t head = 0; head < queue.size(); ++head)
      for (int v : g.variablesOf(queue[head])) {
        int b = m.matchOfVariable[v];
        if (!reach[a][b]) reach[a][b] = true, queue.push_back(b);
      }
  }
  return reach;
}

std::set<std::vector<int>> asSet(const BlockTriangularOrder& order) {
  return {order.blocks.begin(), order.blocks.end()};
}

TEST(Randomized, BlockTriangularOrderIsSccsInDependencyOrder) {
  std::mt19937 rng(99);
  for (int round = 0; round < 200; ++round) {
    int n = 1 + static_cast<int>(rng() % 40);
    BipartiteGraph g = randomNonsingularGraph(rng, n, static_cast<int>(rng() % 3));
    Matching m = maximumMatching(g);
    ASSERT_TRUE(m.isPerfect());
    BlockTriangularOrder order = blockTriangularOrder(g, m);
    ASSERT_TRUE(test::respectsDependencies(g, m, order)) << "round " << round;
    // Same block iff mutually dependent.
    std::vector<int> blockOf = test::blockIndexOfEquation(order, n);
    std::vector<std::vector<bool>> reach = dependencyClosure(g, m);
    for (int a = 0; a < n; ++a)
      for (int b = 0; b < n; ++b)
        ASSERT_EQ(blockOf[a] == blockOf[b], reach[a][b] && reach[b][a]) << "round " << round;
    // The partition does not depend on the perfect matching; the order respects the other one.
    Matching other = shuffledReferenceMatching(g, rng);
    ASSERT_TRUE(other.isPerfect());
    BlockTriangularOrder otherOrder = blockTriangularOrder(g, other);
    ASSERT_TRUE(test::respectsDependencies(g, other, otherOrder));
    ASSERT_EQ(asSet(otherOrder), asSet(order)) << "round " << round;
  }
}

}  // namespace
}  // namespace qdot::structural
