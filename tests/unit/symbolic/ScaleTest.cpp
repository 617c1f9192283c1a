// Cost guarantees on big inputs: differentiating a sum of 100 000 terms creates O(N) nodes and is
// fast, repeated derivatives reuse nodes, and expressions of depth 100 000 go through diff,
// substitute, evaluate, toString, CSE, freeSymbols, dependsOn and dagSize without recursion.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

std::string numbered(const char* prefix, size_t i) {
  std::string name = prefix;
  name += std::to_string(i);
  return name;
}

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Generous bounds: the Release build takes a small fraction of these; sanitizer builds are slower.
#ifdef NDEBUG
constexpr double kSlack = 1.0;
#else
constexpr double kSlack = 20.0;
#endif

TEST(Scale, DiffOfLargeSumIsLinear) {
  const size_t N = 100000;
  Context ctx;
  Expr x = ctx.symbol("x");
  std::vector<Expr> q, terms;
  for (size_t i = 0; i < N; ++i) q.push_back(ctx.symbol(numbered("q", i)));
  auto t0 = std::chrono::steady_clock::now();
  for (size_t i = 0; i < N; ++i) terms.push_back(ctx.mul(q[i], ctx.unary(Kind::Sin, ctx.mul(x, q[i]))));
  Expr sum = ctx.add(terms);  // Σ q_i sin(x q_i)
  double buildSeconds = secondsSince(t0);
  ASSERT_EQ(sum->kind, Kind::Add);
  ASSERT_EQ(sum->args.size(), N);

  size_t before = ctx.nodeCount();
  t0 = std::chrono::steady_clock::now();
  Expr d = ctx.diff(sum, x);  // Σ q_i^2 cos(x q_i)
  double diffSeconds = secondsSince(t0);
  size_t created = ctx.nodeCount() - before;
  std::printf("[ info ] N = %zu: build %.3f s, diff %.3f s, %zu new nodes (%.2f per term)\n", N, buildSeconds,
              diffSeconds, created, double(created) / N);
  EXPECT_LT(created, 10 * N);
  EXPECT_LT(diffSeconds, 2.0 * kSlack);
  ASSERT_EQ(d->kind, Kind::Add);
  EXPECT_EQ(d->args.size(), N);

  // the same derivative again: identical pointer, no new node
  before = ctx.nodeCount();
  EXPECT_EQ(ctx.diff(sum, x), d);
  EXPECT_EQ(ctx.nodeCount(), before);

  // w.r.t. one q_j only one term contributes: sin(x q_j) + x q_j cos(x q_j)
  Expr qj = q[12345];
  before = ctx.nodeCount();
  Expr dq = ctx.diff(sum, qj);
  EXPECT_LT(ctx.nodeCount() - before, 20u);
  Expr xq = ctx.mul(x, qj);
  EXPECT_EQ(dq, ctx.add(ctx.unary(Kind::Sin, xq), ctx.mul(xq, ctx.unary(Kind::Cos, xq))));

  // value check against the closed form
  std::vector<double> values(ctx.symbolCount());
  values[x->symbolId] = 0.7;
  double expected = 0;
  for (size_t i = 0; i < N; ++i) {
    double qi = 1.0 + double(i % 97) / 97.0;
    values[q[i]->symbolId] = qi;
    expected += qi * qi * std::cos(0.7 * qi);
  }
  EXPECT_NEAR(evaluate(d, values), expected, 1e-9 * std::fabs(expected) + 1e-9);
}

TEST(Scale, BuildingLargeSumsAndProducts) {
  const size_t N = 200000;
  Context ctx;
  Expr x = ctx.symbol("x");
  std::vector<Expr> terms;
  for (size_t i = 0; i < N; ++i) terms.push_back(ctx.pow(x, ctx.constant(double(i % 1000) + 2)));
  auto t0 = std::chrono::steady_clock::now();
  Expr sum = ctx.add(terms);
  Expr product = ctx.mul(terms);
  double seconds = secondsSince(t0);
  std::printf("[ info ] add + mul of %zu operands: %.3f s\n", N, seconds);
  EXPECT_LT(seconds, 2.0 * kSlack);
  ASSERT_EQ(sum->kind, Kind::Add);
  EXPECT_EQ(sum->args.size(), 1000u);                     // like terms collected
  EXPECT_EQ(sum->coefs()[0], 200.0);
  EXPECT_EQ(product, ctx.pow(x, ctx.constant(200.0 * (1000 * 1001 / 2 + 1000))));  // Σ exponents
}

// a_0 = x, a_{k+1} = a_k * x + 1 (depth ~ 2·10^5 nodes on the longest path)
struct Chain {
  Context ctx;
  Expr x = ctx.symbol("x");
  Expr top;
  explicit Chain(size_t n) {
    Expr a = x;
    for (size_t k = 0; k < n; ++k) a = ctx.add(ctx.mul(a, x), ctx.one());
    top = a;
  }
};

TEST(Scale, DeepChainThroughEveryAlgorithm) {
  const size_t N = 100000;
  Chain ch(N);
  Context& ctx = ch.ctx;
  Expr x = ch.x, a = ch.top;
  EXPECT_GE(a->depth, N);
  EXPECT_LT(ctx.nodeCount(), 4 * N);

  // reference values by the recurrence itself
  double xv = 0.5, av = xv, dv = 1.0;
  for (size_t k = 0; k < N; ++k) {
    dv = dv * xv + av;
    av = av * xv + 1;
  }
  std::vector<double> values = {xv};
  EXPECT_NEAR(evaluate(a, values), av, 1e-12);

  size_t before = ctx.nodeCount();
  Expr d = ctx.diff(a, x);
  EXPECT_LT(ctx.nodeCount() - before, 10 * N);
  EXPECT_NEAR(evaluate(d, values), dv, 1e-9 * dv);
  EXPECT_EQ(ctx.diff(a, x), d);

  Expr y = ctx.symbol("y");
  Expr ay = ctx.substitute(a, {{x, y}});
  EXPECT_EQ(ctx.freeSymbols(ay), std::vector<Expr>{y});
  EXPECT_NEAR(evaluate(ay, std::vector<double>{0.0, xv}), av, 1e-12);
  Expr folded = ctx.substitute(a, {{x, ctx.constant(0.5)}});
  ASSERT_TRUE(folded->isConstant());
  EXPECT_NEAR(folded->value, av, 1e-12);

  EXPECT_EQ(ctx.freeSymbols(a), std::vector<Expr>{x});
  EXPECT_TRUE(ctx.dependsOn(a, x));
  Expr sameBit = x;  // a symbol sharing x's mask bit forces a full (iterative) traversal
  while (sameBit->symbolId % 64 != 0 || sameBit == x) sameBit = ctx.symbol(numbered("s", ctx.symbolCount()));
  ASSERT_EQ(sameBit->symbolMask, x->symbolMask);
  EXPECT_FALSE(ctx.dependsOn(a, sameBit));

  Expr roots[] = {a, d};
  size_t dag = ctx.dagSize(roots);
  EXPECT_GT(dag, 2 * N);
  EXPECT_EQ(ctx.dagSize(std::span<const Expr>(&a, 1)), 2 * N + 3);  // N Adds, N Muls, x, 1, and a_0 = x

  // a_1 = x^2 + 1, a_k = x*(a_{k-1}) + 1: factors print symbols first
  std::string text = toString(ctx, a);
  EXPECT_EQ(text.size(), 7 + 8 * (N - 1));
  EXPECT_EQ(text.substr(0, 9), "x*(x*(x*(");
  EXPECT_EQ(text.substr(text.size() - 10), ") + 1) + 1");
  EXPECT_EQ(text.find("x^2"), 3 * (N - 1));

  CseResult cse = eliminateCommonSubexpressions(ctx, roots);
  ASSERT_EQ(cse.outputs.size(), 2u);
  EXPECT_GT(cse.temporaries.size(), N / 2);
  std::vector<double> all(ctx.symbolCount(), 0.0);
  all[x->symbolId] = xv;
  for (auto& [t, v] : cse.temporaries) {
    all.resize(ctx.symbolCount(), 0.0);
    all[t->symbolId] = evaluate(v, all);
  }
  EXPECT_NEAR(evaluate(cse.outputs[0], all), av, 1e-12);
  EXPECT_NEAR(evaluate(cse.outputs[1], all), dv, 1e-9 * dv);
}

// e_{k+1} = sin(e_k) * x + 1: a deep chain through a function, differentiated twice.
TEST(Scale, DeepFunctionChain) {
  const size_t N = 100000;
  Context ctx;
  Expr x = ctx.symbol("x");
  Expr e = x;
  for (size_t k = 0; k < N; ++k) e = ctx.add(ctx.mul(ctx.unary(Kind::Sin, e), x), ctx.one());
  double xv = 0.3, ev = xv, dv = 1.0;
  for (size_t k = 0; k < N; ++k) {
    dv = std::cos(ev) * dv * xv + std::sin(ev);
    ev = std::sin(ev) * xv + 1;
  }
  std::vector<double> values = {xv};
  EXPECT_NEAR(evaluate(e, values), ev, 1e-12);
  size_t before = ctx.nodeCount();
  Expr d = ctx.diff(e, x);
  EXPECT_LT(ctx.nodeCount() - before, 10 * N);
  EXPECT_NEAR(evaluate(d, values), dv, 1e-9 * (1 + std::fabs(dv)));
  Expr d2 = ctx.diff(d, x);
  EXPECT_TRUE(std::isfinite(evaluate(d2, values)));
  // printing is tree-sized (e occurs once in each level of itself, so this is linear)
  std::string text = toString(ctx, e);
  EXPECT_EQ(text.size(), 12 + 11 * (N - 1));
  EXPECT_EQ(text.substr(0, 12), "x*sin(x*sin(");
  EXPECT_EQ(text.find("x*sin(x) + 1)"), 6 * (N - 1));
}

}  // namespace
