// toString golden strings: minimal parentheses, signs of terms, division and sqrt forms, number
// formatting and the deterministic (symbol-creation) order of terms and factors.
#include <gtest/gtest.h>

#include <cmath>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

class Print : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), z = ctx.symbol("z");
  Expr c(double v) { return ctx.constant(v); }
  Expr f(Kind k, Expr a) { return ctx.unary(k, a); }
  Expr b(Kind k, Expr a, Expr e) { return ctx.binary(k, a, e); }
  std::string str(Expr e) { return toString(ctx, e); }
};

TEST_F(Print, Numbers) {
  EXPECT_EQ(str(c(2)), "2");
  EXPECT_EQ(str(c(-2.5)), "-2.5");
  EXPECT_EQ(str(c(0.1)), "0.1");
  EXPECT_EQ(str(c(1e-20)), "1e-20");
  EXPECT_EQ(str(c(1.0 / 3.0)), "0.3333333333333333");
  EXPECT_EQ(str(c(INFINITY)), "inf");
}

TEST_F(Print, SumsAndProducts) {
  EXPECT_EQ(str(ctx.add(y, x)), "x + y");
  EXPECT_EQ(str(ctx.sub(x, y)), "x - y");
  EXPECT_EQ(str(ctx.sub(ctx.one(), x)), "-x + 1");
  EXPECT_EQ(str(ctx.add(ctx.scale(2, x), c(-3))), "2*x - 3");
  EXPECT_EQ(str(ctx.neg(ctx.mul(x, y))), "-x*y");
  EXPECT_EQ(str(ctx.sub(z, ctx.scale(2.5, ctx.mul(x, y)))), "z - 2.5*x*y");
  EXPECT_EQ(str(ctx.mul(ctx.add(x, y), z)), "z*(x + y)");
  EXPECT_EQ(str(ctx.neg(ctx.add(x, y))), "-(x + y)");
  EXPECT_EQ(str(ctx.scale(3, ctx.add(x, c(1)))), "3*(x + 1)");
}

TEST_F(Print, PowersAndDivision) {
  EXPECT_EQ(str(ctx.pow(x, c(2))), "x^2");
  EXPECT_EQ(str(ctx.mul(ctx.pow(x, c(2)), y)), "x^2*y");
  EXPECT_EQ(str(ctx.div(x, y)), "x/y");
  EXPECT_EQ(str(ctx.div(x, ctx.mul(y, z))), "x/(y*z)");
  EXPECT_EQ(str(ctx.div(ctx.one(), x)), "1/x");
  EXPECT_EQ(str(ctx.div(c(2), ctx.pow(x, c(2)))), "2/x^2");
  EXPECT_EQ(str(ctx.div(x, ctx.add(y, z))), "x/(y + z)");
  EXPECT_EQ(str(ctx.neg(ctx.div(x, y))), "-x/y");
  EXPECT_EQ(str(ctx.pow(x, c(0.5))), "sqrt(x)");
  EXPECT_EQ(str(ctx.pow(ctx.add(x, y), c(0.5))), "sqrt(x + y)");
  EXPECT_EQ(str(ctx.div(x, ctx.pow(y, c(0.5)))), "x/sqrt(y)");
  EXPECT_EQ(str(ctx.pow(ctx.add(x, y), c(3))), "(x + y)^3");
  EXPECT_EQ(str(ctx.pow(x, y)), "x^y");
  EXPECT_EQ(str(ctx.pow(x, ctx.add(y, c(1)))), "x^(y + 1)");
  EXPECT_EQ(str(ctx.pow(x, ctx.neg(y))), "x^(-y)");
  EXPECT_EQ(str(ctx.pow(c(2), x)), "2^x");
  EXPECT_EQ(str(ctx.pow(c(-2), x)), "(-2)^x");
  EXPECT_EQ(str(ctx.pow(f(Kind::Sin, x), c(2))), "sin(x)^2");
}

TEST_F(Print, FunctionsAndLogic) {
  EXPECT_EQ(str(f(Kind::Sin, ctx.add(x, c(1)))), "sin(x + 1)");
  EXPECT_EQ(str(b(Kind::Atan2, y, x)), "atan2(y, x)");
  EXPECT_EQ(str(b(Kind::Max, y, x)), "max(x, y)");
  EXPECT_EQ(str(f(Kind::Abs, ctx.neg(x))), "abs(-x)");
  EXPECT_EQ(str(b(Kind::Lt, ctx.add(x, y), z)), "x + y < z");
  EXPECT_EQ(str(b(Kind::Le, z, x)), "z <= x");
  EXPECT_EQ(str(b(Kind::Ne, x, y)), "x <> y");
  EXPECT_EQ(str(b(Kind::And, b(Kind::Lt, x, y), b(Kind::Eq, y, z))), "x < y and y == z");
  EXPECT_EQ(str(f(Kind::Not, b(Kind::Or, x, y))), "not (x or y)");
  EXPECT_EQ(str(b(Kind::Or, b(Kind::And, x, y), z)), "z or x and y");
  EXPECT_EQ(str(ctx.select(b(Kind::Lt, x, y), x, ctx.neg(y))), "if x < y then x else -y");
  Expr sel = ctx.select(b(Kind::Lt, x, c(0)), ctx.neg(x), x);
  EXPECT_EQ(str(ctx.add(sel, y)), "y + (if x < 0 then -x else x)");
  EXPECT_EQ(str(ctx.mul(b(Kind::Lt, x, y), z)), "z*(x < y)");
}

TEST_F(Print, MechanicsStyle) {
  Expr m = ctx.symbol("m"), l = ctx.symbol("l"), g = ctx.symbol("g"), th = ctx.symbol("th");
  Expr der = ctx.symbol("der(th)");
  // factors in symbol-creation order; the shallower product first
  Expr kin = ctx.scale(0.5, ctx.mul(std::vector<Expr>{m, ctx.pow(l, c(2)), ctx.pow(der, c(2))}));
  Expr pot = ctx.mul(std::vector<Expr>{m, g, l, f(Kind::Cos, th)});
  EXPECT_EQ(str(ctx.add(kin, pot)), "0.5*m*l^2*der(th)^2 + m*l*g*cos(th)");
  EXPECT_EQ(str(ctx.sub(kin, pot)), "0.5*m*l^2*der(th)^2 - m*l*g*cos(th)");
  EXPECT_EQ(str(ctx.diff(ctx.sub(kin, pot), th)), "m*l*g*sin(th)");
  EXPECT_EQ(str(ctx.diff(kin, der)), "m*l^2*der(th)");
}

}  // namespace

namespace {

// toStringGrouped: the terms of the top-level sum (or of the one sum factor of a product) by group.
TEST(PrintGrouped, OrdersTheTermsOfTheOuterSumByGroup) {
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), z = ctx.symbol("z"), m = ctx.symbol("m");
  Expr sum = ctx.add(std::vector<Expr>{x, ctx.scale(-2, y), z});
  auto zFirst = [&](Expr t) { return t == z ? 0 : t == y ? 1 : 2; };
  EXPECT_EQ(toString(ctx, sum), "x - 2*y + z");
  EXPECT_EQ(toStringGrouped(ctx, sum, zFirst), "z - 2*y + x");
  EXPECT_EQ(toStringGrouped(ctx, ctx.mul(m, sum), zFirst), "m*(z - 2*y + x)");
  EXPECT_EQ(toStringGrouped(ctx, ctx.neg(sum), zFirst), "-(z - 2*y + x)");
  // not a sum: as toString
  EXPECT_EQ(toStringGrouped(ctx, ctx.mul(m, x), zFirst), toString(ctx, ctx.mul(m, x)));
}

}  // namespace
