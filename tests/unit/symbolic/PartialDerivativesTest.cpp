// PartialDerivatives gives the very nodes Context::diff gives (the kernel's --emit=kernel output must
// not depend on which one built the Jacobian): on random expressions over more symbols than the mask
// has bits, and on a kinematic chain, where its rule cache answers most derivatives.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "RandomTree.h"
#include "symbolic/Expr.h"

namespace qdot::sym {
namespace {

// Every listed symbol's derivative, from PartialDerivatives and from Context::diff, must be one node.
void expectSameAsDiff(Context& ctx, PartialDerivatives& partial, std::span<const Expr> symbols, Expr e) {
  std::span<const Expr> gradient = partial.gradient(e);
  std::span<const uint32_t> in = partial.symbolsIn(e);
  ASSERT_EQ(gradient.size(), in.size());
  ASSERT_TRUE(std::is_sorted(in.begin(), in.end()));
  std::vector<Expr> free = ctx.freeSymbols(e);
  size_t listedFree = 0;
  for (uint32_t k = 0; k < symbols.size(); ++k) {
    bool occurs = std::find(free.begin(), free.end(), symbols[k]) != free.end();
    listedFree += occurs;
    auto at = std::lower_bound(in.begin(), in.end(), k);
    bool listed = at != in.end() && *at == k;
    EXPECT_EQ(listed, occurs) << ctx.symbolName(symbols[k]) << " in " << toString(ctx, e);
    Expr expected = ctx.diff(e, symbols[k]);
    EXPECT_EQ(partial.diff(e, k), expected) << "d/d" << ctx.symbolName(symbols[k]) << " of " << toString(ctx, e);
    if (listed) {
      EXPECT_EQ(gradient[at - in.begin()], expected);
    }
  }
  EXPECT_EQ(in.size(), listedFree);
}

TEST(PartialDerivatives, RandomExpressionsOverAliasedSymbols) {
  const int kVars = 150;  // more than the 64 mask bits: Context::diff's mask says "maybe" a lot
  testing::TreeGen gen(2024, kVars);
  Context ctx;
  std::vector<Expr> vars;
  for (int i = 0; i < kVars; ++i) vars.push_back(ctx.symbol("v" + std::to_string(i)));
  std::vector<Expr> listed(vars.begin(), vars.begin() + 100);  // v100.. occur but are not unknowns
  PartialDerivatives partial(ctx, listed);
  for (int n = 0; n < 400; ++n) {
    std::vector<Expr> terms;  // wide sums of random trees, as residuals are
    for (int t = 0; t < 6; ++t) terms.push_back(testing::toExpr(ctx, *gen.gen(5), vars));
    expectSameAsDiff(ctx, partial, listed, ctx.add(terms));
    expectSameAsDiff(ctx, partial, listed, terms[0]);
  }
}

// The N-link pendulum's shape: partial sums over the links, and residuals made of products of a
// per-row context with each partial sum, so the same derivative arises from many nodes.
TEST(PartialDerivatives, KinematicChainMatchesDiff) {
  const int n = 12;
  Context ctx;
  Expr l = ctx.symbol("l"), m = ctx.symbol("m");
  std::vector<Expr> th, w, a, unknowns;
  for (int i = 0; i < n; ++i) {
    th.push_back(ctx.symbol("th" + std::to_string(i)));
    w.push_back(ctx.symbol("w" + std::to_string(i)));
    a.push_back(ctx.symbol("a" + std::to_string(i)));
  }
  for (int i = 0; i < n; ++i) unknowns.insert(unknowns.end(), {th[i], w[i], a[i]});
  std::vector<Expr> sx, sy;  // partial sums of l*w_j*cos(th_j) and l*a_j*sin(th_j) - l*w_j^2*cos(th_j)
  std::vector<Expr> tx, ty;
  for (int k = 0; k < n; ++k) {
    Expr cos = ctx.unary(Kind::Cos, th[k]), sin = ctx.unary(Kind::Sin, th[k]);
    Expr x[] = {l, w[k], cos};
    tx.push_back(ctx.mul(x));
    Expr y[] = {l, a[k], sin};
    ty.push_back(ctx.sub(ctx.mul(y), ctx.mul(ctx.mul(l, ctx.pow(w[k], ctx.constant(2))), cos)));
    sx.push_back(ctx.add(tx));
    sy.push_back(ctx.add(ty));
  }
  PartialDerivatives partial(ctx, unknowns);
  for (int i = 0; i < n; ++i) {
    std::vector<Expr> terms;
    for (int k = i; k < n; ++k) {
      Expr context[] = {ctx.constant(2), l, w[i], sx[k], ctx.unary(Kind::Cos, th[i])};
      Expr p = ctx.add(ctx.mul(context), ctx.mul(ctx.scale(2, l), ctx.mul(sy[k], ctx.unary(Kind::Sin, th[i]))));
      terms.push_back(ctx.scale(k % 2 ? 0.5 : -0.5, ctx.mul(m, p)));
    }
    terms.push_back(ctx.mul(ctx.constant(n - i), ctx.unary(Kind::Sin, th[i])));
    expectSameAsDiff(ctx, partial, unknowns, ctx.add(terms));
  }
}

TEST(PartialDerivatives, LeavesAndErrors) {
  Context ctx;
  Expr x = ctx.symbol("x"), y = ctx.symbol("y"), p = ctx.symbol("p");
  Expr list[] = {x, y};
  PartialDerivatives partial(ctx, list);
  EXPECT_TRUE(partial.symbolsIn(ctx.constant(3)).empty());
  EXPECT_TRUE(partial.symbolsIn(p).empty());
  EXPECT_EQ(partial.diff(p, 0), ctx.zero());
  ASSERT_EQ(partial.gradient(y).size(), 1u);
  EXPECT_EQ(partial.symbolsIn(y)[0], 1u);
  EXPECT_EQ(partial.gradient(y)[0], ctx.one());
  Expr s = ctx.unary(Kind::Sign, x);  // contains x, derivative 0
  ASSERT_EQ(partial.gradient(s).size(), 1u);
  EXPECT_EQ(partial.gradient(s)[0], ctx.zero());
  Expr twice[] = {x, x};
  EXPECT_THROW(PartialDerivatives(ctx, twice), std::invalid_argument);
  Expr notSymbol[] = {ctx.add(x, y)};
  EXPECT_THROW(PartialDerivatives(ctx, notSymbol), std::invalid_argument);
}

}  // namespace
}  // namespace qdot::sym
