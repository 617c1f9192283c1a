// Maximum matching and Dulmage–Mendelsohn decomposition on small hand-made graphs with known
// answers: chains, a graph where the greedy start is not enough, and structurally singular systems
// with exactly known over- and under-determined parts.
#include "structural/Matching.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace qdot::structural {
namespace {

using Ids = std::vector<int>;

Matching matchOf(const BipartiteGraph& g) {
  Matching m = maximumMatching(g);
  EXPECT_TRUE(isValidMatching(g, m));
  return m;
}

TEST(Matching, EmptyGraphHasEmptyPerfectMatching) {
  BipartiteGraph g;
  Matching m = matchOf(g);
  EXPECT_EQ(m.size(), 0);
  EXPECT_TRUE(m.isPerfect());
  EXPECT_TRUE(dulmageMendelsohn(g, m).isWellDetermined());
}

TEST(Matching, KnownSizesOnSmallGraphs) {
  // Star: three equations all in the same single variable.
  EXPECT_EQ(matchOf(BipartiteGraph::fromAdjacency(1, {{0}, {0}, {0}})).size(), 1);
  // Complete 3x3.
  EXPECT_EQ(matchOf(BipartiteGraph::fromAdjacency(3, {{0, 1, 2}, {0, 1, 2}, {0, 1, 2}})).size(), 3);
  // Two equations share two variables, a third variable is free: 2 of 3.
  EXPECT_EQ(matchOf(BipartiteGraph::fromAdjacency(3, {{0, 1}, {0, 1}})).size(), 2);
  // Variables 0 and 1 only occur in equation 0: at most one of them can be matched.
  EXPECT_EQ(matchOf(BipartiteGraph::fromAdjacency(4, {{0, 1, 2}, {2, 3}, {2, 3}})).size(), 3);
  // An equation with no variables.
  EXPECT_EQ(matchOf(BipartiteGraph::fromAdjacency(2, {{}, {0, 1}})).size(), 1);
}

TEST(Matching, PerfectOnChain) {
  // e_i mentions v_i and v_{i+1}; the last equation only v_{n-1}.
  const int n = 50;
  std::vector<Ids> rows(n);
  for (int i = 0; i < n; ++i) rows[i] = i + 1 < n ? Ids{i, i + 1} : Ids{i};
  BipartiteGraph g = BipartiteGraph::fromAdjacency(n, rows);
  Matching m = matchOf(g);
  EXPECT_TRUE(m.isPerfect());
  for (int i = 0; i < n; ++i) EXPECT_EQ(m.matchOfEquation[i], i);
}

TEST(Matching, AugmentingPathNeededWhenGreedyFails) {
  // First-free greedy pairs e0-v0 and strands e1 (only v0); e1-v0-e0-v1 fixes it.
  BipartiteGraph g = BipartiteGraph::fromAdjacency(2, {{0, 1}, {0}});
  Matching m = matchOf(g);
  EXPECT_EQ(m.matchOfEquation, (Ids{1, 0}));
  EXPECT_EQ(m.matchOfVariable, (Ids{1, 0}));
}

TEST(Matching, AugmentingPathNeededWhenHeuristicGuessesWrong) {
  // No vertex has degree one, so the Karp–Sipser start must guess; pairing e0 with v1 (its first
  // variable) starves e1 or e2, and Hopcroft–Karp has to repair it through e0.
  BipartiteGraph g = BipartiteGraph::fromAdjacency(4, {{1, 2, 3}, {0, 1}, {0, 1}, {2, 3}});
  Matching m = matchOf(g);
  EXPECT_TRUE(m.isPerfect());
  EXPECT_NE(m.matchOfEquation[0], 1);
}

// e_i = {v_i, v_{i+1}} for i < n-1 and e_{n-1} = {v_0}; the perfect matching is e_i-v_{i+1},
// e_{n-1}-v_0. Starting from the maximal (but not maximum) e_i-v_i, the only augmenting path
// runs through every vertex.
BipartiteGraph shiftedChain(int n) {
  std::vector<Ids> rows(n);
  for (int i = 0; i + 1 < n; ++i) rows[i] = {i, i + 1};
  rows[n - 1] = {0};
  return BipartiteGraph::fromAdjacency(n, rows);
}

void expectShiftedChainMatching(const Matching& m, int n) {
  ASSERT_TRUE(m.isPerfect());
  EXPECT_EQ(m.matchOfEquation[n - 1], 0);
  for (int i = 0; i + 1 < n; ++i) EXPECT_EQ(m.matchOfEquation[i], i + 1);
}

TEST(Matching, ShiftedChain) {
  const int n = 40;
  expectShiftedChainMatching(matchOf(shiftedChain(n)), n);
}

TEST(Matching, LongAugmentingPathFromMaximalStart) {
  const int n = 40;
  BipartiteGraph g = shiftedChain(n);
  Matching start = Matching::empty(n, n);
  for (int i = 0; i + 1 < n; ++i) start.matchOfEquation[i] = i, start.matchOfVariable[i] = i;
  Matching m = maximumMatching(g, start);
  EXPECT_TRUE(isValidMatching(g, m));
  expectShiftedChainMatching(m, n);
}

TEST(Matching, WarmStartKeepsMatchedVerticesMatched) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(3, {{0, 1}, {0}, {1, 2}});
  Matching initial = Matching::empty(3, 3);
  initial.matchOfEquation[0] = 0;
  initial.matchOfVariable[0] = 0;
  Matching m = maximumMatching(g, initial);
  EXPECT_TRUE(isValidMatching(g, m));
  EXPECT_TRUE(m.isPerfect());
  EXPECT_NE(m.matchOfEquation[0], kUnmatched);
  EXPECT_NE(m.matchOfVariable[0], kUnmatched);
}

TEST(Matching, RejectsInvalidInitialMatching) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(2, {{0}, {1}});
  Matching notAnEdge = Matching::empty(2, 2);
  notAnEdge.matchOfEquation[0] = 1;
  notAnEdge.matchOfVariable[1] = 0;
  EXPECT_FALSE(isValidMatching(g, notAnEdge));
  EXPECT_THROW(maximumMatching(g, notAnEdge), std::invalid_argument);
  Matching inconsistent = Matching::empty(2, 2);
  inconsistent.matchOfEquation[0] = 0;  // variable side not updated
  EXPECT_FALSE(isValidMatching(g, inconsistent));
  EXPECT_FALSE(isValidMatching(g, Matching::empty(2, 3)));
}

TEST(DulmageMendelsohn, WellDeterminedSystemHasOnlyWellPart) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(3, {{0, 1}, {1, 2}, {2}});
  DulmageMendelsohn dm = dulmageMendelsohn(g, matchOf(g));
  EXPECT_TRUE(dm.isWellDetermined());
  EXPECT_EQ(dm.wellEquations, (Ids{0, 1, 2}));
  EXPECT_EQ(dm.wellVariables, (Ids{0, 1, 2}));
}

TEST(DulmageMendelsohn, OverDeterminedPart) {
  // e0: x, e1: x, y, e2: y   (x = 0, y = 1)   -- three equations for two unknowns
  // e3: z, w, e4: w          (z = 2, w = 3)   -- fine on their own
  BipartiteGraph g = BipartiteGraph::fromAdjacency(4, {{0}, {0, 1}, {1}, {2, 3}, {3}});
  DulmageMendelsohn dm = dulmageMendelsohn(g, matchOf(g));
  EXPECT_EQ(dm.overEquations, (Ids{0, 1, 2}));
  EXPECT_EQ(dm.overVariables, (Ids{0, 1}));
  EXPECT_TRUE(dm.underEquations.empty());
  EXPECT_TRUE(dm.underVariables.empty());
  EXPECT_EQ(dm.wellEquations, (Ids{3, 4}));
  EXPECT_EQ(dm.wellVariables, (Ids{2, 3}));
}

TEST(DulmageMendelsohn, UnderDeterminedPart) {
  // 3 equations for 4 unknowns x, y, z, w: e0: x + y, e1: y + z, e2: z + w; plus a separate
  // well-determined pair e3: p (= 4), e4: p, q (= 5).
  BipartiteGraph g = BipartiteGraph::fromAdjacency(6, {{0, 1}, {1, 2}, {2, 3}, {4}, {4, 5}});
  DulmageMendelsohn dm = dulmageMendelsohn(g, matchOf(g));
  EXPECT_TRUE(dm.overEquations.empty());
  EXPECT_TRUE(dm.overVariables.empty());
  EXPECT_EQ(dm.underEquations, (Ids{0, 1, 2}));
  EXPECT_EQ(dm.underVariables, (Ids{0, 1, 2, 3}));
  EXPECT_EQ(dm.wellEquations, (Ids{3, 4}));
  EXPECT_EQ(dm.wellVariables, (Ids{4, 5}));
}

TEST(DulmageMendelsohn, VariableInNoEquation) {
  // x occurs in e0, y in e1; w occurs nowhere.
  BipartiteGraph g = BipartiteGraph::fromAdjacency(3, {{0}, {0, 1}});
  DulmageMendelsohn dm = dulmageMendelsohn(g, matchOf(g));
  EXPECT_EQ(dm.underVariables, (Ids{2}));
  EXPECT_TRUE(dm.underEquations.empty());
  EXPECT_EQ(dm.wellEquations, (Ids{0, 1}));
  EXPECT_EQ(dm.wellVariables, (Ids{0, 1}));
}

TEST(DulmageMendelsohn, OverAndUnderTogether) {
  // Over: e0: a, e1: a (a = 0). Well: e2: a, b (b = 1) -- uses the over-determined a.
  // Under: e3: b, c, d (c = 2, d = 3) -- one equation for c, d.
  // An equation with no variables (e4) is over-determined on its own.
  BipartiteGraph g = BipartiteGraph::fromAdjacency(4, {{0}, {0}, {0, 1}, {1, 2, 3}, {}});
  DulmageMendelsohn dm = dulmageMendelsohn(g, matchOf(g));
  EXPECT_EQ(dm.overEquations, (Ids{0, 1, 4}));
  EXPECT_EQ(dm.overVariables, (Ids{0}));
  EXPECT_EQ(dm.wellEquations, (Ids{2}));
  EXPECT_EQ(dm.wellVariables, (Ids{1}));
  EXPECT_EQ(dm.underEquations, (Ids{3}));
  EXPECT_EQ(dm.underVariables, (Ids{2, 3}));
}

TEST(DulmageMendelsohn, SameResultForDifferentMaximumMatchings) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(3, {{0, 1}, {0, 1}, {0, 1}, {1, 2}});
  Matching a = matchOf(g);
  Matching start = Matching::empty(4, 3);
  start.matchOfEquation[2] = 1, start.matchOfVariable[1] = 2;
  start.matchOfEquation[3] = 2, start.matchOfVariable[2] = 3;
  Matching b = maximumMatching(g, start);
  ASSERT_NE(a.matchOfEquation, b.matchOfEquation);
  DulmageMendelsohn da = dulmageMendelsohn(g, a), db = dulmageMendelsohn(g, b);
  EXPECT_EQ(da.overEquations, (Ids{0, 1, 2}));
  EXPECT_EQ(da.overVariables, (Ids{0, 1}));
  EXPECT_EQ(da.wellEquations, (Ids{3}));
  EXPECT_EQ(da.overEquations, db.overEquations);
  EXPECT_EQ(da.overVariables, db.overVariables);
  EXPECT_EQ(da.wellEquations, db.wellEquations);
}

TEST(DulmageMendelsohn, RejectsNonMaximumMatching) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(2, {{0, 1}, {0}});
  Matching m = Matching::empty(2, 2);
  m.matchOfEquation[0] = 0, m.matchOfVariable[0] = 0;  // valid but e1-v0-e0-v1 augments it
  EXPECT_THROW(dulmageMendelsohn(g, m), std::invalid_argument);
}

}  // namespace
}  // namespace qdot::structural
