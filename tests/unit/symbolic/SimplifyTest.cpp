// The simplifier (Simplify.h): one test per rewrite with its expected text, the never-longer and
// determinism guarantees, the budget, and a randomized comparison of original and simplified
// expressions at random points inside their domains.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "RandomTree.h"
#include "symbolic/Simplify.h"

using namespace qdot::sym;
using namespace qdot::sym::testing;

namespace {

Expr addAll(Context& cx, std::initializer_list<Expr> l) { return cx.add(std::span<const Expr>(l.begin(), l.size())); }
Expr mulAll(Context& cx, std::initializer_list<Expr> l) { return cx.mul(std::span<const Expr>(l.begin(), l.size())); }

class Simplify : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), a = ctx.symbol("a"), b = ctx.symbol("b"), k = ctx.symbol("k");
  Expr c(double v) { return ctx.constant(v); }
  Expr sin(Expr u) { return ctx.unary(Kind::Sin, u); }
  Expr cos(Expr u) { return ctx.unary(Kind::Cos, u); }
  Expr sq(Expr u) { return ctx.pow(u, c(2)); }
  std::string str(Expr e) { return toString(ctx, e); }
  std::string simp(Expr e, SimplifyLevel l = SimplifyLevel::Fast) { return str(simplify(ctx, e, l)); }
};

TEST_F(Simplify, ExpandsAndCollectsLikeTerms) {
  // (x + y)^2 - (x - y)^2 = 4xy: the terms x^2 and y^2 cancel only after expansion.
  EXPECT_EQ(simp(ctx.sub(sq(ctx.add(x, y)), sq(ctx.sub(x, y)))), "4*x*y");
  // a*(x + y) - a*x = a*y
  EXPECT_EQ(simp(ctx.sub(ctx.mul(a, ctx.add(x, y)), ctx.mul(a, x))), "y*a");
  EXPECT_EQ(simp(ctx.sub(ctx.mul(ctx.add(x, c(1)), ctx.add(x, c(-1))), sq(x))), "-1");
}

TEST_F(Simplify, NeverLengthens) {
  Expr spring = ctx.mul(k, sq(ctx.sub(x, y)));  // expanding gives k*x^2 - 2*k*x*y + k*y^2: longer
  EXPECT_EQ(simplify(ctx, spring), spring);
  Expr poly = ctx.mul(ctx.add(x, c(1)), ctx.add(y, c(2)));
  EXPECT_EQ(simplify(ctx, poly), poly);
}

TEST_F(Simplify, Pythagorean) {
  EXPECT_EQ(simp(ctx.add(sq(sin(x)), sq(cos(x)))), "1");
  // k sin²u + k cos²u = k, also inside a sum with other terms
  EXPECT_EQ(simp(addAll(ctx, {ctx.mul(k, sq(sin(ctx.mul(a, y)))), ctx.mul(k, sq(cos(ctx.mul(a, y)))), x})), "x + k");
  // partial match: 3 sin² + cos² = 1 + 2 sin² (shorter); a sin² + b cos² stays (rewriting is longer)
  EXPECT_EQ(simp(ctx.add(ctx.scale(3, sq(sin(x))), sq(cos(x)))), "2*sin(x)^2 + 1");
  Expr general = ctx.add(ctx.mul(a, sq(sin(x))), ctx.mul(b, sq(cos(x))));
  EXPECT_EQ(simplify(ctx, general), general);
  // cos⁴ − sin⁴ = cos² − sin² = 1 − 2 sin² (whichever is shortest)
  EXPECT_EQ(simp(ctx.sub(ctx.pow(cos(x), c(4)), ctx.pow(sin(x), c(4)))), "-2*sin(x)^2 + 1");
}

TEST_F(Simplify, Hyperbolic) {
  Expr sh = ctx.unary(Kind::Sinh, x), ch = ctx.unary(Kind::Cosh, x);
  EXPECT_EQ(simp(ctx.sub(sq(ch), sq(sh))), "1");
  EXPECT_EQ(simp(ctx.mul(a, ctx.sub(sq(sh), sq(ch)))), "-a");
}

TEST_F(Simplify, AngleDifferenceAndSum) {
  EXPECT_EQ(simp(ctx.sub(ctx.mul(sin(a), cos(b)), ctx.mul(cos(a), sin(b)))), "sin(a - b)");
  EXPECT_EQ(simp(ctx.add(ctx.mul(cos(a), cos(b)), ctx.mul(sin(a), sin(b)))), "cos(a - b)");
  EXPECT_EQ(simp(ctx.sub(ctx.mul(cos(a), cos(b)), ctx.mul(sin(a), sin(b)))), "cos(a + b)");
  EXPECT_EQ(simp(ctx.add(ctx.mul(sin(a), cos(b)), ctx.mul(cos(a), sin(b)))), "sin(a + b)");
  // with a common rest and coefficient: 2 x (cos a cos b + sin a sin b) = 2 x cos(a − b)
  Expr rest = ctx.scale(2, x);
  EXPECT_EQ(simp(ctx.add(mulAll(ctx, {rest, cos(a), cos(b)}), mulAll(ctx, {rest, sin(a), sin(b)}))), "2*x*cos(a - b)");
  // coefficients that differ do not contract
  Expr unequal = ctx.add(ctx.mul(cos(a), cos(b)), ctx.scale(2, ctx.mul(sin(a), sin(b))));
  EXPECT_EQ(simplify(ctx, unequal), unequal);
}

TEST_F(Simplify, CanonicalSignOfArguments) {
  EXPECT_EQ(simp(ctx.add(sin(ctx.sub(a, b)), sin(ctx.sub(b, a)))), "0");
  EXPECT_EQ(simp(ctx.sub(cos(ctx.sub(a, b)), cos(ctx.sub(b, a)))), "0");
}

TEST_F(Simplify, FactorsCommonFactors) {
  // m R² θ'' − m R² Ω² s c + m g R s: every term has m and R
  Expr m = ctx.symbol("m"), R = ctx.symbol("R"), g = ctx.symbol("g");
  Expr e = addAll(ctx, {mulAll(ctx, {m, sq(R), x}), mulAll(ctx, {m, R, g, sin(y)})});
  EXPECT_EQ(simp(e), "m*R*(x*R + g*sin(y))");
}

TEST_F(Simplify, InversePairsAndRoots) {
  Expr positive = ctx.add(sq(x), c(1));
  EXPECT_EQ(simp(ctx.unary(Kind::Exp, ctx.unary(Kind::Log, positive))), "x^2 + 1");
  EXPECT_EQ(simp(ctx.unary(Kind::Log, ctx.unary(Kind::Exp, x))), "x");
  EXPECT_EQ(simp(ctx.pow(sq(x), c(0.5))), "abs(x)");
  // inside a product: sqrt(x²)·y = abs(x)·y
  EXPECT_EQ(simp(ctx.mul(ctx.pow(sq(ctx.sub(x, y)), c(0.5)), y)), "y*abs(x - y)");
}

TEST_F(Simplify, LevelNoneKeepsTheExpression) {
  Expr e = ctx.add(sq(sin(x)), sq(cos(x)));
  EXPECT_EQ(simplify(ctx, e, SimplifyLevel::None), e);
}

TEST_F(Simplify, BudgetBoundsTheWork) {
  // (x1 + ... + x12)^12 has millions of terms: fast gives up after a budget proportional to the input.
  std::vector<Expr> xs;
  for (int i = 0; i < 12; ++i) xs.push_back(ctx.symbol("x" + std::to_string(i)));
  Expr big = ctx.pow(ctx.add(xs), c(12));
  Simplifier s(ctx, SimplifyLevel::Fast);
  EXPECT_EQ(s(big), big);
  EXPECT_TRUE(s.gaveUp());
  // 1.35 million terms need far more products; the call stopped after its budget (40 000 + 8 per
  // node) plus the one product that went over it.
  EXPECT_LT(s.work(), 200000u);
  Expr small = ctx.pow(ctx.add(xs[0], xs[1]), c(2));
  EXPECT_EQ(s(small), small);  // (x0 + x1)^2 expanded is longer
  EXPECT_FALSE(s.gaveUp());
}

TEST_F(Simplify, DeterministicAcrossContexts) {
  // The same expression built in two contexts with different allocation histories prints the same.
  auto build = [](Context& cx, int padding) {
    for (int i = 0; i < padding; ++i) cx.symbol("pad" + std::to_string(i));
    Expr p = cx.symbol("p"), q = cx.symbol("q"), r = cx.symbol("r");
    Expr s = cx.unary(Kind::Sin, p), co = cx.unary(Kind::Cos, p), s2 = cx.unary(Kind::Sin, q), c2 = cx.unary(Kind::Cos, q);
    Expr e = addAll(cx, {mulAll(cx, {r, co, c2}), mulAll(cx, {r, s, s2}), cx.pow(cx.add(s, r), cx.constant(2)), cx.mul(r, cx.pow(co, cx.constant(2)))});
    return toString(cx, simplify(cx, e));
  };
  Context c1, c2;
  EXPECT_EQ(build(c1, 0), build(c2, 0));
}

TEST_F(Simplify, ParsesLevels) {
  SimplifyLevel l;
  EXPECT_TRUE(parseSimplifyLevel("full", l));
  EXPECT_EQ(l, SimplifyLevel::Full);
  EXPECT_TRUE(parseSimplifyLevel("none", l));
  EXPECT_EQ(l, SimplifyLevel::None);
  EXPECT_FALSE(parseSimplifyLevel("fastest", l));
}

// Whether the tree compares values: x < y flips when rounding moves x across y, so such trees may
// differ by more than rounding (log(exp(u)) < u is sometimes true; u < u never).
bool compares(const Tree& t) {
  if (t.op == Op::Lt || t.op == Op::Le || t.op == Op::Eq || t.op == Op::Ne) return true;
  for (const auto& k : t.kids)
    if (compares(*k)) return true;
  return false;
}

// Original and simplified agree at random points (the generator keeps arguments in their domains).
TEST(SimplifyRandom, AgreesWithTheOriginal) {
  int compared = 0;
  for (uint64_t seed = 1; seed <= 400; ++seed) {
    TreeGen gen(seed);
    TreePtr t = gen.gen(5);
    Context ctx;
    std::vector<Expr> vars{ctx.symbol("x0"), ctx.symbol("x1"), ctx.symbol("x2")};
    Expr e = toExpr(ctx, *t, vars);
    Expr s = simplify(ctx, e, SimplifyLevel::Full);
    EXPECT_LE(expressionCost(s), expressionCost(e)) << toString(ctx, e);
    for (int p = 0; p < 5; ++p) {
      std::vector<double> at{gen.point(), gen.point(), gen.point()};
      RefEval ref = refEval(*t, at);
      double v0 = evaluate(e, at), v1 = evaluate(s, at);
      if (!std::isfinite(v0) || ref.maxAbs > 1e6 || compares(*t)) continue;
      double tol = 1e-9 * std::max(1.0, ref.maxAbs);
      EXPECT_NEAR(v1, v0, tol) << "seed " << seed << ": " << toString(ctx, e) << "  ->  " << toString(ctx, s);
      ++compared;
    }
  }
  EXPECT_GT(compared, 600);
}

}  // namespace

namespace {

// For kernels: sin/cos of a ± b (two symbols) as products of sin and cos of each, same values.
TEST(ExpandAngleDifferences, WritesDifferencesThroughEachAngle) {
  Context ctx;
  Expr a = ctx.symbol("a"), b = ctx.symbol("b"), x = ctx.symbol("x");
  Expr d = ctx.sub(a, b), s = ctx.add(a, b), nd = ctx.sub(b, a);
  std::vector<Expr> roots{ctx.mul(x, ctx.unary(Kind::Sin, d)), ctx.unary(Kind::Cos, d), ctx.unary(Kind::Sin, s),
                          ctx.unary(Kind::Cos, s), ctx.unary(Kind::Sin, nd), ctx.unary(Kind::Sin, ctx.scale(2, a))};
  std::vector<Expr> out = expandAngleDifferences(ctx, roots);
  EXPECT_EQ(toString(ctx, out[1]), "sin(a)*sin(b) + cos(a)*cos(b)");
  EXPECT_EQ(out[5], roots[5]);  // sin(2a) is not a pair of symbols
  std::vector<double> values(ctx.symbolCount());
  values[a->symbolId] = 0.7, values[b->symbolId] = -1.3, values[x->symbolId] = 2.5;
  for (size_t i = 0; i < roots.size(); ++i) {
    EXPECT_NEAR(evaluate(out[i], values), evaluate(roots[i], values), 1e-15) << toString(ctx, roots[i]);
    EXPECT_FALSE(toString(ctx, out[i]).find("a - b") != std::string::npos) << toString(ctx, out[i]);
  }
}

}  // namespace

namespace {

// Sums of products of squared sines and cosines (and hyperbolic ones) of a few arguments, with
// coefficients that cancel or nearly cancel: the Pythagorean rewrites move, merge and drop terms
// (pythagorean rewrites in place); the result has the original's values at random points.
TEST(SimplifyRandom, TrigonometricSquaresKeepTheirValues) {
  std::mt19937_64 rng(7);
  const double coefs[] = {1, -1, 2, 0.5, -0.5, 0.1, 0.2, -0.3, 3};
  int rewritten = 0;
  for (int round = 0; round < 3000; ++round) {
    Context ctx;
    std::vector<Expr> x{ctx.symbol("x0"), ctx.symbol("x1"), ctx.symbol("x2")};
    std::vector<Expr> args{x[0], ctx.sub(x[0], x[1]), ctx.add(x[2], x[0])};
    const Kind kinds[] = {Kind::Sin, Kind::Cos, Kind::Sinh, Kind::Cosh};
    int terms = 1 + static_cast<int>(rng() % 9);
    std::vector<Expr> sum;
    for (int t = 0; t < terms; ++t) {
      std::vector<Expr> factors{ctx.constant(coefs[rng() % std::size(coefs)])};
      int n = 1 + static_cast<int>(rng() % 3);
      for (int f = 0; f < n; ++f) {
        Kind k = kinds[rng() % (rng() % 4 == 0 ? 4 : 2)];
        Expr u = args[rng() % args.size()];
        factors.push_back(ctx.pow(ctx.unary(k, ctx.mul(ctx.constant(0.3), u)), ctx.constant(static_cast<double>(1 + rng() % 4))));
      }
      if (rng() % 3 == 0) factors.push_back(x[rng() % 3]);
      sum.push_back(ctx.mul(std::span<const Expr>(factors)));
      if (rng() % 2 == 0) {  // its partner: one factor's sine for its cosine (or back), which may cancel
        size_t f = 1 + rng() % n;
        bool power = factors[f]->kind == Kind::Pow;
        Expr base = power ? factors[f]->args[0] : factors[f];
        Kind partner = base->kind == Kind::Sin ? Kind::Cos : base->kind == Kind::Cos ? Kind::Sin
                     : base->kind == Kind::Sinh ? Kind::Cosh : Kind::Sinh;
        factors[f] = ctx.pow(ctx.unary(partner, base->args[0]), power ? factors[f]->args[1] : ctx.one());
        if (rng() % 2 == 0) factors[0] = ctx.constant(-factors[0]->value);
        sum.push_back(ctx.mul(std::span<const Expr>(factors)));
      }
    }
    Expr e = ctx.add(std::span<const Expr>(sum));
    Expr s = simplify(ctx, e, SimplifyLevel::Full);
    rewritten += s != e;
    for (int p = 0; p < 3; ++p) {
      std::uniform_real_distribution<double> d(-2, 2);
      std::vector<double> at{d(rng), d(rng), d(rng)};
      double v0 = evaluate(e, at), v1 = evaluate(s, at);
      ASSERT_NEAR(v1, v0, 1e-9 * std::max(1.0, std::abs(v0))) << toString(ctx, e) << "  ->  " << toString(ctx, s);
    }
  }
  EXPECT_GT(rewritten, 300);
}

}  // namespace
