// Canonical arithmetic: the Add and Mul builders and Context::add/sub/neg/mul/div/pow/scale.
// Add = constant + Σ coef·term (flattened, like terms collected, sorted by structuralCompare);
// Mul = coef · Π base^exp (equal bases collected, sorted); see Expr.h for the full canonical form.
// Products of sums are never expanded and a coefficient times a sum stays a Mul.
#include <algorithm>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

bool lessByStructure(Expr a, Expr b) { return a != b && structuralCompare(a, b) < 0; }

// A strict weak order on doubles with NaN last (plain < is not one when NaN is present).
bool lessNumber(double a, double b) {
  bool na = std::isnan(a), nb = std::isnan(b);
  return na || nb ? (!na && nb) : a < b;
}

Expr scaleExponent(Context& ctx, Expr e, double k) {
  return e->isConstant() ? ctx.constant(e->value * k) : ctx.scale(k, e);
}

bool isIntegerConstant(Expr e) { return e->isConstant() && isIntegerValue(e->value); }

// Drops the numeric coefficient of a Mul (the result may be an Add when the Mul was c*(sum)).
Expr stripCoefficient(Context& ctx, Expr m) {
  return ctx.impl().makeMul(1.0, std::vector<Expr>(m->args), std::vector<Expr>(m->exps));
}

}  // namespace

// --- AddBuilder ------------------------------------------------------------------------------------

void AddBuilder::add(double coef, Expr e) {
  if (coef == 0.0) return;
  if (e->kind == Kind::Constant) {
    constants_.push_back(coef * e->value);
  } else if (e->kind == Kind::Add) {
    constants_.push_back(coef * e->value);
    for (size_t i = 0; i < e->args.size(); ++i) terms_.emplace_back(e->args[i], coef * e->coefs[i]);
  } else if (e->kind == Kind::Mul && e->value != 1.0) {
    Expr stripped = stripCoefficient(ctx_, e);
    if (stripped->kind == Kind::Add) return add(coef * e->value, stripped);
    terms_.emplace_back(stripped, coef * e->value);
  } else {
    terms_.emplace_back(e, coef);
  }
}

// Sorted by term, then coefficient, so like terms are summed in an order independent of the input.
Expr AddBuilder::build() {
  std::sort(terms_.begin(), terms_.end(), [](const auto& a, const auto& b) {
    return a.first == b.first ? lessNumber(a.second, b.second) : lessByStructure(a.first, b.first);
  });
  std::sort(constants_.begin(), constants_.end(), lessNumber);
  double constant = 0.0;
  for (double c : constants_) constant += c;
  size_t out = 0;
  for (size_t i = 0; i < terms_.size();) {
    Expr t = terms_[i].first;
    double c = 0.0;
    for (; i < terms_.size() && terms_[i].first == t; ++i) c += terms_[i].second;
    if (c != 0.0) terms_[out++] = {t, c};
  }
  terms_.resize(out);
  if (terms_.empty()) return ctx_.constant(constant);
  if (terms_.size() == 1 && constant == 0.0) {
    if (terms_[0].second == 1.0) return terms_[0].first;
    MulBuilder m(ctx_, terms_[0].second);
    m.factor(terms_[0].first);
    return m.build();
  }
  Node n{};
  n.kind = Kind::Add;
  n.value = constant;
  n.args.reserve(out);
  n.coefs.reserve(out);
  for (auto& [t, c] : terms_) {
    n.args.push_back(t);
    n.coefs.push_back(c);
  }
  return ctx_.impl().intern(std::move(n));
}

// --- MulBuilder ------------------------------------------------------------------------------------

void MulBuilder::factor(Expr f) {
  if (f->kind == Kind::Constant) {
    scale(f->value);
  } else if (f->kind == Kind::Mul) {
    if (f->value != 1.0) scale(f->value);
    for (size_t i = 0; i < f->args.size(); ++i) pairs_.emplace_back(f->args[i], f->exps[i]);
  } else if (f->kind == Kind::Pow && !f->args[0]->isConstant() && f->args[0]->kind != Kind::Mul) {
    pairs_.emplace_back(f->args[0], f->args[1]);
  } else {
    pairs_.emplace_back(f, ctx_.one());  // Pow of a constant or of a product stays whole
  }
}

void MulBuilder::power(Expr b, Expr e) {
  if (e->isConstant()) {
    if (e->isZero()) return;
    if (b->isConstant()) return scale(powValue(b->value, e->value));
    if (b->kind == Kind::Mul && isIntegerValue(e->value)) {
      scale(powValue(b->value, e->value));
      for (size_t i = 0; i < b->args.size(); ++i) power(b->args[i], scaleExponent(ctx_, b->exps[i], e->value));
      return;
    }
    if (b->kind != Kind::Pow) {
      pairs_.emplace_back(b, e);
      return;
    }
  }
  factor(ctx_.pow(b, e));
}

// Sorted by base, then exponent, so exponents of equal bases are added in a canonical order.
void MulBuilder::mergeEqualBases() {
  std::sort(pairs_.begin(), pairs_.end(), [](const auto& a, const auto& b) {
    return a.first == b.first ? lessByStructure(a.second, b.second) : lessByStructure(a.first, b.first);
  });
  size_t out = 0;
  for (size_t i = 0; i < pairs_.size();) {
    size_t j = i + 1;
    while (j < pairs_.size() && pairs_[j].first == pairs_[i].first) ++j;
    Expr e = j == i + 1 ? pairs_[i].second : sumExponents(i, j);
    if (!e->isZero()) pairs_[out++] = {pairs_[i].first, e};
    i = j;
  }
  pairs_.resize(out);
}

// Sum of the exponents of pairs_[i, j) (constants added as numbers, no intermediate nodes).
Expr MulBuilder::sumExponents(size_t i, size_t j) {
  AddBuilder sum(ctx_);
  for (; i < j; ++i) sum.add(1.0, pairs_[i].second);
  return sum.build();
}

// A pair (Pow(B, E), k) with integer k is really pow(Pow(B, E), k), which the Pow rules rewrite;
// re-enter it so e.g. sqrt(u)*sqrt(u) = u and 2^x*2^x = 2^(2*x) match pow(..., 2).
bool MulBuilder::redecompose() {
  std::vector<std::pair<Expr, Expr>> again;
  size_t out = 0;
  for (auto& p : pairs_) {
    Expr b = p.first;
    bool opaque = b->kind == Kind::Pow && (b->args[0]->isConstant() || b->args[0]->kind == Kind::Mul);
    if (b->kind == Kind::Pow && isIntegerConstant(p.second) && !(opaque && p.second->isOne()))
      again.push_back(p);
    else
      pairs_[out++] = p;
  }
  pairs_.resize(out);
  for (auto& [b, e] : again) factor(ctx_.pow(b, e));
  return !again.empty();
}

double MulBuilder::coefficient() {
  std::sort(coefs_.begin(), coefs_.end(), lessNumber);
  double c = 1.0;
  for (double v : coefs_) c *= v;
  return c;
}

Expr MulBuilder::build() {
  double coef = coefficient();
  if (coef == 0.0) return ctx_.zero();
  do mergeEqualBases();
  while (redecompose());
  std::vector<Expr> bases, exps;
  bases.reserve(pairs_.size());
  exps.reserve(pairs_.size());
  for (auto& [b, e] : pairs_) {
    bases.push_back(b);
    exps.push_back(e);
  }
  return ctx_.impl().makeMul(coefficient(), std::move(bases), std::move(exps));
}

// --- Context arithmetic ----------------------------------------------------------------------------

Expr Context::add(Expr a, Expr b) {
  if (a->isZero()) return b;
  if (b->isZero()) return a;
  AddBuilder s(*this);
  s.add(1.0, a);
  s.add(1.0, b);
  return s.build();
}

Expr Context::add(std::span<const Expr> terms) {
  Expr single = zero_;
  size_t nonZero = 0;
  for (Expr t : terms)
    if (!t->isZero()) single = t, ++nonZero;
  if (nonZero <= 1) return single;
  AddBuilder s(*this);
  for (Expr t : terms) s.add(1.0, t);
  return s.build();
}

Expr Context::sub(Expr a, Expr b) {
  if (b->isZero()) return a;
  if (a == b) return zero_;
  AddBuilder s(*this);
  s.add(1.0, a);
  s.add(-1.0, b);
  return s.build();
}

Expr Context::neg(Expr a) { return scale(-1.0, a); }

Expr Context::scale(double c, Expr a) {
  if (c == 1.0) return a;
  MulBuilder m(*this, c);
  m.factor(a);
  return m.build();
}

Expr Context::mul(Expr a, Expr b) {
  if (a->isOne()) return b;
  if (b->isOne()) return a;
  MulBuilder m(*this);
  m.factor(a);
  m.factor(b);
  return m.build();
}

Expr Context::mul(std::span<const Expr> factors) {
  MulBuilder m(*this);
  for (Expr f : factors) m.factor(f);
  return m.build();
}

Expr Context::div(Expr a, Expr b) {
  if (b->isOne()) return a;
  MulBuilder m(*this);
  m.factor(a);
  m.power(b, constant(-1.0));
  return m.build();
}

Expr Context::pow(Expr base, Expr exponent) {
  if (base->isConstant() && exponent->isConstant()) return constant(powValue(base->value, exponent->value));
  if (exponent->isZero() || base->isOne()) return one_;
  if (exponent->isOne()) return base;
  if (isIntegerConstant(exponent)) {
    if (base->kind == Kind::Pow)
      return pow(base->args[0], scaleExponent(*this, base->args[1], exponent->value));
    if (base->kind == Kind::Mul) {
      MulBuilder m(*this);
      m.power(base, exponent);
      return m.build();
    }
  }
  Node n{};
  n.kind = Kind::Pow;
  n.args = {base, exponent};
  return impl_->intern(std::move(n));
}

}  // namespace qdot::sym
