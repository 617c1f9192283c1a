// BLT ordering on hand-made systems with known block structure and solve order: triangular systems,
// a single algebraic loop, loops feeding each other, and rejection of non-perfect matchings.
#include "structural/BlockTriangular.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "Reference.h"

namespace qdot::structural {
namespace {

using Blocks = std::vector<std::vector<int>>;

BlockTriangularOrder bltOf(const BipartiteGraph& g, Matching& m) {
  m = maximumMatching(g);
  EXPECT_TRUE(m.isPerfect());
  BlockTriangularOrder order = blockTriangularOrder(g, m);
  EXPECT_TRUE(test::respectsDependencies(g, m, order));
  return order;
}

TEST(BlockTriangular, EmptySystemHasNoBlocks) {
  BipartiteGraph g;
  EXPECT_TRUE(blockTriangularOrder(g, maximumMatching(g)).blocks.empty());
}

TEST(BlockTriangular, LowerTriangularGivesSingletonsInOrder) {
  // e_i mentions v_0..v_i.
  const int n = 6;
  std::vector<std::vector<int>> rows(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= i; ++j) rows[i].push_back(j);
  BipartiteGraph g = BipartiteGraph::fromAdjacency(n, rows);
  Matching m;
  EXPECT_EQ(bltOf(g, m).blocks, (Blocks{{0}, {1}, {2}, {3}, {4}, {5}}));
}

TEST(BlockTriangular, UpperTriangularGivesSingletonsInReverse) {
  // e_i mentions v_i..v_{n-1}: e_{n-1} must be solved first.
  const int n = 5;
  std::vector<std::vector<int>> rows(n);
  for (int i = 0; i < n; ++i)
    for (int j = i; j < n; ++j) rows[i].push_back(j);
  BipartiteGraph g = BipartiteGraph::fromAdjacency(n, rows);
  Matching m;
  EXPECT_EQ(bltOf(g, m).blocks, (Blocks{{4}, {3}, {2}, {1}, {0}}));
}

TEST(BlockTriangular, CycleGivesOneBlock) {
  // e_i mentions v_i and v_{(i+1) mod n}.
  const int n = 7;
  std::vector<std::vector<int>> rows(n);
  for (int i = 0; i < n; ++i) rows[i] = {i, (i + 1) % n};
  BipartiteGraph g = BipartiteGraph::fromAdjacency(n, rows);
  Matching m;
  EXPECT_EQ(bltOf(g, m).blocks, (Blocks{{0, 1, 2, 3, 4, 5, 6}}));
}

TEST(BlockTriangular, LoopsAndSingletonsInSolveOrder) {
  // x = 0, y = 1, z = 2, u = 3, w = 4.
  //   e0: z, u      (loop {e0, e3} with e3, needs y)
  //   e1: x         (x first)
  //   e2: x, y      (y from x)
  //   e3: y, z, u
  //   e4: u, w      (w last)
  BipartiteGraph g = BipartiteGraph::fromAdjacency(5, {{2, 3}, {0}, {0, 1}, {1, 2, 3}, {3, 4}});
  Matching m;
  BlockTriangularOrder order = bltOf(g, m);
  EXPECT_EQ(order.blocks, (Blocks{{1}, {2}, {0, 3}, {4}}));
  EXPECT_EQ(variablesOfBlock(order.blocks[0], m), (std::vector<int>{0}));
  EXPECT_EQ(variablesOfBlock(order.blocks[1], m), (std::vector<int>{1}));
  std::vector<int> loopVars = variablesOfBlock(order.blocks[2], m);
  std::sort(loopVars.begin(), loopVars.end());
  EXPECT_EQ(loopVars, (std::vector<int>{2, 3}));
}

TEST(BlockTriangular, TwoIndependentLoopsThenConsumer) {
  // Loop A: e0 <-> e1 over a0, a1; loop B: e2 <-> e3 over b0, b1; e4 needs a0 and b1.
  BipartiteGraph g = BipartiteGraph::fromAdjacency(5, {{0, 1}, {0, 1}, {2, 3}, {2, 3}, {0, 3, 4}});
  Matching m;
  BlockTriangularOrder order = bltOf(g, m);
  ASSERT_EQ(order.blocks.size(), 3u);
  EXPECT_EQ(order.blocks[0], (std::vector<int>{0, 1}));
  EXPECT_EQ(order.blocks[1], (std::vector<int>{2, 3}));
  EXPECT_EQ(order.blocks[2], (std::vector<int>{4}));
}

TEST(BlockTriangular, RejectsNonPerfectMatching) {
  BipartiteGraph g = BipartiteGraph::fromAdjacency(2, {{0}, {0}});
  EXPECT_THROW(blockTriangularOrder(g, maximumMatching(g)), std::invalid_argument);
  BipartiteGraph square = BipartiteGraph::fromAdjacency(2, {{0}, {1}});
  EXPECT_THROW(blockTriangularOrder(square, Matching::empty(2, 2)), std::invalid_argument);
}

}  // namespace
}  // namespace qdot::structural
