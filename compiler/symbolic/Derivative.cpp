// Symbolic differentiation: one rule per kind (the switch in `rule` has no default, so a new kind
// without a rule triggers -Wswitch), applied along a Direction: the rate at which each symbol moves.
// Context::diff is the direction {s -> 1}; DirectionalDerivative is any field {s -> rate(s)} (d/dt).
// One iterative post-order walk serves both, memoising per node and skipping nodes whose symbol mask
// misses every moving symbol; the memo doubles as the visited set, so a call costs O(new nodes).
#include <stdexcept>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

// What the derivative is taken along: rate(s) for every symbol; `mask` has the bits of every symbol
// whose rate may be non-zero (all bits when rates are only known on demand).
struct Direction {
  uint64_t mask = 0;
  virtual Expr rate(Expr symbol) = 0;

 protected:
  ~Direction() = default;
};

// What a rule sees: the Context, the direction, and the derivatives of the node's children.
struct Diff {
  Context& ctx;
  Direction& dir;
  NodeMap<Expr>& memo;

  bool mayMove(Expr c) const { return (c->symbolMask & dir.mask) != 0; }
  Expr d(Expr c) const { return mayMove(c) ? *memo.find(c) : ctx.zero(); }
  Expr chain(Expr outer, Expr du) const { return du->isZero() ? du : ctx.mul(outer, du); }
  Expr square(Expr u) const { return ctx.pow(u, ctx.constant(2.0)); }
};

Expr minusOne(Expr e, Context& ctx) {
  return e->isConstant() ? ctx.constant(e->value - 1.0) : ctx.sub(e, ctx.one());
}

// d(b^e) = e*b^(e-1)*db + b^e*log(b)*de; only the first term when e does not move.
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
  Expr factors[] = {bToE, ctx.unary(Kind::Log, b), de};
  Expr second = ctx.mul(factors);
  return ctx.add(first, second);
}

Expr dConstant(const Diff& D, Expr) { return D.ctx.zero(); }
Expr dSymbol(const Diff& D, Expr n) { return D.dir.rate(n); }

Expr dAdd(const Diff& D, Expr n) {
  AddBuilder sum(D.ctx);
  for (size_t i = 0; i < n->args.size(); ++i)
    if (Expr d = D.d(n->args[i]); !d->isZero()) sum.add(n->coefs[i], d);
  return sum.build();
}

// Product rule over the factors that may move: Σ_i (Π_{j≠i} f_j) * d(f_i).
Expr dMul(const Diff& D, Expr n) {
  AddBuilder sum(D.ctx);
  size_t m = n->args.size();
  for (size_t i = 0; i < m; ++i) {
    Expr b = n->args[i], e = n->exps[i];
    if (!D.mayMove(b) && !D.mayMove(e)) continue;
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

// The derivative of e along dir: post-order over the nodes that may move and have no memo yet.
// A child is finished (memoised) before its next sibling is looked at. If dir.rate throws, only
// finished nodes are in the memo, so it stays valid.
Expr differentiate(Context& ctx, Direction& dir, NodeMap<Expr>& memo, Expr e) {
  Diff D{ctx, dir, memo};
  if (!D.mayMove(e)) return ctx.zero();
  if (Expr* known = memo.find(e)) return *known;
  struct Frame {
    Expr node;
    uint32_t next;  // next child to look at
  };
  SmallVec<Frame, 16> stack;
  stack.push_back({e, 0});
  while (!stack.empty()) {
    Frame& f = stack.back();
    if (f.next < childCount(f.node)) {
      Expr c = child(f.node, f.next++);
      if (D.mayMove(c) && !memo.find(c)) stack.push_back({c, 0});
    } else {
      Expr node = f.node;
      stack.pop_back();
      memo.insert(node, rule(D, node));
    }
  }
  return *memo.find(e);
}

// ∂/∂s: rate 1 for s, 0 for every other symbol.
struct Partial final : Direction {
  Partial(Context& c, Expr s) : ctx(c), wrt(s) { mask = symbolBit(s); }
  Expr rate(Expr symbol) override { return symbol == wrt ? ctx.one() : ctx.zero(); }
  Context& ctx;
  Expr wrt;
};

}  // namespace

Expr Context::diff(Expr e, Expr s) {
  if (!s || !s->isSymbol()) throw std::invalid_argument("diff: not a symbol");
  auto& memos = impl_->diffMemo;
  if (memos.size() <= s->symbolId) memos.resize(s->symbolId + 1);
  Partial along(*this, s);
  return differentiate(*this, along, memos[s->symbolId], e);
}

// --- DirectionalDerivative -------------------------------------------------------------------------

// Explicit rates (mask: their bits), plus the rate function's answers, cached as rates.
struct DirectionalDerivative::Impl final : Direction {
  explicit Impl(Context& c) : ctx(c) {}
  Expr rate(Expr symbol) override {
    if (Expr* known = rates.find(symbol)) return *known;
    if (!rateOf) return ctx.zero();
    Expr r = rateOf(symbol);
    if (!r) throw std::invalid_argument("DirectionalDerivative: the rate function returned no expression");
    rates.insert(symbol, r);
    return r;
  }

  Context& ctx;
  NodeMap<Expr> rates;
  std::function<Expr(Expr)> rateOf;
  NodeMap<Expr> memo;  ///< node -> derivative along the current rates
};

DirectionalDerivative::DirectionalDerivative(Context& ctx) : impl_(std::make_unique<Impl>(ctx)) {}
DirectionalDerivative::~DirectionalDerivative() = default;
DirectionalDerivative::DirectionalDerivative(DirectionalDerivative&&) noexcept = default;

// The memo is kept unless a memoised node may contain the symbol: it was reached (it is memoised
// itself), or its bit is new to the mask (subtrees with that bit were skipped as constant).
void DirectionalDerivative::setRate(Expr symbol, Expr rate) {
  if (!symbol || !symbol->isSymbol()) throw std::invalid_argument("setRate: not a symbol");
  if (!rate) throw std::invalid_argument("setRate: no rate expression");
  Impl& d = *impl_;
  Expr* old = d.rates.find(symbol);
  if (old ? *old == rate : rate->isZero() && !d.rateOf) return;
  if (d.memo.find(symbol) || !(d.mask & symbolBit(symbol))) d.memo.clear();
  d.mask |= symbolBit(symbol);
  if (old) *old = rate;
  else d.rates.insert(symbol, rate);
}

// The first function widens the mask to every symbol (skipped subtrees may now move: drop the
// memo); replacing it later keeps the memo, since every symbol reached so far has a cached rate.
void DirectionalDerivative::setRateFunction(std::function<Expr(Expr)> rateOf) {
  Impl& d = *impl_;
  d.rateOf = std::move(rateOf);
  if (!d.rateOf || d.mask == ~uint64_t{0}) return;
  d.memo.clear();
  d.mask = ~uint64_t{0};
}

Expr DirectionalDerivative::operator()(Expr e) { return differentiate(impl_->ctx, *impl_, impl_->memo, e); }

}  // namespace qdot::sym
