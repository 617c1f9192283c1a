// Impl::rebuild: the node of the same kind over new children, re-simplified through the canonical
// constructors. Used by substitute and CSE; one switch over kinds without a default.
#include <algorithm>
#include <stdexcept>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

Expr Context::Impl::rebuild(Expr n, std::span<const Expr> kids) {
  bool same = true;
  for (size_t i = 0; i < kids.size() && same; ++i) same = kids[i] == child(n, i);
  if (same) return n;
  switch (n->kind) {
    case Kind::Constant:
    case Kind::Symbol: return n;
    case Kind::Add: {
      AddBuilder sum(ctx);
      sum.addConstant(n->value);
      for (size_t i = 0; i < n->args.size(); ++i) sum.add(n->coefs()[i], kids[i]);
      return sum.build();
    }
    case Kind::Mul: {
      MulBuilder product(ctx, n->value);
      size_t m = n->args.size();
      for (size_t i = 0; i < m; ++i) product.power(kids[i], kids[m + i]);
      return product.build();
    }
    case Kind::Pow: return ctx.pow(kids[0], kids[1]);
    case Kind::Sin:
    case Kind::Cos:
    case Kind::Tan:
    case Kind::Asin:
    case Kind::Acos:
    case Kind::Atan:
    case Kind::Sinh:
    case Kind::Cosh:
    case Kind::Tanh:
    case Kind::Exp:
    case Kind::Log:
    case Kind::Abs:
    case Kind::Sign:
    case Kind::Not: return ctx.unary(n->kind, kids[0]);
    case Kind::Atan2:
    case Kind::Min:
    case Kind::Max:
    case Kind::Lt:
    case Kind::Le:
    case Kind::Eq:
    case Kind::Ne:
    case Kind::And:
    case Kind::Or: return ctx.binary(n->kind, kids[0], kids[1]);
    case Kind::Select: return ctx.select(kids[0], kids[1], kids[2]);
  }
  throw std::logic_error("rebuild: corrupt node kind");
}

}  // namespace qdot::sym
