// Property tests of the canonical simplifier on random expressions: the simplified DAG evaluates to
// the value of an independent naive evaluation of the same random tree, every node reachable from it
// satisfies the documented canonical-form invariants, and n-ary add/mul are permutation invariant.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "RandomTree.h"
#include "symbolic/Expr.h"

using namespace qdot::sym;
using namespace qdot::sym::testing;

namespace {

// Checks the canonical-form invariants of Expr.h on one node; returns a description or "".
std::string canonicalViolation(Expr n) {
  if (n->kind == Kind::Add) {
    if (n->args.size() != n->coefs().size()) return "Add: coefs size";
    if (n->args.empty()) return "Add: no terms";
    if (n->args.size() == 1 && n->value == 0 && n->coefs()[0] == 1) return "Add: single plain term";
    if (n->args.size() == 1 && n->value == 0) return "Add: single scaled term (should be a Mul)";
    for (size_t i = 0; i < n->args.size(); ++i) {
      Expr t = n->args[i];
      if (t->isConstant() || t->kind == Kind::Add) return "Add: constant or Add term";
      if (t->kind == Kind::Mul && t->value != 1) return "Add: term with a coefficient";
      if (n->coefs()[i] == 0) return "Add: zero coefficient";
      if (i > 0 && structuralCompare(n->args[i - 1], t) >= 0) return "Add: terms not strictly sorted";
    }
  }
  if (n->kind == Kind::Mul) {
    if (n->args.size() != n->exps().size()) return "Mul: exps size";
    if (n->value == 0) return "Mul: zero coefficient";
    if (n->args.empty()) return "Mul: no factors";
    if (n->args.size() == 1 && n->value == 1) return "Mul: single factor with coefficient 1";
    for (size_t i = 0; i < n->args.size(); ++i) {
      Expr b = n->args[i];
      if (b->isConstant() || b->kind == Kind::Mul) return "Mul: constant or Mul base";
      if (n->exps()[i]->isZero()) return "Mul: zero exponent";
      if (i > 0 && structuralCompare(n->args[i - 1], b) >= 0) return "Mul: bases not strictly sorted";
    }
  }
  if (n->kind == Kind::Pow) {
    Expr e = n->args[1];
    if (n->args[0]->isConstant() && e->isConstant()) return "Pow: unfolded constant";
    if (e->isZero() || e->isOne()) return "Pow: trivial exponent";
    bool integer = e->isConstant() && std::floor(e->value) == e->value;
    if (integer && (n->args[0]->kind == Kind::Pow || n->args[0]->kind == Kind::Mul))
      return "Pow: integer power of a Pow or Mul";
  }
  if (n->kind != Kind::Constant && n->kind != Kind::Symbol && n->kind != Kind::Add &&
      n->kind != Kind::Mul && n->kind != Kind::Select) {
    bool allConstant = std::all_of(n->args.begin(), n->args.end(), [](Expr a) { return a->isConstant(); });
    if (allConstant) return std::string("unfolded ") + kindSpelling(n->kind);
  }
  return "";
}

std::string firstViolation(Expr root) {
  std::vector<Expr> stack{root};
  std::set<Expr> seen;
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    if (!seen.insert(n).second) continue;
    if (std::string v = canonicalViolation(n); !v.empty()) return v;
    for (Expr a : n->args) stack.push_back(a);
    for (Expr e : n->exps()) stack.push_back(e);
  }
  return "";
}

// Simplification preserves value. Tolerance: re-association of sums and collected powers change
// round-off only, bounded by a few ulps of the largest intermediate M: |q - ref| <= 1e-9 (1 + |ref| + M).
// Points where atan2 sits on its cut with y = ±0 are skipped: the simplifier does not keep the sign
// of zero (0*y is 0, -0 constants are 0), so atan2(0*y, -1) is pi where IEEE gives -pi for y < 0.
TEST(SimplifyRandom, PreservesValueAndIsCanonical) {
  TreeGen gen(777);
  int compared = 0, failures = 0;
  const int kExpressions = 3000;
  for (int n = 0; n < kExpressions; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("x"), ctx.symbol("y"), ctx.symbol("z")};
    TreePtr tree = gen.gen(6);
    Expr e = toExpr(ctx, *tree, vars);
    std::string violation = firstViolation(e);
    if (!violation.empty() && ++failures <= 10) ADD_FAILURE() << violation << " in " << toString(ctx, e);
    for (int k = 0; k < 3; ++k) {
      std::vector<double> pt = {gen.point(), gen.point(), gen.point()};
      RefEval ref = refEval(*tree, pt);
      if (!std::isfinite(ref.value) || ref.maxAbs > 1e12 || ref.signedZeroSensitive) continue;
      double q = evaluate(e, pt);
      ++compared;
      if (!(std::fabs(q - ref.value) <= 1e-9 * (1 + std::fabs(ref.value) + ref.maxAbs)) && ++failures <= 10)
        ADD_FAILURE() << toString(ctx, e) << " at (" << pt[0] << ", " << pt[1] << ", " << pt[2]
                      << "): " << q << " vs reference " << ref.value << "\n  tree: " << treeString(*tree);
    }
  }
  EXPECT_EQ(failures, 0);
  EXPECT_GE(compared, 0.9 * 3 * kExpressions);
}

// add/mul over a span give the identical node whatever the order of the operands.
TEST(SimplifyRandom, NaryOperationsArePermutationInvariant) {
  TreeGen gen(4242);
  for (int n = 0; n < 300; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("x"), ctx.symbol("y"), ctx.symbol("z")};
    std::vector<Expr> ops;
    for (int i = 0; i < 6; ++i) ops.push_back(toExpr(ctx, *gen.gen(2), vars));
    ops.push_back(ctx.constant(0.1));
    ops.push_back(ctx.constant(0.2));
    ops.push_back(ctx.constant(0.3));
    Expr sum = ctx.add(ops), product = ctx.mul(ops);
    for (int p = 0; p < 5; ++p) {
      std::vector<Expr> shuffled = ops;
      for (size_t i = shuffled.size(); i > 1; --i) std::swap(shuffled[i - 1], shuffled[gen.pick(int(i))]);
      ASSERT_EQ(ctx.add(shuffled), sum) << toString(ctx, sum);
      ASSERT_EQ(ctx.mul(shuffled), product) << toString(ctx, product);
    }
    // building the sum pairwise, left to right, gives the same value
    Expr folded = ctx.zero();
    for (Expr o : ops) folded = ctx.add(folded, o);
    std::vector<double> pt = {0.3, -0.7, 1.1};
    double a = evaluate(sum, pt), b = evaluate(folded, pt);
    if (std::isfinite(a)) {
      EXPECT_NEAR(a, b, 1e-9 * (1 + std::fabs(a)));
    }
  }
}

// Rebuilding any canonical node through the constructors returns the node itself.
TEST(SimplifyRandom, CanonicalNodesAreFixedPoints) {
  TreeGen gen(99);
  int checked = 0;
  for (int n = 0; n < 500; ++n) {
    Context ctx;
    std::vector<Expr> vars = {ctx.symbol("x"), ctx.symbol("y"), ctx.symbol("z")};
    Expr e = toExpr(ctx, *gen.gen(4), vars);
    EXPECT_EQ(ctx.add(e, ctx.zero()), e);
    EXPECT_EQ(ctx.mul(e, ctx.one()), e);
    EXPECT_EQ(ctx.mul(std::vector<Expr>{e}), e);
    EXPECT_EQ(ctx.add(std::vector<Expr>{e, ctx.zero()}), e);
    // with a symbol w that e does not contain (so no coefficient round-off is involved)
    Expr w = ctx.symbol("w");
    bool scaledSum = e->kind == Kind::Mul && e->args.size() == 1 && e->args[0]->kind == Kind::Add;
    if (!scaledSum) {
      EXPECT_EQ(ctx.sub(ctx.add(e, w), w), e) << toString(ctx, e);
    }
    EXPECT_EQ(ctx.div(ctx.mul(e, w), w), e) << toString(ctx, e);
    ++checked;
  }
  EXPECT_EQ(checked, 500);
}

}  // namespace
