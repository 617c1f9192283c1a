// BipartiteGraph: CSR construction in both directions, sorting, duplicate merging, empty rows and
// input validation.
#include "structural/BipartiteGraph.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace qdot::structural {
namespace {

std::vector<int> toVector(std::span<const int> s) { return {s.begin(), s.end()}; }

TEST(BipartiteGraph, EmptyGraph) {
  BipartiteGraph g;
  EXPECT_EQ(g.numEquations(), 0);
  EXPECT_EQ(g.numVariables(), 0);
  EXPECT_EQ(g.numEdges(), 0u);
  BipartiteGraph h(0, 0, {});
  EXPECT_EQ(h.numEdges(), 0u);
}

TEST(BipartiteGraph, BothDirectionsSortedFromUnsortedEdges) {
  std::vector<Edge> edges = {{1, 2}, {0, 1}, {2, 0}, {0, 0}, {1, 0}, {2, 2}};
  BipartiteGraph g(3, 3, edges);
  EXPECT_EQ(g.numEdges(), 6u);
  EXPECT_EQ(toVector(g.variablesOf(0)), (std::vector<int>{0, 1}));
  EXPECT_EQ(toVector(g.variablesOf(1)), (std::vector<int>{0, 2}));
  EXPECT_EQ(toVector(g.variablesOf(2)), (std::vector<int>{0, 2}));
  EXPECT_EQ(toVector(g.equationsOf(0)), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(toVector(g.equationsOf(1)), (std::vector<int>{0}));
  EXPECT_EQ(toVector(g.equationsOf(2)), (std::vector<int>{1, 2}));
}

TEST(BipartiteGraph, DuplicateEdgesAreMerged) {
  std::vector<Edge> edges = {{0, 1}, {0, 1}, {1, 0}, {0, 1}, {1, 0}};
  BipartiteGraph g(2, 2, edges);
  EXPECT_EQ(g.numEdges(), 2u);
  EXPECT_EQ(toVector(g.variablesOf(0)), (std::vector<int>{1}));
  EXPECT_EQ(toVector(g.equationsOf(1)), (std::vector<int>{0}));
  EXPECT_EQ(toVector(g.equationsOf(0)), (std::vector<int>{1}));
}

TEST(BipartiteGraph, IsolatedEquationsAndVariablesHaveEmptyRows) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(4, {{}, {3}, {}});
  EXPECT_EQ(g.numEquations(), 3);
  EXPECT_EQ(g.numVariables(), 4);
  EXPECT_TRUE(g.variablesOf(0).empty());
  EXPECT_TRUE(g.variablesOf(2).empty());
  EXPECT_TRUE(g.equationsOf(0).empty());
  EXPECT_EQ(toVector(g.equationsOf(3)), (std::vector<int>{1}));
}

TEST(BipartiteGraph, RejectsOutOfRangeIds) {
  std::vector<Edge> badVariable = {{0, 2}};
  std::vector<Edge> badEquation = {{-1, 0}};
  EXPECT_THROW(BipartiteGraph(1, 2, badVariable), std::invalid_argument);
  EXPECT_THROW(BipartiteGraph(1, 2, badEquation), std::invalid_argument);
  EXPECT_THROW(BipartiteGraph(-1, 2, {}), std::invalid_argument);
}

}  // namespace
}  // namespace qdot::structural
