// Hash-consing and canonical simplification (Expr.h): structurally equal expressions are the same
// pointer, and the documented rewrites (constant folding, neutral/absorbing elements, like terms,
// power collection, no expansion / distribution) hold exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

class Canonical : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), z = ctx.symbol("z");
  Expr c(double v) { return ctx.constant(v); }
  Expr sq(Expr e) { return ctx.pow(e, c(2)); }
};

TEST_F(Canonical, LeavesAreInterned) {
  EXPECT_EQ(ctx.constant(2.5), ctx.constant(2.5));
  EXPECT_EQ(ctx.constant(0.0), ctx.zero());
  EXPECT_EQ(ctx.constant(-0.0), ctx.zero());
  EXPECT_EQ(ctx.constant(1.0), ctx.one());
  EXPECT_EQ(ctx.constant(NAN), ctx.constant(-NAN));
  EXPECT_EQ(ctx.symbol("x"), x);
  EXPECT_EQ(ctx.findSymbol("y"), y);
  EXPECT_EQ(ctx.findSymbol("nope"), nullptr);
  EXPECT_EQ(ctx.symbolName(z), "z");
  EXPECT_EQ(ctx.symbolCount(), 3u);
  EXPECT_EQ(x->symbolId, 0u);
  EXPECT_EQ(z->symbolId, 2u);
  EXPECT_NE(x->symbolMask, 0u);
  EXPECT_EQ(c(3)->symbolMask, 0u);
}

TEST_F(Canonical, AddIsCommutativeAndAssociative) {
  EXPECT_EQ(ctx.add(x, y), ctx.add(y, x));
  EXPECT_EQ(ctx.add(ctx.add(x, y), z), ctx.add(x, ctx.add(y, z)));
  Expr terms[] = {z, x, c(1), y};
  Expr terms2[] = {y, c(1), z, x};
  EXPECT_EQ(ctx.add(terms), ctx.add(terms2));
  Expr s = ctx.add(terms);
  EXPECT_EQ(s->kind, Kind::Add);
  EXPECT_EQ(s->value, 1.0);
  ASSERT_EQ(s->args.size(), 3u);
  EXPECT_EQ(s->args[0], x);  // symbols sort in creation order
  EXPECT_EQ(s->args[2], z);
}

TEST_F(Canonical, LikeTermsAreCollected) {
  EXPECT_EQ(ctx.sub(x, x), ctx.zero());
  EXPECT_EQ(ctx.add(ctx.scale(2, x), ctx.scale(3, x)), ctx.scale(5, x));
  EXPECT_EQ(ctx.add(x, x), ctx.scale(2, x));
  Expr xy = ctx.mul(x, y);
  EXPECT_EQ(ctx.add(ctx.scale(2, xy), ctx.mul(y, x)), ctx.scale(3, xy));
  EXPECT_EQ(ctx.sub(ctx.add(x, y), y), x);
  Expr s = ctx.add(x, y);
  EXPECT_EQ(ctx.sub(s, s), ctx.zero());
  EXPECT_EQ(ctx.add(s, ctx.neg(s)), ctx.zero());
  // the coefficient of a term moves into the Add
  Expr t = ctx.add(ctx.scale(3, xy), z);
  ASSERT_EQ(t->kind, Kind::Add);
  ASSERT_EQ(t->args.size(), 2u);
  EXPECT_EQ(t->args[0], z);
  EXPECT_EQ(t->args[1], xy);
  EXPECT_EQ(t->coefs()[1], 3.0);
}

TEST_F(Canonical, ConstantFolding) {
  EXPECT_EQ(ctx.add(c(2), c(3)), c(5));
  EXPECT_EQ(ctx.mul(c(2), c(3)), c(6));
  EXPECT_EQ(ctx.div(c(1), c(4)), c(0.25));
  EXPECT_EQ(ctx.pow(c(2), c(10)), c(1024));
  EXPECT_EQ(ctx.pow(c(4), c(0.5)), c(2));
  EXPECT_EQ(ctx.unary(Kind::Sin, ctx.zero()), ctx.zero());
  EXPECT_EQ(ctx.unary(Kind::Exp, ctx.zero()), ctx.one());
  EXPECT_EQ(ctx.unary(Kind::Cos, ctx.zero()), ctx.one());
  EXPECT_EQ(ctx.unary(Kind::Log, ctx.one()), ctx.zero());
  EXPECT_EQ(ctx.unary(Kind::Abs, c(-3)), c(3));
  EXPECT_EQ(ctx.unary(Kind::Sign, c(-3)), c(-1));
  EXPECT_EQ(ctx.unary(Kind::Sign, ctx.zero()), ctx.zero());
  EXPECT_EQ(ctx.binary(Kind::Max, c(2), c(7)), c(7));
  EXPECT_EQ(ctx.binary(Kind::Lt, c(2), c(7)), ctx.one());
  EXPECT_EQ(ctx.binary(Kind::Atan2, c(0), c(1)), ctx.zero());
  EXPECT_EQ(ctx.unary(Kind::Not, c(0)), ctx.one());
  EXPECT_TRUE(std::isnan(ctx.unary(Kind::Log, c(-1))->value));
  EXPECT_EQ(ctx.unary(Kind::Log, ctx.zero())->value, -INFINITY);
  EXPECT_EQ(ctx.add(ctx.add(x, c(2)), c(3)), ctx.add(x, c(5)));
  EXPECT_EQ(ctx.mul(ctx.mul(c(2), x), c(3)), ctx.scale(6, x));
}

TEST_F(Canonical, NeutralAndAbsorbingElements) {
  EXPECT_EQ(ctx.add(x, ctx.zero()), x);
  EXPECT_EQ(ctx.sub(x, ctx.zero()), x);
  EXPECT_EQ(ctx.mul(x, ctx.one()), x);
  EXPECT_EQ(ctx.mul(x, ctx.zero()), ctx.zero());
  EXPECT_EQ(ctx.scale(0, ctx.add(x, y)), ctx.zero());
  EXPECT_EQ(ctx.div(x, ctx.one()), x);
  EXPECT_EQ(ctx.pow(x, ctx.one()), x);
  EXPECT_EQ(ctx.pow(x, ctx.zero()), ctx.one());
  EXPECT_EQ(ctx.pow(ctx.one(), y), ctx.one());
  EXPECT_EQ(ctx.neg(ctx.neg(x)), x);
  EXPECT_EQ(ctx.binary(Kind::And, x, ctx.zero()), ctx.zero());
  EXPECT_EQ(ctx.binary(Kind::Or, c(2), x), ctx.one());
  EXPECT_EQ(ctx.select(ctx.one(), x, y), x);
  EXPECT_EQ(ctx.select(ctx.zero(), x, y), y);
  EXPECT_EQ(ctx.select(ctx.binary(Kind::Lt, x, y), z, z), z);
  EXPECT_EQ(ctx.binary(Kind::Min, x, x), x);
  EXPECT_EQ(ctx.binary(Kind::Lt, x, x), ctx.zero());
  EXPECT_EQ(ctx.binary(Kind::Le, x, x), ctx.one());
}

TEST_F(Canonical, PowersOfEqualBasesAreCollected) {
  EXPECT_EQ(ctx.mul(ctx.mul(x, y), x), ctx.mul(sq(x), y));
  EXPECT_EQ(ctx.mul(x, y), ctx.mul(y, x));
  EXPECT_EQ(ctx.mul(x, x), sq(x));
  EXPECT_EQ(ctx.div(x, x), ctx.one());
  EXPECT_EQ(ctx.div(ctx.mul(x, y), ctx.mul(y, x)), ctx.one());
  EXPECT_EQ(ctx.div(ctx.scale(6, ctx.mul(x, y)), ctx.scale(3, x)), ctx.scale(2, y));
  EXPECT_EQ(ctx.mul(ctx.pow(x, c(0.5)), ctx.pow(x, c(0.5))), x);
  EXPECT_EQ(ctx.mul(ctx.pow(x, y), x), ctx.pow(x, ctx.add(y, ctx.one())));
  EXPECT_EQ(ctx.pow(ctx.pow(x, c(3)), c(2)), ctx.pow(x, c(6)));
  EXPECT_EQ(ctx.pow(ctx.pow(x, y), c(2)), ctx.pow(x, ctx.scale(2, y)));
  EXPECT_EQ(ctx.pow(ctx.mul(x, y), c(2)), ctx.mul(sq(x), sq(y)));
  EXPECT_EQ(ctx.pow(ctx.scale(2, x), c(-1)), ctx.scale(0.5, ctx.pow(x, c(-1))));
  Expr e2x = ctx.pow(c(2), x);
  EXPECT_EQ(ctx.mul(e2x, e2x), ctx.pow(e2x, c(2)));
  EXPECT_EQ(ctx.mul(e2x, e2x), ctx.pow(c(2), ctx.scale(2, x)));
  Expr m = ctx.mul(std::vector<Expr>{sq(x), y, ctx.pow(z, c(-1))});
  ASSERT_EQ(m->kind, Kind::Mul);
  EXPECT_EQ(m->value, 1.0);
  ASSERT_EQ(m->args.size(), 3u);
  EXPECT_EQ(m->args[0], x);
  EXPECT_EQ(m->exps()[0], c(2));
  EXPECT_EQ(m->exps()[2], c(-1));
}

TEST_F(Canonical, NonIntegerPowerOfPowerIsKept) {
  Expr r = ctx.pow(sq(x), c(0.5));  // |x|, not x
  ASSERT_EQ(r->kind, Kind::Pow);
  EXPECT_EQ(r->args[0], sq(x));
  EXPECT_EQ(ctx.mul(r, r), sq(x));  // sqrt(x^2)^2 = x^2
  EXPECT_EQ(ctx.pow(r, c(2)), sq(x));
}

TEST_F(Canonical, NoExpansionNoDistribution) {
  Expr s = ctx.add(x, y);
  Expr p = ctx.mul(s, ctx.add(x, z));
  ASSERT_EQ(p->kind, Kind::Mul);
  EXPECT_EQ(p->args.size(), 2u);
  Expr d = ctx.scale(2, s);
  ASSERT_EQ(d->kind, Kind::Mul);
  EXPECT_EQ(d->value, 2.0);
  ASSERT_EQ(d->args.size(), 1u);
  EXPECT_EQ(d->args[0], s);
  EXPECT_EQ(ctx.mul(s, s), ctx.pow(s, c(2)));
  // inside a sum, a coefficient times a sum is flattened (nested sums never survive)
  Expr flat = ctx.add(d, z);
  ASSERT_EQ(flat->kind, Kind::Add);
  EXPECT_EQ(flat->args.size(), 3u);
  EXPECT_EQ(flat->coefs()[0], 2.0);
}

TEST_F(Canonical, CommutativeFunctionsAreOrdered) {
  EXPECT_EQ(ctx.binary(Kind::Min, x, y), ctx.binary(Kind::Min, y, x));
  EXPECT_EQ(ctx.binary(Kind::Eq, x, y), ctx.binary(Kind::Eq, y, x));
  EXPECT_EQ(ctx.binary(Kind::And, x, y), ctx.binary(Kind::And, y, x));
  EXPECT_NE(ctx.binary(Kind::Lt, x, y), ctx.binary(Kind::Lt, y, x));
  EXPECT_NE(ctx.binary(Kind::Atan2, x, y), ctx.binary(Kind::Atan2, y, x));
}

TEST_F(Canonical, FunctionsAreInterned) {
  EXPECT_EQ(ctx.unary(Kind::Sin, ctx.add(x, y)), ctx.unary(Kind::Sin, ctx.add(y, x)));
  EXPECT_NE(ctx.unary(Kind::Sin, x), ctx.unary(Kind::Cos, x));
  size_t before = ctx.nodeCount();
  ctx.unary(Kind::Sin, ctx.add(x, y));
  EXPECT_EQ(ctx.nodeCount(), before);
  EXPECT_THROW(ctx.unary(Kind::Atan2, x), std::invalid_argument);
  EXPECT_THROW(ctx.binary(Kind::Sin, x, y), std::invalid_argument);
}

TEST_F(Canonical, NodeFields) {
  Expr e = ctx.unary(Kind::Sin, ctx.mul(x, ctx.add(y, c(1))));
  EXPECT_EQ(e->depth, 3u);
  EXPECT_EQ(e->symbolMask, x->symbolMask | y->symbolMask);
  EXPECT_EQ(c(4)->depth, 0u);
  EXPECT_STREQ(kindSpelling(Kind::Sin), "sin");
  EXPECT_STREQ(kindSpelling(Kind::Ne), "<>");
}

TEST_F(Canonical, StructuralOrder) {
  EXPECT_LT(structuralCompare(x, y), 0);
  EXPECT_GT(structuralCompare(z, y), 0);
  EXPECT_EQ(structuralCompare(x, x), 0);
  EXPECT_LT(structuralCompare(c(5), x), 0);  // constants before symbols
  Expr sx = ctx.unary(Kind::Sin, x), sy = ctx.unary(Kind::Sin, y);
  EXPECT_LT(structuralCompare(sx, sy), 0);
  EXPECT_GT(structuralCompare(sy, sx), 0);
  EXPECT_LT(structuralCompare(x, sx), 0);
}

}  // namespace
