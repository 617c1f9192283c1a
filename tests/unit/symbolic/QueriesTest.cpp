// substitute, freeSymbols, dependsOn and dagSize on small exact cases.
#include <gtest/gtest.h>

#include <string>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

class Queries : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), z = ctx.symbol("z");
  Expr c(double v) { return ctx.constant(v); }
  Expr sin(Expr e) { return ctx.unary(Kind::Sin, e); }
};

TEST_F(Queries, SubstituteReplacesAllAtOnceAndResimplifies) {
  Expr e = ctx.add(ctx.mul(x, y), sin(x));  // x*y + sin(x)
  EXPECT_EQ(ctx.substitute(e, {{x, c(0)}}), ctx.zero());
  EXPECT_EQ(ctx.substitute(e, {{x, y}}), ctx.add(ctx.pow(y, c(2)), sin(y)));
  // simultaneous: x -> y and y -> x swaps, not chains
  EXPECT_EQ(ctx.substitute(ctx.sub(x, ctx.scale(2, y)), {{x, y}, {y, x}}), ctx.sub(y, ctx.scale(2, x)));
  // like terms created by the substitution are collected
  EXPECT_EQ(ctx.substitute(ctx.add(x, y), {{y, x}}), ctx.scale(2, x));
  EXPECT_EQ(ctx.substitute(ctx.div(x, y), {{y, x}}), ctx.one());
  // untouched expressions come back as the same node
  EXPECT_EQ(ctx.substitute(e, {{z, c(3)}}), e);
  EXPECT_EQ(ctx.substitute(e, {}), e);
  // functions fold when their argument becomes constant
  EXPECT_EQ(ctx.substitute(ctx.unary(Kind::Cos, ctx.mul(x, y)), {{y, c(0)}}), ctx.one());
  Expr sel = ctx.select(ctx.binary(Kind::Lt, x, y), x, y);
  EXPECT_EQ(ctx.substitute(sel, {{x, c(1)}, {y, c(2)}}), c(1));
}

TEST_F(Queries, SubstituteNonSymbolKeyAndSharedNodes) {
  Expr s = sin(x);
  Expr e = ctx.add(ctx.mul(s, y), ctx.pow(s, c(2)));  // sin(x)*y + sin(x)^2
  EXPECT_EQ(ctx.substitute(e, {{s, z}}), ctx.add(ctx.mul(y, z), ctx.pow(z, c(2))));
  size_t before = ctx.nodeCount();
  Expr again = ctx.substitute(e, {{s, z}});
  EXPECT_EQ(again, ctx.add(ctx.mul(y, z), ctx.pow(z, c(2))));
  EXPECT_EQ(ctx.nodeCount(), before);  // everything already exists
}

TEST_F(Queries, FreeSymbolsInFirstOccurrenceOrder) {
  // z*sin(y) + x: Add terms are ordered x first (symbols before products), then y inside sin
  Expr e = ctx.add(ctx.mul(z, sin(y)), x);
  EXPECT_EQ(ctx.freeSymbols(e), (std::vector<Expr>{x, z, y}));
  EXPECT_EQ(ctx.freeSymbols(c(2)), std::vector<Expr>{});
  EXPECT_EQ(ctx.freeSymbols(ctx.pow(y, x)), (std::vector<Expr>{y, x}));
  Expr shared = ctx.add(sin(ctx.mul(x, y)), ctx.unary(Kind::Cos, ctx.mul(x, y)));
  EXPECT_EQ(ctx.freeSymbols(shared), (std::vector<Expr>{x, y}));
}

TEST_F(Queries, DependsOn) {
  Expr e = ctx.add(ctx.mul(z, sin(y)), c(1));
  EXPECT_TRUE(ctx.dependsOn(e, y));
  EXPECT_TRUE(ctx.dependsOn(e, z));
  EXPECT_FALSE(ctx.dependsOn(e, x));
  EXPECT_FALSE(ctx.dependsOn(c(3), x));
  // a symbol with the same mask bit as y (id 1 + 64) must still be answered exactly
  Expr alias = nullptr;
  for (size_t i = 0; !alias || alias->symbolId % 64 != 1; ++i) alias = ctx.symbol(std::string(1, 'a').append(std::to_string(i)));
  ASSERT_EQ(alias->symbolMask, y->symbolMask);
  EXPECT_FALSE(ctx.dependsOn(e, alias));
  EXPECT_TRUE(ctx.dependsOn(ctx.mul(e, alias), alias));
  EXPECT_TRUE(ctx.dependsOn(ctx.mul(e, alias), y));
}

TEST_F(Queries, DagSizeCountsDistinctNodes) {
  Expr xy = ctx.mul(x, y);  // Mul(x, y; exps 1, 1): x, y, 1, Mul
  Expr roots[] = {xy};
  EXPECT_EQ(ctx.dagSize(roots), 4u);
  Expr e = ctx.add(sin(xy), ctx.unary(Kind::Cos, xy));  // + sin, cos, Add
  Expr both[] = {e, xy};
  EXPECT_EQ(ctx.dagSize(both), 7u);
  Expr none[] = {c(5)};
  EXPECT_EQ(ctx.dagSize(none), 1u);
  EXPECT_EQ(ctx.dagSize({}), 0u);
}

}  // namespace
