// Numeric evaluation: applyKind (the one switch over kinds, shared with constant folding) and the
// Evaluator tape: roots are flattened once into post-order slots, then each run is a single loop
// over the tape, so DAGs cost their distinct-node count and deep expressions need no recursion.
#include <limits>
#include <stdexcept>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

double powValue(double base, double exponent) {
  if (exponent == 1.0) return base;
  if (exponent == 2.0) return base * base;
  if (exponent == -1.0) return 1.0 / base;
  if (exponent == 0.5) return std::sqrt(base);
  return std::pow(base, exponent);
}

double applyKind(Kind k, double a, double b, double c) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  switch (k) {
    case Kind::Constant:
    case Kind::Symbol:
    case Kind::Add:
    case Kind::Mul:
      return nan;  // need the node (value, coefficients); handled by the callers
    case Kind::Pow: return powValue(a, b);
    case Kind::Sin: return std::sin(a);
    case Kind::Cos: return std::cos(a);
    case Kind::Tan: return std::tan(a);
    case Kind::Asin: return std::asin(a);
    case Kind::Acos: return std::acos(a);
    case Kind::Atan: return std::atan(a);
    case Kind::Sinh: return std::sinh(a);
    case Kind::Cosh: return std::cosh(a);
    case Kind::Tanh: return std::tanh(a);
    case Kind::Exp: return std::exp(a);
    case Kind::Log: return std::log(a);
    case Kind::Abs: return std::fabs(a);
    case Kind::Sign: return a > 0.0 ? 1.0 : (a < 0.0 ? -1.0 : (a == 0.0 ? 0.0 : a));
    case Kind::Atan2: return std::atan2(a, b);
    case Kind::Min: return std::fmin(a, b);
    case Kind::Max: return std::fmax(a, b);
    case Kind::Lt: return a < b ? 1.0 : 0.0;
    case Kind::Le: return a <= b ? 1.0 : 0.0;
    case Kind::Eq: return a == b ? 1.0 : 0.0;
    case Kind::Ne: return a != b ? 1.0 : 0.0;
    case Kind::And: return a != 0.0 && b != 0.0 ? 1.0 : 0.0;
    case Kind::Or: return a != 0.0 || b != 0.0 ? 1.0 : 0.0;
    case Kind::Not: return a == 0.0 ? 1.0 : 0.0;
    case Kind::Select: return a != 0.0 ? b : c;
  }
  return nan;
}

double unaryValue(Kind k, double x) { return applyKind(k, x); }

Evaluator::Evaluator(std::span<const Expr> roots) {
  PostOrder po = postOrder(roots);
  nodes_ = std::move(po.order);
  argStart_.reserve(nodes_.size() + 1);
  for (Expr n : nodes_) {
    argStart_.push_back(static_cast<uint32_t>(argSlots_.size()));
    for (size_t i = 0; i < childCount(n); ++i) argSlots_.push_back(*po.index.find(child(n, i)));
    if (n->isSymbol()) minValues_ = std::max(minValues_, n->symbolId + 1);
  }
  argStart_.push_back(static_cast<uint32_t>(argSlots_.size()));
  for (Expr r : roots) roots_.push_back(*po.index.find(r));
  slots_.resize(nodes_.size());
}

void Evaluator::run(std::span<const double> values, std::span<double> out) {
  if (values.size() < minValues_) throw std::invalid_argument("evaluate: fewer values than symbols");
  if (out.size() < roots_.size()) throw std::invalid_argument("evaluate: output span too small");
  for (size_t i = 0; i < nodes_.size(); ++i) {
    Expr n = nodes_[i];
    const uint32_t* a = argSlots_.data() + argStart_[i];
    double v;
    if (n->kind == Kind::Constant) {
      v = n->value;
    } else if (n->kind == Kind::Symbol) {
      v = values[n->symbolId];
    } else if (n->kind == Kind::Add) {
      v = n->value;
      for (size_t j = 0; j < n->args.size(); ++j) v += n->coefs()[j] * slots_[a[j]];
    } else if (n->kind == Kind::Mul) {
      v = n->value;
      size_t m = n->args.size();
      for (size_t j = 0; j < m; ++j) v *= powValue(slots_[a[j]], slots_[a[m + j]]);
    } else {
      size_t k = argStart_[i + 1] - argStart_[i];
      v = applyKind(n->kind, k > 0 ? slots_[a[0]] : 0.0, k > 1 ? slots_[a[1]] : 0.0, k > 2 ? slots_[a[2]] : 0.0);
    }
    slots_[i] = v;
  }
  for (size_t r = 0; r < roots_.size(); ++r) out[r] = slots_[roots_[r]];
}

double evaluate(Expr e, std::span<const double> values) {
  double out = 0.0;
  Evaluator(std::span<const Expr>(&e, 1)).run(values, std::span<double>(&out, 1));
  return out;
}

void evaluate(std::span<const Expr> roots, std::span<const double> values, std::span<double> out) {
  Evaluator(roots).run(values, out);
}

}  // namespace qdot::sym
