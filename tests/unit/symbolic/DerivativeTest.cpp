// Context::diff: exact results of every rule (pointer equality with the hand-built answer),
// memoisation, and a property test comparing derivatives of thousands of random expressions with
// finite differences of an independent reference evaluation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "RandomTree.h"
#include "symbolic/Expr.h"

using namespace qdot::sym;
using namespace qdot::sym::testing;

namespace {

class Diff : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y");
  Expr c(double v) { return ctx.constant(v); }
  Expr f(Kind k, Expr a) { return ctx.unary(k, a); }
  Expr sq(Expr e) { return ctx.pow(e, c(2)); }
};

TEST_F(Diff, Leaves) {
  EXPECT_EQ(ctx.diff(x, x), ctx.one());
  EXPECT_EQ(ctx.diff(y, x), ctx.zero());
  EXPECT_EQ(ctx.diff(c(3), x), ctx.zero());
  EXPECT_THROW(ctx.diff(x, ctx.add(x, y)), std::invalid_argument);
}

TEST_F(Diff, Arithmetic) {
  EXPECT_EQ(ctx.diff(ctx.add(ctx.scale(3, x), y), x), c(3));
  EXPECT_EQ(ctx.diff(sq(x), x), ctx.scale(2, x));
  EXPECT_EQ(ctx.diff(ctx.pow(x, c(3)), x), ctx.scale(3, sq(x)));
  EXPECT_EQ(ctx.diff(ctx.mul(x, y), x), y);
  EXPECT_EQ(ctx.diff(ctx.mul(sq(x), y), x), ctx.scale(2, ctx.mul(x, y)));
  EXPECT_EQ(ctx.diff(ctx.div(ctx.one(), x), x), ctx.neg(ctx.pow(x, c(-2))));
  EXPECT_EQ(ctx.diff(ctx.pow(x, c(0.5)), x), ctx.scale(0.5, ctx.pow(x, c(-0.5))));
  // product of sums: (x+1)*(x+y) -> (x+y) + (x+1), collected, not expanded further
  Expr p = ctx.mul(ctx.add(x, c(1)), ctx.add(x, y));
  EXPECT_EQ(ctx.diff(p, x), ctx.add(std::vector<Expr>{ctx.scale(2, x), y, c(1)}));
}

TEST_F(Diff, PowWithConstantExponentHasNoLog) {
  Expr d = ctx.diff(ctx.pow(ctx.add(x, y), c(2)), x);
  EXPECT_EQ(d, ctx.scale(2, ctx.add(x, y)));
  EXPECT_EQ(toString(ctx, ctx.diff(ctx.pow(x, c(2.5)), x)).find("log"), std::string::npos);
}

TEST_F(Diff, GeneralPow) {
  // d(2^x) = 2^x * log(2)
  Expr e = ctx.pow(c(2), x);
  EXPECT_EQ(ctx.diff(e, x), ctx.scale(std::log(2.0), e));
  // d(x^y)/dy = x^y * log(x);  d(x^y)/dx = y * x^(y-1)
  Expr xy = ctx.pow(x, y);
  EXPECT_EQ(ctx.diff(xy, y), ctx.mul(xy, f(Kind::Log, x)));
  EXPECT_EQ(ctx.diff(xy, x), ctx.mul(y, ctx.pow(x, ctx.sub(y, ctx.one()))));
}

TEST_F(Diff, ElementaryFunctions) {
  Expr u = ctx.mul(x, y);  // du/dx = y
  EXPECT_EQ(ctx.diff(f(Kind::Sin, x), x), f(Kind::Cos, x));
  EXPECT_EQ(ctx.diff(f(Kind::Sin, u), x), ctx.mul(f(Kind::Cos, u), y));
  EXPECT_EQ(ctx.diff(f(Kind::Cos, x), x), ctx.neg(f(Kind::Sin, x)));
  EXPECT_EQ(ctx.diff(f(Kind::Exp, u), x), ctx.mul(f(Kind::Exp, u), y));
  EXPECT_EQ(ctx.diff(f(Kind::Log, x), x), ctx.pow(x, c(-1)));
  EXPECT_EQ(ctx.diff(f(Kind::Tan, x), x), ctx.add(ctx.one(), sq(f(Kind::Tan, x))));
  EXPECT_EQ(ctx.diff(f(Kind::Tanh, x), x), ctx.sub(ctx.one(), sq(f(Kind::Tanh, x))));
  EXPECT_EQ(ctx.diff(f(Kind::Sinh, x), x), f(Kind::Cosh, x));
  EXPECT_EQ(ctx.diff(f(Kind::Cosh, x), x), f(Kind::Sinh, x));
  Expr root = ctx.pow(ctx.sub(ctx.one(), sq(x)), c(-0.5));
  EXPECT_EQ(ctx.diff(f(Kind::Asin, x), x), root);
  EXPECT_EQ(ctx.diff(f(Kind::Acos, x), x), ctx.neg(root));
  EXPECT_EQ(ctx.diff(f(Kind::Atan, x), x), ctx.pow(ctx.add(ctx.one(), sq(x)), c(-1)));
}

TEST_F(Diff, PiecewiseFunctions) {
  EXPECT_EQ(ctx.diff(f(Kind::Abs, x), x), f(Kind::Sign, x));
  EXPECT_EQ(ctx.diff(f(Kind::Abs, ctx.scale(3, x)), x), ctx.scale(3, f(Kind::Sign, ctx.scale(3, x))));
  EXPECT_EQ(ctx.diff(f(Kind::Sign, x), x), ctx.zero());
  EXPECT_EQ(ctx.diff(ctx.binary(Kind::Min, x, y), x),
            ctx.select(ctx.binary(Kind::Le, x, y), ctx.one(), ctx.zero()));
  EXPECT_EQ(ctx.diff(ctx.binary(Kind::Max, x, y), x),
            ctx.select(ctx.binary(Kind::Le, y, x), ctx.one(), ctx.zero()));
  Expr cond = ctx.binary(Kind::Lt, x, y);
  EXPECT_EQ(ctx.diff(ctx.select(cond, sq(x), y), x), ctx.select(cond, ctx.scale(2, x), ctx.zero()));
  for (Kind k : {Kind::Lt, Kind::Le, Kind::Eq, Kind::Ne, Kind::And, Kind::Or})
    EXPECT_EQ(ctx.diff(ctx.binary(k, x, y), x), ctx.zero()) << kindSpelling(k);
  EXPECT_EQ(ctx.diff(f(Kind::Not, x), x), ctx.zero());
}

TEST_F(Diff, Atan2) {
  Expr den = ctx.add(sq(x), sq(y));
  EXPECT_EQ(ctx.diff(ctx.binary(Kind::Atan2, y, x), x), ctx.neg(ctx.div(y, den)));
  EXPECT_EQ(ctx.diff(ctx.binary(Kind::Atan2, y, x), y), ctx.div(x, den));
}

TEST_F(Diff, MemoisedAndShared) {
  Expr e = f(Kind::Sin, ctx.mul(f(Kind::Exp, x), ctx.add(x, y)));
  Expr d1 = ctx.diff(e, x);
  size_t nodes = ctx.nodeCount();
  EXPECT_EQ(ctx.diff(e, x), d1);
  EXPECT_EQ(ctx.nodeCount(), nodes);
  Expr d2 = ctx.diff(d1, x);  // second derivative reuses first-derivative nodes
  EXPECT_NE(d2, ctx.zero());
  EXPECT_EQ(ctx.diff(e, ctx.symbol("unused")), ctx.zero());
}

// The kinds occurring in e (each counted once).
std::set<Kind> kindsOf(Expr e) {
  std::set<Kind> kinds;
  std::vector<Expr> stack{e};
  std::set<Expr> seen;
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    if (!seen.insert(n).second) continue;
    kinds.insert(n->kind);
    for (Expr a : n->args) stack.push_back(a);
    for (Expr x : n->exps()) stack.push_back(x);
  }
  return kinds;
}

// --- random expressions vs finite differences -------------------------------------------------------
//
// Reference: 5-point central difference of the independent tree evaluator,
//   fd(h) = (f(x-2h) - 8 f(x-h) + 8 f(x+h) - f(x+2h)) / (12 h),  h = 1e-3 * (1 + |x|),
// truncation error O(h^4 f^(5)) ~ 1e-13 f^(5), round-off ~ 1.5 eps M / h ~ 3e-13 M, where M bounds
// the magnitude of every intermediate value. The derivative must satisfy
//   |d - fd(h)| <= 1e-6 * (1 + |fd(h)|) + 1e-9 * M,
// which leaves a margin of > 1000 over both error terms while any wrong rule is off by O(|d|).
// Points are skipped (and counted) when a stencil point takes a different branch at an
// abs/sign/min/max/comparison/atan2 site (non-smooth), when a value is not finite, or when the
// difference quotient itself has not converged (|fd(h) - fd(h/2)| above the tolerance, which only
// happens where f has huge higher derivatives); at least 80% of the checks must be performed.
TEST(DiffRandom, AgreesWithFiniteDifferences) {
  const int kExpressions = 2500;
  TreeGen gen(12345);
  int checked = 0, skipped = 0, failures = 0;
  std::map<Kind, int> kindsChecked;  // coverage: every kind must occur in checked expressions
  size_t totalNodes = 0;
  for (int n = 0; n < kExpressions; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("x"), ctx.symbol("y"), ctx.symbol("z")};
    TreePtr tree = gen.gen(6);
    Expr e = toExpr(ctx, *tree, vars);
    std::vector<double> pt = {gen.point(), gen.point(), gen.point()};
    RefEval center = refEval(*tree, pt);
    for (int v = 0; v < 3; ++v) {
      double d = evaluate(ctx.diff(e, vars[v]), pt);
      double h = 1e-3 * (1 + std::fabs(pt[v]));
      bool smooth = std::isfinite(center.value) && std::fabs(center.value) < 1e8;
      double maxAbs = center.maxAbs;
      auto fd = [&](double step) {
        const double off[] = {-2, -1, 1, 2}, w[] = {1, -8, 8, -1};
        double acc = 0;
        for (int i = 0; i < 4; ++i) {
          std::vector<double> p = pt;
          p[v] += off[i] * step;
          RefEval r = refEval(*tree, p);
          smooth = smooth && std::isfinite(r.value) && r.branches == center.branches;
          maxAbs = std::max(maxAbs, r.maxAbs);
          acc += w[i] * r.value;
        }
        return acc / (12 * step);
      };
      double fd1 = fd(h), fd2 = fd(h / 2);
      double tol = 1e-6 * (1 + std::fabs(fd1)) + 1e-9 * maxAbs;
      if (!smooth || !std::isfinite(d) || std::fabs(fd1 - fd2) > tol) {
        ++skipped;
        continue;
      }
      ++checked;
      for (Kind k : kindsOf(e)) ++kindsChecked[k];
      totalNodes += ctx.dagSize(std::span<const Expr>(&e, 1));
      if (std::fabs(d - fd1) > tol && ++failures <= 10)
        ADD_FAILURE() << "d/d" << ctx.symbolName(vars[v]) << " of " << toString(ctx, e) << "\n  at ("
                      << pt[0] << ", " << pt[1] << ", " << pt[2] << "): symbolic " << d << ", fd " << fd1
                      << "\n  derivative: " << toString(ctx, ctx.diff(e, vars[v]));
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GE(checked, 0.8 * (checked + skipped)) << "skipped " << skipped;
  EXPECT_GE(checked, 6000);
  for (int k = 0; k <= static_cast<int>(Kind::Select); ++k)
    EXPECT_GE(kindsChecked[static_cast<Kind>(k)], 20) << kindSpelling(static_cast<Kind>(k));
  std::printf("[ info ] %d derivative checks, %d skipped, mean DAG size %.1f nodes\n", checked, skipped,
              double(totalNodes) / checked);
}

}  // namespace
