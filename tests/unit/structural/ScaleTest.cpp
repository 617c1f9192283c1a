// Scale: 10^6-equation chains, bands and random sparse systems must match, decompose and BLT-order
// without deep recursion (no stack overflow) and in near-linear time. Correctness is asserted;
// times are printed, not asserted.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>
#include <vector>

#include "Reference.h"
#include "structural/BlockTriangular.h"
#include "structural/Matching.h"

namespace qdot::structural {
namespace {

constexpr int kN = 1'000'000;

class Stopwatch {
 public:
  explicit Stopwatch(const char* what) : what_(what), start_(std::chrono::steady_clock::now()) {}
  ~Stopwatch() {
    auto ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
    std::printf("[   TIME   ] %-48s %8.1f ms\n", what_, ms);
  }

 private:
  const char* what_;
  std::chrono::steady_clock::time_point start_;
};

// Equation i mentions variables i + offsets[k] (those in range); the last `wrap` adds variable 0
// to the last equation, which closes a cycle.
BipartiteGraph band(int n, const std::vector<int>& offsets, bool wrap = false) {
  std::vector<Edge> edges;
  edges.reserve(static_cast<std::size_t>(n) * offsets.size() + 1);
  for (int i = 0; i < n; ++i)
    for (int d : offsets)
      if (i + d >= 0 && i + d < n) edges.push_back({i, i + d});
  if (wrap) edges.push_back({n - 1, 0});
  return BipartiteGraph(n, n, edges);
}

struct Result {
  Matching matching;
  BlockTriangularOrder order;
};

Result matchAndOrder(const char* name, const BipartiteGraph& g) {
  Stopwatch watch(name);
  Result r;
  r.matching = maximumMatching(g);
  EXPECT_TRUE(r.matching.isPerfect());
  r.order = blockTriangularOrder(g, r.matching);
  return r;
}

TEST(Scale, LowerBidiagonalChainGivesSingletonsInOrder) {
  BipartiteGraph g = band(kN, {-1, 0});
  Result r = matchAndOrder("lower bidiagonal chain, match + BLT", g);
  ASSERT_EQ(r.order.blocks.size(), std::size_t(kN));
  for (int i = 0; i < kN; ++i) ASSERT_EQ(r.order.blocks[i], std::vector<int>{i});
}

TEST(Scale, UpperBidiagonalChainNeedsDeepSearch) {
  // e_0 depends on e_1 depends on ... e_{n-1}: the Tarjan search is 10^6 deep.
  BipartiteGraph g = band(kN, {0, 1});
  Result r = matchAndOrder("upper bidiagonal chain, match + BLT", g);
  ASSERT_EQ(r.order.blocks.size(), std::size_t(kN));
  for (int i = 0; i < kN; ++i) ASSERT_EQ(r.order.blocks[i], std::vector<int>{kN - 1 - i});
}

TEST(Scale, CyclicBandIsOneBlock) {
  BipartiteGraph g = band(kN, {-1, 0, 1}, /*wrap=*/true);
  Result r = matchAndOrder("cyclic tridiagonal band, match + BLT", g);
  ASSERT_EQ(r.order.blocks.size(), 1u);
  ASSERT_EQ(r.order.blocks[0].size(), std::size_t(kN));
  ASSERT_TRUE(test::respectsDependencies(g, r.matching, r.order));
}

BipartiteGraph shiftedChain(int n) {
  std::vector<Edge> edges;
  for (int i = 0; i + 1 < n; ++i) edges.push_back({i, i}), edges.push_back({i, i + 1});
  edges.push_back({n - 1, 0});
  return BipartiteGraph(n, n, edges);
}

TEST(Scale, AugmentingPathThroughWholeChain) {
  // e_i = {v_i, v_{i+1}}, e_{n-1} = {v_0}. From the maximal start e_i-v_i the one augmenting path
  // visits all 2*10^6 vertices, so Hopcroft–Karp's BFS has 10^6 layers and its DFS is 10^6 deep.
  BipartiteGraph g = shiftedChain(kN);
  Matching start = Matching::empty(kN, kN);
  for (int i = 0; i + 1 < kN; ++i) start.matchOfEquation[i] = i, start.matchOfVariable[i] = i;
  Matching m;
  {
    Stopwatch watch("10^6-long augmenting path (warm start)");
    m = maximumMatching(g, start);
  }
  ASSERT_TRUE(m.isPerfect());
  ASSERT_EQ(m.matchOfEquation[kN - 1], 0);
  for (int i = 0; i + 1 < kN; ++i) ASSERT_EQ(m.matchOfEquation[i], i + 1);
}

TEST(Scale, ShiftedChainFromScratch) {
  BipartiteGraph g = shiftedChain(kN);
  Result r = matchAndOrder("shifted chain, match + BLT", g);
  for (int i = 0; i + 1 < kN; ++i) ASSERT_EQ(r.matching.matchOfEquation[i], i + 1);
  // e_{n-1} computes v_0, which e_0 needs, whose v_1 e_1 needs, ...
  ASSERT_EQ(r.order.blocks.size(), std::size_t(kN));
  ASSERT_EQ(r.order.blocks[0], std::vector<int>{kN - 1});
  for (int i = 0; i + 1 < kN; ++i) ASSERT_EQ(r.order.blocks[i + 1], std::vector<int>{i});
}

TEST(Scale, RandomSparseNonsingularSystem) {
  std::mt19937 rng(7);
  BipartiteGraph g = test::randomNonsingularGraph(rng, kN, 2);
  Result r = matchAndOrder("random sparse (3 per row), match + BLT", g);
  ASSERT_TRUE(isValidMatching(g, r.matching));
  ASSERT_TRUE(test::respectsDependencies(g, r.matching, r.order));
  std::printf("[   INFO   ] random sparse: %zu blocks, largest %zu\n", r.order.blocks.size(),
              std::max_element(r.order.blocks.begin(), r.order.blocks.end(),
                               [](const auto& a, const auto& b) { return a.size() < b.size(); })
                  ->size());
}

TEST(Scale, UnderDeterminedChainDecomposes) {
  // 10^6 - 1 equations e_i = {v_i, v_{i+1}} for 10^6 variables: everything is under-determined.
  std::vector<Edge> edges;
  for (int i = 0; i + 1 < kN; ++i) edges.push_back({i, i}), edges.push_back({i, i + 1});
  BipartiteGraph g(kN - 1, kN, edges);
  Stopwatch watch("under-determined chain, match + DM");
  Matching m = maximumMatching(g);
  ASSERT_EQ(m.size(), kN - 1);
  DulmageMendelsohn dm = dulmageMendelsohn(g, m);
  ASSERT_EQ(dm.underEquations.size(), std::size_t(kN - 1));
  ASSERT_EQ(dm.underVariables.size(), std::size_t(kN));
  ASSERT_TRUE(dm.overEquations.empty());
  ASSERT_TRUE(dm.wellEquations.empty());
}

TEST(Scale, GraphConstruction) {
  std::mt19937 rng(11);
  std::vector<Edge> edges;
  edges.reserve(3 * static_cast<std::size_t>(kN));
  for (int e = 0; e < kN; ++e)
    for (int k = 0; k < 3; ++k) edges.push_back({e, static_cast<int>(rng() % kN)});
  Stopwatch watch("build CSR from 3*10^6 random edges");
  BipartiteGraph g(kN, kN, edges);
  ASSERT_LE(g.numEdges(), 3u * kN);
}

}  // namespace
}  // namespace qdot::structural
