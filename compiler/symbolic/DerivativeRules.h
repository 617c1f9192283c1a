// Internal: the per-kind derivative rules (Derivative.cpp) and what they see of a node, shared by
// the memoised walk (Context::diff, DirectionalDerivative) and the sparse pass of
// PartialDerivatives (Gradient.cpp).
#pragma once

#include <algorithm>
#include <span>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

/// What the derivative is taken along: rate(s) for every symbol; `mask` has the bits of every
/// symbol whose rate may be non-zero (all bits when rates are only known on demand).
struct Direction {
  uint64_t mask = 0;
  virtual Expr rate(Expr symbol) = 0;

 protected:
  ~Direction() = default;
};

/// What a rule sees: the node and the derivatives of its children, by child number (args, then
/// exps). They come either from a walk's memo (every child that may move, by the direction's mask,
/// is memoised before its parent) or from an explicit list of the children that move.
struct Diff {
  Context& ctx;
  Expr node;
  // Memoised walk:
  Direction* dir = nullptr;
  const NodeMap<Expr>* memo = nullptr;
  // Explicit list (when memo is null): ascending child numbers and their derivatives.
  std::span<const uint32_t> moving;
  std::span<const Expr> movingD;

  bool mayMove(Expr c) const { return (c->symbolMask & dir->mask) != 0; }
  /// Derivative of child i (zero when it does not move).
  Expr d(size_t i) const {
    if (memo) {
      Expr c = child(node, i);
      const Expr* known = mayMove(c) ? memo->find(c) : nullptr;
      return known ? *known : ctx.zero();
    }
    auto at = std::lower_bound(moving.begin(), moving.end(), i);
    return at != moving.end() && *at == i ? movingD[at - moving.begin()] : ctx.zero();
  }
  /// Calls f(i) for each term i of a sum, or factor i of a product (moving if its base, child i, or
  /// its exponent, child m + i, moves), that may move, in ascending order.
  template <class F>
  void forEachMoving(F&& f) const;

  Expr chain(Expr outer, Expr du) const { return du->isZero() ? du : ctx.mul(outer, du); }
  Expr square(Expr u) const { return ctx.pow(u, ctx.constant(2.0)); }
};

template <class F>
void Diff::forEachMoving(F&& f) const {
  size_t m = node->args.size();
  if (memo) {
    for (size_t i = 0; i < m; ++i)
      if (mayMove(node->args[i]) || (!node->exps().empty() && mayMove(node->exps()[i]))) f(i);
    return;
  }
  size_t split = std::lower_bound(moving.begin(), moving.end(), m) - moving.begin();
  for (size_t a = 0, e = split; a < split || e < moving.size();) {  // merge bases and exponents
    size_t ia = a < split ? moving[a] : SIZE_MAX, ie = e < moving.size() ? moving[e] - m : SIZE_MAX;
    size_t i = std::min(ia, ie);
    a += ia == i;
    e += ie == i;
    f(i);
  }
}

/// The derivative of D.node from its children's derivatives. A Symbol asks D.dir for its rate.
Expr applyRule(const Diff& D);

}  // namespace qdot::sym
