// Context::unary / binary / select: elementary functions, comparisons, logic and if-expressions.
// Folds constant arguments (with the same numeric code as evaluation), applies identities that hold
// for every non-NaN value (min(a, a) = a, a < a = 0, x and 0 = 0, ...) and orders the arguments of
// commutative kinds (min, max, ==, <>, and, or) so that min(x, y) and min(y, x) are one node.
#include <stdexcept>
#include <string>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

bool isUnaryKind(Kind k) { return kindArity(k) == 1; }
bool isBinaryKind(Kind k) { return kindArity(k) == 2 && k != Kind::Pow; }
bool isCommutative(Kind k) {
  return k == Kind::Min || k == Kind::Max || k == Kind::Eq || k == Kind::Ne || k == Kind::And ||
         k == Kind::Or;
}

// Result of k(a, a) for a non-NaN a, or nullptr if it does not simplify.
Expr sameArgument(Context& ctx, Kind k, Expr a) {
  if (k == Kind::Min || k == Kind::Max) return a;
  if (k == Kind::Lt || k == Kind::Ne) return ctx.zero();
  if (k == Kind::Le || k == Kind::Eq) return ctx.one();
  return nullptr;
}

// Result when one argument of and/or is a constant that decides it, or nullptr.
Expr absorbingLogic(Context& ctx, Kind k, Expr a, Expr b) {
  for (Expr c : {a, b}) {
    if (!c->isConstant()) continue;
    if (k == Kind::And && c->value == 0.0) return ctx.zero();
    if (k == Kind::Or && c->value != 0.0) return ctx.one();
  }
  return nullptr;
}

}  // namespace

Expr Context::unary(Kind k, Expr x) {
  if (!isUnaryKind(k)) throw std::invalid_argument(std::string("unary: not a unary kind: ") + kindSpelling(k));
  if (x->isConstant()) return constant(applyKind(k, x->value));
  NodeKey n{};
  n.kind = k;
  n.args = {&x, 1};
  return impl_->intern(n);
}

Expr Context::binary(Kind k, Expr a, Expr b) {
  if (!isBinaryKind(k)) throw std::invalid_argument(std::string("binary: not a binary kind: ") + kindSpelling(k));
  if (a->isConstant() && b->isConstant()) return constant(applyKind(k, a->value, b->value));
  if (a == b)
    if (Expr r = sameArgument(*this, k, a)) return r;
  if (Expr r = absorbingLogic(*this, k, a, b)) return r;
  if (isCommutative(k) && structuralCompare(b, a) < 0) std::swap(a, b);
  Expr args[] = {a, b};
  NodeKey n{};
  n.kind = k;
  n.args = args;
  return impl_->intern(n);
}

Expr Context::select(Expr cond, Expr ifTrue, Expr ifFalse) {
  if (cond->isConstant()) return cond->value != 0.0 ? ifTrue : ifFalse;
  if (ifTrue == ifFalse) return ifTrue;
  Expr args[] = {cond, ifTrue, ifFalse};
  NodeKey n{};
  n.kind = Kind::Select;
  n.args = args;
  return impl_->intern(n);
}

}  // namespace qdot::sym
