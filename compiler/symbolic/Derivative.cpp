// Symbolic differentiation: one rule per kind (the switch in `applyRule` has no default, so a new
// kind without a rule triggers -Wswitch), applied along a Direction: the rate at which each symbol
// moves. Context::diff is the direction {s -> 1}; DirectionalDerivative is any field
// {s -> rate(s)} (d/dt). One iterative post-order walk serves both, memoising per node and skipping
// nodes whose symbol mask misses every moving symbol; the memo doubles as the visited set, so a call
// costs O(new nodes). PartialDerivatives (Gradient.cpp) applies the same rules in a sparse pass.
#include <stdexcept>

#include "symbolic/DerivativeRules.h"

namespace qdot::sym {

namespace {

// Fast paths below rely on canonical nodes being fixed points of the builders: MulBuilder over the
// one factor x gives x, and AddBuilder over the one term 1·x gives x unless x = k·(sum), which it
// distributes (tested in BuilderFixedPointTest). They skip a builder, never change a result.

// What AddBuilder makes of the single term 1·x.
Expr sumOfOne(Context& ctx, Expr x) {
  bool scaledSum = x->kind == Kind::Mul && x->value != 1.0 && x->args.size() == 1 && x->exps()[0]->isOne() &&
                   x->args[0]->kind == Kind::Add;
  if (!scaledSum) return x;
  AddBuilder sum(ctx);
  sum.add(1.0, x);
  return sum.build();
}

Expr minusOne(Expr e, Context& ctx) {
  return e->isConstant() ? ctx.constant(e->value - 1.0) : ctx.sub(e, ctx.one());
}

// d(b^e) = e*b^(e-1)*db + b^e*log(b)*de; only the first term when e does not move.
// `self` is b^e (the Pow node, or nullptr to build it when needed).
Expr powRule(Context& ctx, Expr b, Expr e, Expr db, Expr de, Expr self) {
  Expr first = ctx.zero();
  if (!db->isZero() && e->isOne()) {
    first = db;  // 1 * b^0 * db
  } else if (!db->isZero()) {
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

Expr dConstant(const Diff& D) { return D.ctx.zero(); }
Expr dSymbol(const Diff& D) { return D.dir->rate(D.node); }

// Σ coef·term over non-zero terms; one term with coefficient 1 (one moving term of a sum, one
// moving factor of a product: the usual case) skips most of the AddBuilder.
class TermSum {
 public:
  explicit TermSum(Context& ctx) : ctx_(ctx), sum_(ctx) {}
  void add(double coef, Expr term) {
    if (count_++ == 0) first_ = {term, coef};
    else if (count_ == 2) sum_.add(first_.coef, first_.e);
    if (count_ > 1) sum_.add(coef, term);
  }
  Expr build() {
    if (count_ == 1 && first_.coef == 1.0) return sumOfOne(ctx_, first_.e);
    if (count_ == 1) sum_.add(first_.coef, first_.e);
    return sum_.build();
  }

 private:
  Context& ctx_;
  AddBuilder sum_;
  AddBuilder::Term first_{};
  size_t count_ = 0;
};

Expr dAdd(const Diff& D) {
  Expr n = D.node;
  TermSum sum(D.ctx);
  D.forEachMoving([&](size_t i) {
    if (Expr d = D.d(i); !d->isZero()) sum.add(n->coefs()[i], d);
  });
  return sum.build();
}

// Product rule over the factors that may move: Σ_i (Π_{j≠i} f_j) * d(f_i).
Expr dMul(const Diff& D) {
  Expr n = D.node;
  TermSum sum(D.ctx);
  size_t m = n->args.size();
  D.forEachMoving([&](size_t i) {
    Expr dFactor = powRule(D.ctx, n->args[i], n->exps()[i], D.d(i), D.d(m + i), nullptr);
    if (dFactor->isZero()) return;  // the mask only said "maybe"
    MulBuilder term(D.ctx, n->value);
    for (size_t j = 0; j < m; ++j)
      if (j != i) term.pair(n->args[j], n->exps()[j]);
    term.factor(dFactor);
    sum.add(1.0, term.build());
  });
  return sum.build();
}

Expr dPow(const Diff& D) { return powRule(D.ctx, D.node->args[0], D.node->args[1], D.d(0), D.d(1), D.node); }

// The rules of one-argument functions: u = the argument, du = its derivative.
Expr dSin(const Diff& D, Expr u, Expr du) { return D.chain(D.ctx.unary(Kind::Cos, u), du); }
Expr dCos(const Diff& D, Expr u, Expr du) { return D.chain(D.ctx.neg(D.ctx.unary(Kind::Sin, u)), du); }
// tan' = 1 + tan^2, tanh' = 1 - tanh^2: reuse the node itself.
Expr dTan(const Diff& D, Expr, Expr du) { return D.chain(D.ctx.add(D.ctx.one(), D.square(D.node)), du); }
Expr dTanh(const Diff& D, Expr, Expr du) { return D.chain(D.ctx.sub(D.ctx.one(), D.square(D.node)), du); }
Expr dAsin(const Diff& D, Expr u, Expr du) {
  Context& c = D.ctx;
  Expr root = c.pow(c.sub(c.one(), D.square(u)), c.constant(-0.5));
  return D.chain(root, du);
}
Expr dAcos(const Diff& D, Expr u, Expr du) {
  Context& c = D.ctx;
  Expr root = c.pow(c.sub(c.one(), D.square(u)), c.constant(-0.5));
  return D.chain(c.neg(root), du);
}
Expr dAtan(const Diff& D, Expr u, Expr du) {
  Context& c = D.ctx;
  return D.chain(c.pow(c.add(c.one(), D.square(u)), c.constant(-1.0)), du);
}
Expr dSinh(const Diff& D, Expr u, Expr du) { return D.chain(D.ctx.unary(Kind::Cosh, u), du); }
Expr dCosh(const Diff& D, Expr u, Expr du) { return D.chain(D.ctx.unary(Kind::Sinh, u), du); }
Expr dExp(const Diff& D, Expr, Expr du) { return D.chain(D.node, du); }
// log' = u'/u, in forms that stay finite where u overflows (|v| > 710): log(cosh v)' = tanh(v) v',
// log(sinh v)' = v'/tanh(v), log(c + k exp v)' = k v'/(c exp(−v) + k) (log(exp v)' = v' already,
// since u' = exp(v) v' cancels). v' is u' over the outer derivative, which the builders cancel exactly.
Expr dLog(const Diff& D, Expr u, Expr du) {
  Context& c = D.ctx;
  if (du->isZero()) return du;
  if (u->kind == Kind::Cosh) {
    Expr v = u->args[0];
    return c.mul(c.unary(Kind::Tanh, v), c.div(du, c.unary(Kind::Sinh, v)));
  }
  if (u->kind == Kind::Sinh) {
    Expr v = u->args[0];
    return c.div(c.div(du, c.unary(Kind::Cosh, v)), c.unary(Kind::Tanh, v));
  }
  if (u->kind == Kind::Add && u->args.size() == 1 && u->args[0]->kind == Kind::Exp) {
    Expr e = u->args[0], v = e->args[0];
    Expr denominator = c.add(c.scale(u->value, c.unary(Kind::Exp, c.neg(v))), c.constant(u->coefs()[0]));
    return c.div(c.div(du, e), denominator);
  }
  return c.div(du, u);
}
Expr dAbs(const Diff& D, Expr u, Expr du) { return D.chain(D.ctx.unary(Kind::Sign, u), du); }

// atan2(y, x)' = (x*dy - y*dx) / (x^2 + y^2)
Expr dAtan2(const Diff& D) {
  Context& c = D.ctx;
  Expr y = D.node->args[0], x = D.node->args[1];
  Expr num = c.sub(c.mul(x, D.d(0)), c.mul(y, D.d(1)));
  return c.div(num, c.add(D.square(x), D.square(y)));
}
// min(a, b)' = if a <= b then a' else b';  max(a, b)' = if b <= a then a' else b'
Expr dMin(const Diff& D) {
  Expr a = D.node->args[0], b = D.node->args[1];
  return D.ctx.select(D.ctx.binary(Kind::Le, a, b), D.d(0), D.d(1));
}
Expr dMax(const Diff& D) {
  Expr a = D.node->args[0], b = D.node->args[1];
  return D.ctx.select(D.ctx.binary(Kind::Le, b, a), D.d(0), D.d(1));
}
// Sign and the Boolean-valued kinds are piecewise constant.
Expr dPiecewiseConstant(const Diff& D) { return D.ctx.zero(); }
Expr dSelect(const Diff& D) { return D.ctx.select(D.node->args[0], D.d(1), D.d(2)); }

}  // namespace

Expr applyRule(const Diff& D) {
  Expr u = D.node->args.empty() ? nullptr : D.node->args[0];
  auto unary = [&](Expr (*rule)(const Diff&, Expr, Expr)) { return rule(D, u, D.d(0)); };
  switch (D.node->kind) {
    case Kind::Constant: return dConstant(D);
    case Kind::Symbol: return dSymbol(D);
    case Kind::Add: return dAdd(D);
    case Kind::Mul: return dMul(D);
    case Kind::Pow: return dPow(D);
    case Kind::Sin: return unary(dSin);
    case Kind::Cos: return unary(dCos);
    case Kind::Tan: return unary(dTan);
    case Kind::Asin: return unary(dAsin);
    case Kind::Acos: return unary(dAcos);
    case Kind::Atan: return unary(dAtan);
    case Kind::Sinh: return unary(dSinh);
    case Kind::Cosh: return unary(dCosh);
    case Kind::Tanh: return unary(dTanh);
    case Kind::Exp: return unary(dExp);
    case Kind::Log: return unary(dLog);
    case Kind::Abs: return unary(dAbs);
    case Kind::Sign: return dPiecewiseConstant(D);
    case Kind::Atan2: return dAtan2(D);
    case Kind::Min: return dMin(D);
    case Kind::Max: return dMax(D);
    case Kind::Lt:
    case Kind::Le:
    case Kind::Eq:
    case Kind::Ne:
    case Kind::And:
    case Kind::Or:
    case Kind::Not: return dPiecewiseConstant(D);
    case Kind::Select: return dSelect(D);
  }
  throw std::logic_error("diff: corrupt node kind");
}

namespace {

// The derivative of e along dir: post-order over the nodes that may move and have no memo yet.
// A child is finished (memoised) before its next sibling is looked at. If dir.rate throws, only
// finished nodes are in the memo, so it stays valid.
Expr differentiate(Context& ctx, Direction& dir, NodeMap<Expr>& memo, Expr e) {
  if (!(e->symbolMask & dir.mask)) return ctx.zero();
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
      if ((c->symbolMask & dir.mask) && !memo.find(c)) stack.push_back({c, 0});
    } else {
      Expr node = f.node;
      stack.pop_back();
      memo.insert(node, applyRule(Diff{.ctx = ctx, .node = node, .dir = &dir, .memo = &memo}));
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
  Partial along(*this, s);
  return differentiate(*this, along, impl_->diffMemo[s->symbolId], e);
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
