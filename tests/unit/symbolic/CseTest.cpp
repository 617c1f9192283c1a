// eliminateCommonSubexpressions on exact small cases, plus a check that the temporaries and the
// rewritten outputs evaluate to the original outputs.
#include <gtest/gtest.h>

#include <cmath>

#include "symbolic/Expr.h"

using namespace qdot::sym;

namespace {

class Cse : public ::testing::Test {
 protected:
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y");
  Expr c(double v) { return ctx.constant(v); }
  Expr sin(Expr e) { return ctx.unary(Kind::Sin, e); }
  Expr cos(Expr e) { return ctx.unary(Kind::Cos, e); }

  // Evaluates the temporaries in order, then the outputs; values of x and y given.
  std::vector<double> run(const CseResult& r, double xv, double yv) {
    std::vector<double> v(ctx.symbolCount(), 0.0);
    v[x->symbolId] = xv;
    v[y->symbolId] = yv;
    for (auto& [t, value] : r.temporaries) v[t->symbolId] = evaluate(value, v);
    std::vector<double> out;
    for (Expr o : r.outputs) out.push_back(evaluate(o, v));
    return out;
  }
};

TEST_F(Cse, SharedFunctionBecomesOneTemporary) {
  Expr outs[] = {ctx.mul(sin(x), y), ctx.add(sin(x), c(1))};
  CseResult r = eliminateCommonSubexpressions(ctx, outs);
  ASSERT_EQ(r.temporaries.size(), 1u);
  Expr t0 = r.temporaries[0].first;
  EXPECT_EQ(ctx.symbolName(t0), "_t0");
  EXPECT_EQ(r.temporaries[0].second, sin(x));
  ASSERT_EQ(r.outputs.size(), 2u);
  EXPECT_EQ(r.outputs[0], ctx.mul(t0, y));
  EXPECT_EQ(r.outputs[1], ctx.add(t0, c(1)));
}

TEST_F(Cse, NothingSharedNothingChanged) {
  Expr outs[] = {ctx.mul(sin(x), y), cos(x)};
  CseResult r = eliminateCommonSubexpressions(ctx, outs);
  EXPECT_TRUE(r.temporaries.empty());
  EXPECT_EQ(r.outputs[0], outs[0]);
  EXPECT_EQ(r.outputs[1], outs[1]);
  // leaves are never temporaries, however often they are used
  Expr leaves[] = {ctx.add(x, y), ctx.mul(x, y), ctx.sub(x, y)};
  EXPECT_TRUE(eliminateCommonSubexpressions(ctx, leaves).temporaries.empty());
}

TEST_F(Cse, NestedTemporariesInDependencyOrder) {
  Expr u = ctx.add(x, y);               // used by sin(u) and cos(u)
  Expr s = sin(u);                       // used by both outputs
  Expr outs[] = {ctx.mul(s, cos(u)), ctx.add(s, x)};
  CseResult r = eliminateCommonSubexpressions(ctx, outs, "tmp");
  ASSERT_EQ(r.temporaries.size(), 2u);
  Expr t0 = r.temporaries[0].first, t1 = r.temporaries[1].first;
  EXPECT_EQ(ctx.symbolName(t0), "tmp0");
  EXPECT_EQ(ctx.symbolName(t1), "tmp1");
  EXPECT_EQ(r.temporaries[0].second, u);
  EXPECT_EQ(r.temporaries[1].second, sin(t0));
  EXPECT_EQ(r.outputs[0], ctx.mul(t1, cos(t0)));
  EXPECT_EQ(r.outputs[1], ctx.add(t1, x));
  std::vector<double> got = run(r, 0.3, 0.9);
  EXPECT_DOUBLE_EQ(got[0], std::sin(1.2) * std::cos(1.2));
  EXPECT_DOUBLE_EQ(got[1], std::sin(1.2) + 0.3);
}

TEST_F(Cse, RepeatedOutputAndUseWithinOneParent) {
  Expr u = ctx.mul(x, y);
  Expr outs[] = {ctx.binary(Kind::Atan2, u, ctx.add(u, c(1))), sin(x), sin(x)};
  CseResult r = eliminateCommonSubexpressions(ctx, outs);
  // u is used by atan2 and by u + 1; sin(x) is two outputs
  ASSERT_EQ(r.temporaries.size(), 2u);
  EXPECT_EQ(r.temporaries[0].second, u);
  EXPECT_EQ(r.temporaries[1].second, sin(x));
  EXPECT_EQ(r.outputs[1], r.temporaries[1].first);
  EXPECT_EQ(r.outputs[2], r.temporaries[1].first);
  std::vector<double> got = run(r, 0.5, 2.0);
  EXPECT_DOUBLE_EQ(got[0], std::atan2(1.0, 2.0));
  EXPECT_DOUBLE_EQ(got[1], std::sin(0.5));
}

TEST_F(Cse, TemporaryNamesAvoidSymbolsOfTheOutputs) {
  Expr t0 = ctx.symbol("_t0");  // e.g. from an earlier CSE run
  Expr outs[] = {ctx.mul(sin(x), t0), ctx.add(sin(x), t0)};
  CseResult r = eliminateCommonSubexpressions(ctx, outs);
  ASSERT_EQ(r.temporaries.size(), 1u);
  EXPECT_EQ(ctx.symbolName(r.temporaries[0].first), "_t1");
  EXPECT_EQ(r.outputs[0], ctx.mul(r.temporaries[0].first, t0));
}

}  // namespace
