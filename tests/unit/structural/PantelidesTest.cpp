// Pantelides' algorithm on hand-made derivative structures with known differentiation counts (the
// pendulum and a chain of integrators have textbook answers), checks of its postcondition on random
// structures (the highest derivatives can be matched to the latest differentiated equations), and
// a 10^5-pendulum scale case.
#include "structural/Pantelides.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <random>
#include <stdexcept>

#include "structural/BipartiteGraph.h"
#include "structural/Matching.h"

namespace qdot::structural {
namespace {

using Ids = std::vector<int>;

// After the plan: latest form of every equation against the highest derivative of every chain is
// perfectly matchable (Pantelides' postcondition), and the plan's own matching is such a matching.
void expectSolvableForHighestDerivatives(const DerivativeStructure& s, const DifferentiationPlan& p) {
  std::vector<Edge> edges;
  for (int e = 0; e < static_cast<int>(s.occurrences.size()); ++e)
    for (Occurrence o : s.occurrences[e])
      if (o.order + p.differentiations[e] == p.highestOrder[o.chain]) edges.push_back({e, o.chain});
  BipartiteGraph g(static_cast<int>(s.occurrences.size()), static_cast<int>(s.highestOrder.size()), edges);
  EXPECT_TRUE(maximumMatching(g).isPerfect());
  std::vector<char> used(s.highestOrder.size(), 0);
  for (int e = 0; e < static_cast<int>(s.occurrences.size()); ++e) {
    int c = p.matchedChain[e];
    ASSERT_GE(c, 0);
    EXPECT_FALSE(used[c]);
    used[c] = 1;
    bool highest = false;
    for (Occurrence o : s.occurrences[e]) highest |= o.chain == c && o.order + p.differentiations[e] == p.highestOrder[c];
    EXPECT_TRUE(highest) << "equation " << e;
  }
}

// Cartesian pendulum: chains x, y (accelerations appear: order 2) and lambda (0).
//   m x'' - 2 x λ = 0,  m y'' + m g - 2 y λ = 0,  x² + y² - l² = 0.
DerivativeStructure pendulum() {
  return {{2, 2, 0}, {{{0, 2}, {0, 0}, {2, 0}}, {{1, 2}, {1, 0}, {2, 0}}, {{0, 0}, {1, 0}}}};
}

TEST(Pantelides, PendulumDifferentiatesTheConstraintTwice) {
  DerivativeStructure s = pendulum();
  DifferentiationPlan p = pantelides(s);
  EXPECT_EQ(p.differentiations, (Ids{0, 0, 2}));
  EXPECT_EQ(p.highestOrder, (Ids{2, 2, 0}));
  EXPECT_EQ(p.maxDifferentiations(), 2);
  expectSolvableForHighestDerivatives(s, p);
}

TEST(Pantelides, IndexOneSystemIsLeftAlone) {
  // x' = f(x, z), 0 = g(x, z)
  DerivativeStructure s{{1, 0}, {{{0, 1}, {0, 0}, {1, 0}}, {{0, 0}, {1, 0}}}};
  DifferentiationPlan p = pantelides(s);
  EXPECT_EQ(p.differentiations, (Ids{0, 0}));
  EXPECT_EQ(p.highestOrder, (Ids{1, 0}));
}

TEST(Pantelides, PrescribedStateIsIndexTwo) {
  // x' + y = 0, x = sin t: differentiate the second once; y is then determined.
  DerivativeStructure s{{1, 0}, {{{0, 1}, {1, 0}}, {{0, 0}}}};
  DifferentiationPlan p = pantelides(s);
  EXPECT_EQ(p.differentiations, (Ids{0, 1}));
  EXPECT_EQ(p.highestOrder, (Ids{1, 0}));
  expectSolvableForHighestDerivatives(s, p);
}

TEST(Pantelides, ChainOfIntegratorsRaisesOrders) {
  // x1' = x2, x2' = y, x1 = u(t): index 3. x1 = u is differentiated twice, x1' = x2 once, and the
  // chains x1, x2 gain one order each (x1'', x2'' ... only as far as needed).
  DerivativeStructure s{{1, 1, 0}, {{{0, 1}, {1, 0}}, {{1, 1}, {2, 0}}, {{0, 0}}}};
  DifferentiationPlan p = pantelides(s);
  EXPECT_EQ(p.differentiations, (Ids{1, 0, 2}));
  EXPECT_EQ(p.highestOrder, (Ids{2, 1, 0}));
  expectSolvableForHighestDerivatives(s, p);
}

TEST(Pantelides, AlgebraicVariableInDifferentiatedEquationGetsDerivatives) {
  // m x'' = -λ x,  h = x (an algebraic alias used in the constraint),  h = 1 (a fixed position).
  // Chains x (2), λ (0), h (0). The constraint and the definition of h are both differentiated twice.
  DerivativeStructure s{{2, 0, 0}, {{{0, 2}, {0, 0}, {1, 0}}, {{2, 0}, {0, 0}}, {{2, 0}}}};
  DifferentiationPlan p = pantelides(s);
  EXPECT_EQ(p.differentiations, (Ids{0, 2, 2}));
  EXPECT_EQ(p.highestOrder, (Ids{2, 0, 2}));
  expectSolvableForHighestDerivatives(s, p);
}

TEST(Pantelides, StructurallySingularInputIsRejected) {
  DerivativeStructure s{{1, 0}, {{{0, 0}}, {{0, 1}}}};  // y occurs nowhere
  EXPECT_FALSE(chainsDetermined(s));
  EXPECT_THROW(pantelides(s), std::invalid_argument);
  DerivativeStructure tooMany{{1}, {{{0, 1}}, {{0, 0}}}};
  EXPECT_THROW(pantelides(tooMany), std::invalid_argument);
}

// Random square structures that are structurally nonsingular: a hidden perfect matching plus noise.
TEST(Pantelides, RandomStructuresMeetThePostcondition) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 300; ++trial) {
    int n = 1 + static_cast<int>(rng() % 12);
    DerivativeStructure s;
    s.highestOrder.resize(n);
    for (int& k : s.highestOrder) k = static_cast<int>(rng() % 3);
    s.occurrences.resize(n);
    std::vector<int> perm(n);
    for (int i = 0; i < n; ++i) perm[i] = i;
    std::shuffle(perm.begin(), perm.end(), rng);
    for (int e = 0; e < n; ++e) {
      int c = perm[e];
      s.occurrences[e].push_back({c, static_cast<int>(rng() % (s.highestOrder[c] + 1))});
      int extra = static_cast<int>(rng() % 3);
      for (int k = 0; k < extra; ++k) {
        int d = static_cast<int>(rng() % n);
        s.occurrences[e].push_back({d, static_cast<int>(rng() % (s.highestOrder[d] + 1))});
      }
    }
    DifferentiationPlan p = pantelides(s);
    for (int c = 0; c < n; ++c) EXPECT_GE(p.highestOrder[c], s.highestOrder[c]);
    expectSolvableForHighestDerivatives(s, p);
  }
}

TEST(Pantelides, HundredThousandPendulums) {
  const int pendulums = 100000;
  DerivativeStructure s;
  for (int k = 0; k < pendulums; ++k) {
    DerivativeStructure one = pendulum();
    int base = 3 * k;
    for (int& order : one.highestOrder) s.highestOrder.push_back(order);
    for (auto& list : one.occurrences) {
      for (Occurrence& o : list) o.chain += base;
      s.occurrences.push_back(list);
    }
  }
  auto start = std::chrono::steady_clock::now();
  DifferentiationPlan p = pantelides(s);
  double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("pantelides on %d pendulums: %.1f ms\n", pendulums, ms);
  for (int k = 0; k < pendulums; ++k) ASSERT_EQ(p.differentiations[3 * k + 2], 2);
}

}  // namespace
}  // namespace qdot::structural
