// Symbolic differentiation: one rule per kind (the switch in `rule` has no default, so a new kind
// without a rule triggers -Wswitch) and Context::diff, which walks the DAG iteratively in post-order,
// memoising ∂n/∂s per (node, symbol) in the Context and skipping nodes whose symbol mask lacks s.
// The memo doubles as the visited set, so a call costs O(nodes not yet differentiated w.r.t. s).
#include <stdexcept>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

// What a rule sees: the Context, the symbol, and the derivatives of the node's children.
struct Diff {
  Context& ctx;
  Expr s;
  NodeMap<Expr>& memo;

  Expr d(Expr c) const {
    if (!(c->symbolMask & symbolBit(s))) return ctx.zero();
    return *memo.find(c);
  }
  Expr chain(Expr outer, Expr du) const { return du->isZero() ? du : ctx.mul(outer, du); }
  Expr square(Expr u) const { return ctx.pow(u, ctx.constant(2.0)); }
};

Expr minusOne(Expr e, Context& ctx) {
  return e->isConstant() ? ctx.constant(e->value - 1.0) : ctx.sub(e, ctx.one());
}

// d(b^e) = e*b^(e-1)*db + b^e*log(b)*de; only the first term when e does not depend on s.
// `self` is b^e (the Pow node, or nullptr to build it when needed).
Expr powRule(const Diff& D, Expr b, Expr e, Expr self) {
  Context& ctx = D.ctx;
  Expr db = D.d(b), de = D.d(e);
  Expr first = ctx.zero();
  if (!db->isZero()) {
    MulBuilder m(ctx);
    m.factor(e);
    m.power(b, minusOne(e, ctx));
    m.factor(db);
    first = m.build();
  }
  if (de->isZero()) return first;
  Expr bToE = self ? self : ctx.pow(b, e);
  Expr second = ctx.mul(std::vector<Expr>{bToE, ctx.unary(Kind::Log, b), de});
  return ctx.add(first, second);
}

Expr dConstant(const Diff& D, Expr) { return D.ctx.zero(); }
Expr dSymbol(const Diff& D, Expr n) { return n == D.s ? D.ctx.one() : D.ctx.zero(); }

Expr dAdd(const Diff& D, Expr n) {
  AddBuilder sum(D.ctx);
  for (size_t i = 0; i < n->args.size(); ++i) sum.add(n->coefs[i], D.d(n->args[i]));
  return sum.build();
}

// Product rule over the factors that depend on s: Σ_i (Π_{j≠i} f_j) * d(f_i).
Expr dMul(const Diff& D, Expr n) {
  AddBuilder sum(D.ctx);
  size_t m = n->args.size();
  for (size_t i = 0; i < m; ++i) {
    Expr b = n->args[i], e = n->exps[i];
    if (!((b->symbolMask | e->symbolMask) & symbolBit(D.s))) continue;
    Expr dFactor = powRule(D, b, e, nullptr);
    if (dFactor->isZero()) continue;  // the mask only said "maybe"
    MulBuilder term(D.ctx, n->value);
    for (size_t j = 0; j < m; ++j)
      if (j != i) term.pair(n->args[j], n->exps[j]);
    term.factor(dFactor);
    sum.add(1.0, term.build());
  }
  return sum.build();
}

Expr dPow(const Diff& D, Expr n) { return powRule(D, n->args[0], n->args[1], n); }

Expr dSin(const Diff& D, Expr n) { return D.chain(D.ctx.unary(Kind::Cos, n->args[0]), D.d(n->args[0])); }
Expr dCos(const Diff& D, Expr n) {
  return D.chain(D.ctx.neg(D.ctx.unary(Kind::Sin, n->args[0])), D.d(n->args[0]));
}
// tan' = 1 + tan^2, tanh' = 1 - tanh^2: reuse the node itself.
Expr dTan(const Diff& D, Expr n) { return D.chain(D.ctx.add(D.ctx.one(), D.square(n)), D.d(n->args[0])); }
Expr dTanh(const Diff& D, Expr n) { return D.chain(D.ctx.sub(D.ctx.one(), D.square(n)), D.d(n->args[0])); }
Expr dAsin(const Diff& D, Expr n) {
  Context& c = D.ctx;
  Expr root = c.pow(c.sub(c.one(), D.square(n->args[0])), c.constant(-0.5));
  return D.chain(root, D.d(n->args[0]));
}
Expr dAcos(const Diff& D, Expr n) {
  Context& c = D.ctx;
  Expr root = c.pow(c.sub(c.one(), D.square(n->args[0])), c.constant(-0.5));
  return D.chain(c.neg(root), D.d(n->args[0]));
}
Expr dAtan(const Diff& D, Expr n) {
  Context& c = D.ctx;
  return D.chain(c.pow(c.add(c.one(), D.square(n->args[0])), c.constant(-1.0)), D.d(n->args[0]));
}
Expr dSinh(const Diff& D, Expr n) { return D.chain(D.ctx.unary(Kind::Cosh, n->args[0]), D.d(n->args[0])); }
Expr dCosh(const Diff& D, Expr n) { return D.chain(D.ctx.unary(Kind::Sinh, n->args[0]), D.d(n->args[0])); }
Expr dExp(const Diff& D, Expr n) { return D.chain(n, D.d(n->args[0])); }
Expr dLog(const Diff& D, Expr n) { return D.ctx.div(D.d(n->args[0]), n->args[0]); }
Expr dAbs(const Diff& D, Expr n) { return D.chain(D.ctx.unary(Kind::Sign, n->args[0]), D.d(n->args[0])); }

// atan2(y, x)' = (x*dy - y*dx) / (x^2 + y^2)
Expr dAtan2(const Diff& D, Expr n) {
  Context& c = D.ctx;
  Expr y = n->args[0], x = n->args[1];
  Expr num = c.sub(c.mul(x, D.d(y)), c.mul(y, D.d(x)));
  return c.div(num, c.add(D.square(x), D.square(y)));
}
// min(a, b)' = if a <= b then a' else b';  max(a, b)' = if b <= a then a' else b'
Expr dMin(const Diff& D, Expr n) {
  Expr a = n->args[0], b = n->args[1];
  return D.ctx.select(D.ctx.binary(Kind::Le, a, b), D.d(a), D.d(b));
}
Expr dMax(const Diff& D, Expr n) {
  Expr a = n->args[0], b = n->args[1];
  return D.ctx.select(D.ctx.binary(Kind::Le, b, a), D.d(a), D.d(b));
}
// Sign and the Boolean-valued kinds are piecewise constant.
Expr dPiecewiseConstant(const Diff& D, Expr) { return D.ctx.zero(); }
Expr dSelect(const Diff& D, Expr n) { return D.ctx.select(n->args[0], D.d(n->args[1]), D.d(n->args[2])); }

Expr rule(const Diff& D, Expr n) {
  switch (n->kind) {
    case Kind::Constant: return dConstant(D, n);
    case Kind::Symbol: return dSymbol(D, n);
    case Kind::Add: return dAdd(D, n);
    case Kind::Mul: return dMul(D, n);
    case Kind::Pow: return dPow(D, n);
    case Kind::Sin: return dSin(D, n);
    case Kind::Cos: return dCos(D, n);
    case Kind::Tan: return dTan(D, n);
    case Kind::Asin: return dAsin(D, n);
    case Kind::Acos: return dAcos(D, n);
    case Kind::Atan: return dAtan(D, n);
    case Kind::Sinh: return dSinh(D, n);
    case Kind::Cosh: return dCosh(D, n);
    case Kind::Tanh: return dTanh(D, n);
    case Kind::Exp: return dExp(D, n);
    case Kind::Log: return dLog(D, n);
    case Kind::Abs: return dAbs(D, n);
    case Kind::Sign: return dPiecewiseConstant(D, n);
    case Kind::Atan2: return dAtan2(D, n);
    case Kind::Min: return dMin(D, n);
    case Kind::Max: return dMax(D, n);
    case Kind::Lt:
    case Kind::Le:
    case Kind::Eq:
    case Kind::Ne:
    case Kind::And:
    case Kind::Or:
    case Kind::Not: return dPiecewiseConstant(D, n);
    case Kind::Select: return dSelect(D, n);
  }
  throw std::logic_error("diff: corrupt node kind");
}

}  // namespace

Expr Context::diff(Expr e, Expr s) {
  if (!s || !s->isSymbol()) throw std::invalid_argument("diff: not a symbol");
  uint64_t bit = symbolBit(s);
  if (!(e->symbolMask & bit)) return zero_;
  auto& memos = impl_->diffMemo;
  if (memos.size() <= s->symbolId) memos.resize(s->symbolId + 1);
  NodeMap<Expr>& memo = memos[s->symbolId];
  if (Expr* known = memo.find(e)) return *known;

  // Depth-first post-order over the nodes that may contain s and have no memo yet. The memo is the
  // visited set: a child is finished (memoised) before its next sibling is looked at.
  Diff D{*this, s, memo};
  std::vector<std::pair<Expr, uint32_t>> stack{{e, 0}};
  while (!stack.empty()) {
    auto& [n, next] = stack.back();
    if (next < childCount(n)) {
      Expr c = child(n, next++);
      if ((c->symbolMask & bit) && !memo.find(c)) stack.push_back({c, 0});
    } else {
      Expr node = n;
      stack.pop_back();
      memo.insert(node, rule(D, node));
    }
  }
  return *memo.find(e);
}

}  // namespace qdot::sym
