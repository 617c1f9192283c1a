// evaluate / Evaluator: IEEE semantics of every kind, booleans as 1/0, sign(0) = 0, selects, shared
// roots, and the reusable tape.
#include <gtest/gtest.h>

#include <cmath>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

class Eval : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y");
  Expr c(double v) { return ctx.constant(v); }
  double at(Expr e, double xv, double yv = 0) { return evaluate(e, std::vector<double>{xv, yv}); }
};

TEST_F(Eval, Arithmetic) {
  Expr e = ctx.add(ctx.mul(ctx.scale(3, x), ctx.pow(y, c(2))), c(1));  // 3*x*y^2 + 1
  EXPECT_DOUBLE_EQ(at(e, 2, 3), 55);
  EXPECT_DOUBLE_EQ(at(ctx.div(x, y), 1, 4), 0.25);
  EXPECT_DOUBLE_EQ(at(ctx.pow(x, y), 2, 0.5), std::sqrt(2.0));
  EXPECT_DOUBLE_EQ(at(ctx.pow(x, c(-1.5)), 4, 0), 0.125);
  EXPECT_DOUBLE_EQ(at(ctx.sub(x, y), 1, 4), -3);
}

TEST_F(Eval, IeeeSemantics) {
  EXPECT_TRUE(std::isnan(at(ctx.pow(x, c(0.5)), -1)));
  EXPECT_EQ(at(ctx.unary(Kind::Log, x), 0), -INFINITY);
  EXPECT_EQ(at(ctx.div(ctx.one(), x), 0), INFINITY);
  EXPECT_TRUE(std::isnan(at(ctx.unary(Kind::Asin, x), 2)));
}

TEST_F(Eval, Functions) {
  struct Case { Kind k; double arg, expected; };
  const Case cases[] = {
      {Kind::Sin, 0.3, std::sin(0.3)},   {Kind::Cos, 0.3, std::cos(0.3)},   {Kind::Tan, 0.3, std::tan(0.3)},
      {Kind::Asin, 0.3, std::asin(0.3)}, {Kind::Acos, 0.3, std::acos(0.3)}, {Kind::Atan, 0.3, std::atan(0.3)},
      {Kind::Sinh, 0.3, std::sinh(0.3)}, {Kind::Cosh, 0.3, std::cosh(0.3)}, {Kind::Tanh, 0.3, std::tanh(0.3)},
      {Kind::Exp, 0.3, std::exp(0.3)},   {Kind::Log, 0.3, std::log(0.3)},   {Kind::Abs, -0.3, 0.3},
      {Kind::Sign, -0.3, -1},            {Kind::Sign, 0.0, 0},              {Kind::Sign, 2.0, 1},
      {Kind::Not, 0.0, 1},               {Kind::Not, 2.0, 0}};
  for (const Case& k : cases) EXPECT_EQ(at(ctx.unary(k.k, x), k.arg), k.expected) << kindSpelling(k.k);
}

TEST_F(Eval, BinaryLogicAndSelect) {
  EXPECT_DOUBLE_EQ(at(ctx.binary(Kind::Atan2, y, x), -1, 0.5), std::atan2(0.5, -1));
  EXPECT_EQ(at(ctx.binary(Kind::Min, x, y), 3, -2), -2);
  EXPECT_EQ(at(ctx.binary(Kind::Max, x, y), 3, -2), 3);
  EXPECT_EQ(at(ctx.binary(Kind::Lt, x, y), 1, 2), 1);
  EXPECT_EQ(at(ctx.binary(Kind::Lt, x, y), 2, 2), 0);
  EXPECT_EQ(at(ctx.binary(Kind::Le, x, y), 2, 2), 1);
  EXPECT_EQ(at(ctx.binary(Kind::Eq, x, y), 2, 2), 1);
  EXPECT_EQ(at(ctx.binary(Kind::Ne, x, y), 2, 2), 0);
  EXPECT_EQ(at(ctx.binary(Kind::And, x, y), 1, 0), 0);
  EXPECT_EQ(at(ctx.binary(Kind::And, x, y), 1, -3), 1);
  EXPECT_EQ(at(ctx.binary(Kind::Or, x, y), 0, 0), 0);
  EXPECT_EQ(at(ctx.binary(Kind::Or, x, y), 0, 5), 1);
  Expr sel = ctx.select(ctx.binary(Kind::Lt, x, y), ctx.unary(Kind::Log, x), y);
  EXPECT_EQ(at(sel, 1, 2), 0);
  EXPECT_EQ(at(sel, -1, -2), -2);  // the untaken branch log(-1) = NaN does not leak
}

TEST_F(Eval, ManyRootsAndReusableTape) {
  Expr s = ctx.unary(Kind::Sin, ctx.mul(x, y));
  Expr roots[] = {ctx.add(s, x), ctx.mul(s, s), c(7), x};
  std::vector<double> out(4);
  evaluate(roots, std::vector<double>{0.5, 2}, out);
  EXPECT_DOUBLE_EQ(out[0], std::sin(1.0) + 0.5);
  EXPECT_DOUBLE_EQ(out[1], std::sin(1.0) * std::sin(1.0));
  EXPECT_EQ(out[2], 7);
  EXPECT_EQ(out[3], 0.5);

  Evaluator ev(roots);
  EXPECT_EQ(ev.tapeSize(), ctx.dagSize(roots));
  for (double xv : {0.1, 0.2, 0.3}) {
    ev.run(std::vector<double>{xv, 3}, out);
    EXPECT_DOUBLE_EQ(out[0], std::sin(3 * xv) + xv);
    EXPECT_DOUBLE_EQ(out[1], std::pow(std::sin(3 * xv), 2));
  }
  EXPECT_THROW(ev.run(std::vector<double>{1.0}, out), std::invalid_argument);
}

}  // namespace
