// Derivative rules in numerically safe forms: near and past the overflow edge of exp/cosh/sinh
// (|u| ≈ 710) the derivatives stay finite and equal their limits, where u'/u would give inf/inf.
#include <gtest/gtest.h>

#include <cmath>

#include "symbolic/Expr.h"
#include "symbolic/Simplify.h"

using namespace qdot::sym;

namespace {

class SafeDerivative : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x");
  Expr f(Kind k, Expr a) { return ctx.unary(k, a); }
  double at(Expr e, double v) {
    std::vector<double> values(ctx.symbolCount(), 0.0);
    values[x->symbolId] = v;
    return evaluate(e, values);
  }
};

TEST_F(SafeDerivative, LogCoshIsTanh) {
  Expr eps = ctx.constant(1e-3);
  Expr d = ctx.diff(f(Kind::Log, f(Kind::Cosh, ctx.div(x, eps))), x);  // (1/eps) tanh(x/eps)
  EXPECT_EQ(toString(ctx, d), "1000*tanh(1000*x)");
  EXPECT_DOUBLE_EQ(at(d, 0.709), 1000 * std::tanh(709.0));  // below the edge
  EXPECT_DOUBLE_EQ(at(d, 1.0), 1000.0);                      // cosh(1000) = inf: still finite
  EXPECT_DOUBLE_EQ(at(d, -1.0), -1000.0);
}

TEST_F(SafeDerivative, LogSinhIsOneOverTanh) {
  Expr d = ctx.diff(f(Kind::Log, f(Kind::Sinh, x)), x);
  EXPECT_DOUBLE_EQ(at(d, 1.0), 1.0 / std::tanh(1.0));
  EXPECT_DOUBLE_EQ(at(d, 800.0), 1.0);
}

TEST_F(SafeDerivative, SoftplusStaysFinite) {
  Expr d = ctx.diff(f(Kind::Log, ctx.add(ctx.one(), f(Kind::Exp, x))), x);  // 1/(exp(−x) + 1)
  EXPECT_DOUBLE_EQ(at(d, 800.0), 1.0);
  EXPECT_EQ(at(d, -800.0), 0.0);
  EXPECT_NEAR(at(d, 0.3), std::exp(0.3) / (1 + std::exp(0.3)), 1e-15);
}

TEST_F(SafeDerivative, LogOfExpAndOfOnePlusU) {
  EXPECT_EQ(ctx.diff(f(Kind::Log, f(Kind::Exp, ctx.scale(3, x))), x), ctx.constant(3));
  Expr d = ctx.diff(f(Kind::Log, ctx.add(ctx.one(), x)), x);
  EXPECT_EQ(toString(ctx, d), "1/(x + 1)");
  EXPECT_DOUBLE_EQ(at(d, 1e300), 1e-300);
}

TEST_F(SafeDerivative, SimplifiedInversePairsAvoidOverflow) {
  // exp(log(u)) = u and sqrt(u²) = |u|: the originals overflow for u = 1e200 (u² = inf).
  Expr big = ctx.pow(ctx.pow(x, ctx.constant(2)), ctx.constant(0.5));
  EXPECT_TRUE(std::isinf(at(big, 1e200)));
  EXPECT_DOUBLE_EQ(at(simplify(ctx, big), 1e200), 1e200);
  EXPECT_DOUBLE_EQ(at(simplify(ctx, big), -1e200), 1e200);
}

}  // namespace
