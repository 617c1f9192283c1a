// Canonical nodes are fixed points of the builders: MulBuilder over the one factor x gives x, and
// AddBuilder over the one term 1·x gives x unless x = k·(sum), which it distributes. The derivative
// rules skip the builders on these grounds (Derivative.cpp), so this is checked on every node of
// many random expressions.
#include <gtest/gtest.h>

#include <set>

#include "RandomTree.h"
#include "symbolic/ContextImpl.h"

namespace qdot::sym {
namespace {

bool isScaledSum(Expr x) {
  return x->kind == Kind::Mul && x->value != 1.0 && x->args.size() == 1 && x->exps()[0]->isOne() &&
         x->args[0]->kind == Kind::Add;
}

TEST(BuilderFixedPoint, EveryNodeOfRandomExpressions) {
  testing::TreeGen gen(77, 4);
  size_t checked = 0, scaledSums = 0;
  for (int n = 0; n < 1500; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("a"), ctx.symbol("b"), ctx.symbol("c"), ctx.symbol("d")};
    Expr root = testing::toExpr(ctx, *gen.gen(6), vars);
    std::vector<Expr> stack = {root};
    std::set<Expr> seen;
    while (!stack.empty()) {
      Expr x = stack.back();
      stack.pop_back();
      if (!seen.insert(x).second) continue;
      for (Expr c : children(x)) stack.push_back(c);
      MulBuilder product(ctx);
      product.factor(x);
      EXPECT_EQ(product.build(), x) << toString(ctx, x);
      AddBuilder sum(ctx);
      sum.add(1.0, x);
      if (isScaledSum(x)) {
        ++scaledSums;
      } else {
        EXPECT_EQ(sum.build(), x) << toString(ctx, x);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 10000u);
  EXPECT_GT(scaledSums, 0u);
}

}  // namespace
}  // namespace qdot::sym
