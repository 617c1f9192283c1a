// DirectionalDerivative (d/dt along a vector field): agrees with Σ_s diff(e, s)·rate(s) on random
// expressions, shares its memo between calls (a repeated call adds no node, a bigger expression
// only its new nodes), costs O(DAG size) where per-symbol differentiation is quadratic, handles
// rate changes and lazily supplied (even failing) rates.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "RandomTree.h"
#include "symbolic/Expr.h"

using namespace qdot::sym;
using namespace qdot::sym::testing;

namespace {

std::string numbered(const char* prefix, size_t i) {
  std::string name = prefix;  // (not prefix + to_string: GCC 12 -O3 warns falsely on that)
  name += std::to_string(i);
  return name;
}

class Ddt : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), t = ctx.symbol("t");
  Expr vx = ctx.symbol("vx"), vy = ctx.symbol("vy");
  Expr c(double v) { return ctx.constant(v); }
  Expr f(Kind k, Expr a) { return ctx.unary(k, a); }
};

TEST_F(Ddt, LeavesAndRules) {
  DirectionalDerivative d(ctx);
  d.setRate(x, vx);
  d.setRate(t, ctx.one());
  EXPECT_EQ(d(x), vx);
  EXPECT_EQ(d(y), ctx.zero());  // no rate: constant
  EXPECT_EQ(d(c(3)), ctx.zero());
  EXPECT_EQ(d(t), ctx.one());
  EXPECT_EQ(d(f(Kind::Sin, x)), ctx.mul(f(Kind::Cos, x), vx));
  EXPECT_EQ(d(ctx.mul(x, y)), ctx.mul(y, vx));
  EXPECT_EQ(d(ctx.mul(x, t)), ctx.add(x, ctx.mul(t, vx)));
  EXPECT_THROW(d.setRate(ctx.add(x, y), vx), std::invalid_argument);
}

TEST_F(Ddt, DiffIsTheUnitDirection) {
  Expr e = f(Kind::Sin, ctx.mul(f(Kind::Exp, x), ctx.add(x, y)));
  DirectionalDerivative d(ctx);
  d.setRate(x, ctx.one());
  EXPECT_EQ(d(e), ctx.diff(e, x));
}

// Random expressions over x, y, z with rates x -> y, y -> 2, z -> sin(x) + z (a rate may contain
// any symbol): d(e) and Σ diff(e, s)·rate(s) must evaluate to the same number.
TEST(DdtRandom, AgreesWithSumOfPartials) {
  TreeGen gen(4242);
  int checked = 0, failures = 0;
  for (int n = 0; n < 1500; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("x"), ctx.symbol("y"), ctx.symbol("z")};
    std::vector<Expr> rates = {vars[1], ctx.constant(2.0),
                               ctx.add(ctx.unary(Kind::Sin, vars[0]), vars[2])};
    Expr e = toExpr(ctx, *gen.gen(6), vars);
    DirectionalDerivative d(ctx);
    for (int v = 0; v < 3; ++v) d.setRate(vars[v], rates[v]);
    Expr forward = d(e);
    std::vector<Expr> terms;
    for (int v = 0; v < 3; ++v) terms.push_back(ctx.mul(ctx.diff(e, vars[v]), rates[v]));
    Expr reference = ctx.add(terms);
    std::vector<double> pt = {gen.point(), gen.point(), gen.point()};
    double a = evaluate(forward, pt), b = evaluate(reference, pt);
    if (!std::isfinite(a) || !std::isfinite(b)) continue;
    ++checked;
    if (std::fabs(a - b) > 1e-9 * (1 + std::fabs(b)) && ++failures <= 10)
      ADD_FAILURE() << toString(ctx, e) << "\n  forward " << a << " = " << toString(ctx, forward)
                    << "\n  partials " << b << " = " << toString(ctx, reference);
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GE(checked, 1000);
}

TEST_F(Ddt, RepeatedCallAddsNoNode) {
  DirectionalDerivative d(ctx);
  d.setRate(x, vx);
  d.setRate(y, vy);
  Expr e = ctx.mul(f(Kind::Sin, ctx.mul(x, y)), ctx.add(x, ctx.pow(y, c(3))));
  Expr first = d(e);
  size_t nodes = ctx.nodeCount();
  EXPECT_EQ(d(e), first);
  EXPECT_EQ(ctx.nodeCount(), nodes);
}

// A sum whose terms were differentiated before costs only its own node.
TEST_F(Ddt, SharedSubexpressionsAreDifferentiatedOnce) {
  const size_t N = 1000;
  DirectionalDerivative d(ctx);
  std::vector<Expr> terms;
  for (size_t i = 0; i < N; ++i) {
    Expr q = ctx.symbol(numbered("q", i));
    d.setRate(q, ctx.symbol(numbered("v", i)));
    terms.push_back(f(Kind::Sin, q));
    d(terms.back());
  }
  size_t before = ctx.nodeCount();
  Expr sum = ctx.add(terms);
  size_t sumNodes = ctx.nodeCount() - before;
  before = ctx.nodeCount();
  Expr ds = d(sum);
  EXPECT_EQ(ds->args.size(), N);
  EXPECT_LE(ctx.nodeCount() - before, 1 + sumNodes);  // the new Add only
}

// The N-link pendulum's shape: velocities u_i = Σ_{k<=i} cos(q_k) v_k shared by all momenta
// p_j = Σ_{i>=j} u_i cos(q_j). d/dt of every p_j creates O(n²) nodes in total (the size of the
// answer), not the O(n³) a per-symbol expansion would.
TEST(DdtScale, SharedMomentaAreQuadratic) {
  for (size_t n : {20u, 40u, 80u}) {
    Context ctx;
    DirectionalDerivative d(ctx);
    std::vector<Expr> q, v, cosq, u, p;
    for (size_t k = 0; k < n; ++k) {
      q.push_back(ctx.symbol(numbered("q", k)));
      v.push_back(ctx.symbol(numbered("v", k)));
      d.setRate(q[k], v[k]);
      d.setRate(v[k], ctx.symbol(numbered("a", k)));
      cosq.push_back(ctx.unary(Kind::Cos, q[k]));
    }
    for (size_t i = 0; i < n; ++i) {
      std::vector<Expr> terms;
      for (size_t k = 0; k <= i; ++k) terms.push_back(ctx.mul(cosq[k], v[k]));
      u.push_back(ctx.add(terms));
    }
    for (size_t j = 0; j < n; ++j) {
      std::vector<Expr> terms;
      for (size_t i = j; i < n; ++i) terms.push_back(ctx.mul(u[i], cosq[j]));
      p.push_back(ctx.add(terms));
    }
    size_t dag = ctx.dagSize(p), before = ctx.nodeCount();
    for (Expr pj : p) d(pj);
    size_t created = ctx.nodeCount() - before;
    std::printf("[ info ] n = %zu: momenta DAG %zu nodes, d/dt created %zu\n", n, dag, created);
    EXPECT_LE(created, 3 * n * n);  // measured: 2.6 n² at n = 20, 2.1 n² at n = 80
  }
}

// Depth 100 000 without recursion, O(1) new nodes per level.
TEST(DdtScale, DeepChainIsLinear) {
  const size_t N = 100000;
  Context ctx;
  Expr x = ctx.symbol("x");
  DirectionalDerivative d(ctx);
  d.setRate(x, ctx.symbol("v"));
  Expr e = x;
  for (size_t k = 0; k < N; ++k) e = ctx.add(ctx.unary(Kind::Sin, e), x);
  size_t before = ctx.nodeCount();
  Expr de = d(e);
  EXPECT_NE(de, ctx.zero());
  EXPECT_LE(ctx.nodeCount() - before, 6 * N);
}

TEST_F(Ddt, ChangingARateAfterUseDropsTheMemo) {
  DirectionalDerivative d(ctx);
  d.setRate(x, vx);
  Expr e = ctx.mul(x, y);
  EXPECT_EQ(d(e), ctx.mul(y, vx));
  d.setRate(y, vy);  // a new bit: x*y was memoised with y constant
  EXPECT_EQ(d(e), ctx.add(ctx.mul(y, vx), ctx.mul(x, vy)));
  d.setRate(x, c(2));  // x was reached
  EXPECT_EQ(d(e), ctx.add(ctx.scale(2, y), ctx.mul(x, vy)));
  d.setRate(x, c(2));  // unchanged: the memo stays
  size_t nodes = ctx.nodeCount();
  d(e);
  EXPECT_EQ(ctx.nodeCount(), nodes);
}

TEST_F(Ddt, RateFunctionIsAskedOncePerSymbol) {
  DirectionalDerivative d(ctx);
  d.setRate(t, ctx.one());
  int asked = 0;
  d.setRateFunction([&](Expr s) {
    ++asked;
    return s == x ? vx : ctx.zero();
  });
  Expr e = ctx.mul(f(Kind::Sin, x), ctx.add(y, t));
  Expr de = d(e);
  EXPECT_EQ(de, ctx.add(ctx.mul(f(Kind::Sin, x), ctx.one()), ctx.mul(ctx.mul(f(Kind::Cos, x), vx), ctx.add(y, t))));
  EXPECT_EQ(asked, 2);  // x and y; t has an explicit rate
  d(ctx.mul(x, y));
  EXPECT_EQ(asked, 2);
  // replacing the function keeps rates and memo
  d.setRateFunction([&](Expr) -> Expr { ADD_FAILURE() << "asked again"; return ctx.zero(); });
  size_t nodes = ctx.nodeCount();
  EXPECT_EQ(d(e), de);
  EXPECT_EQ(ctx.nodeCount(), nodes);
}

TEST_F(Ddt, ThrowingRateFunctionLeavesAValidMemo) {
  DirectionalDerivative d(ctx);
  bool fail = true;
  d.setRateFunction([&](Expr s) {
    if (s == y && fail) throw std::runtime_error("no rate for y");
    return s == x ? vx : vy;
  });
  EXPECT_EQ(d(f(Kind::Sin, x)), ctx.mul(f(Kind::Cos, x), vx));
  Expr e = ctx.add(f(Kind::Sin, x), ctx.mul(x, y));
  EXPECT_THROW(d(e), std::runtime_error);
  EXPECT_THROW(d(e), std::runtime_error);  // still unrated: asked again
  fail = false;
  EXPECT_EQ(d(e), ctx.add(std::vector<Expr>{ctx.mul(f(Kind::Cos, x), vx), ctx.mul(y, vx), ctx.mul(x, vy)}));
}

}  // namespace
