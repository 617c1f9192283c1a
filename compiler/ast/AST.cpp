// Out-of-line pieces of the AST: operator spellings and deep copies of expressions.
#include "ast/AST.h"

namespace qdot::ast {
namespace {

ExprPtr cloneOrNull(const ExprPtr& e) { return e ? clone(*e) : nullptr; }

std::vector<ExprPtr> cloneAll(const std::vector<ExprPtr>& v) {
  std::vector<ExprPtr> out;
  out.reserve(v.size());
  for (const auto& e : v) out.push_back(cloneOrNull(e));
  return out;
}

std::unique_ptr<NameExpr> cloneName(const NameExpr& n) {
  return std::make_unique<NameExpr>(n.range, n.parts, n.partRanges);
}

std::vector<Iterator> cloneIterators(const std::vector<Iterator>& its) {
  std::vector<Iterator> out;
  for (const auto& it : its) out.push_back({it.name, it.nameRange, cloneOrNull(it.range)});
  return out;
}

ExprPtr cloneCall(const CallExpr& c) {
  std::vector<NamedArg> named;
  for (const auto& a : c.namedArgs) named.push_back({a.name, a.nameRange, cloneOrNull(a.value)});
  auto callee = c.callee ? cloneName(*c.callee) : nullptr;
  return std::make_unique<CallExpr>(c.range, std::move(callee), cloneAll(c.args), std::move(named));
}

}  // namespace

const char* spelling(BinaryOp op) {
  switch (op) {
    case BinaryOp::Add: return "+";
    case BinaryOp::Sub: return "-";
    case BinaryOp::Mul: return "*";
    case BinaryOp::Div: return "/";
    case BinaryOp::Pow: return "^";
    case BinaryOp::Lt: return "<";
    case BinaryOp::Le: return "<=";
    case BinaryOp::Gt: return ">";
    case BinaryOp::Ge: return ">=";
    case BinaryOp::Eq: return "==";
    case BinaryOp::Ne: return "<>";
    case BinaryOp::And: return "and";
    case BinaryOp::Or: return "or";
  }
  return "?";
}

ExprPtr clone(const Expr& e) {
  switch (e.kind) {
    case ExprKind::Number: {
      auto& n = *cast<NumberExpr>(&e);
      return std::make_unique<NumberExpr>(n.range, n.value, n.isInteger);
    }
    case ExprKind::Bool: return std::make_unique<BoolExpr>(e.range, cast<BoolExpr>(&e)->value);
    case ExprKind::String: return std::make_unique<StringExpr>(e.range, cast<StringExpr>(&e)->value);
    case ExprKind::Name: return cloneName(*cast<NameExpr>(&e));
    case ExprKind::Member: {
      auto& m = *cast<MemberExpr>(&e);
      return std::make_unique<MemberExpr>(m.range, cloneOrNull(m.base), m.field, m.fieldRange);
    }
    case ExprKind::Index: {
      auto& i = *cast<IndexExpr>(&e);
      return std::make_unique<IndexExpr>(i.range, cloneOrNull(i.base), cloneAll(i.subscripts));
    }
    case ExprKind::Unary: {
      auto& u = *cast<UnaryExpr>(&e);
      return std::make_unique<UnaryExpr>(u.range, u.op, cloneOrNull(u.operand));
    }
    case ExprKind::Binary: {
      auto& b = *cast<BinaryExpr>(&e);
      return std::make_unique<BinaryExpr>(b.range, b.op, b.opRange, cloneOrNull(b.lhs), cloneOrNull(b.rhs));
    }
    case ExprKind::Call: return cloneCall(*cast<CallExpr>(&e));
    case ExprKind::Range: {
      auto& r = *cast<RangeExpr>(&e);
      return std::make_unique<RangeExpr>(r.range, cloneOrNull(r.start), cloneOrNull(r.step), cloneOrNull(r.stop));
    }
    case ExprKind::Array: return std::make_unique<ArrayExpr>(e.range, cloneAll(cast<ArrayExpr>(&e)->elements));
    case ExprKind::Comprehension: {
      auto& c = *cast<ComprehensionExpr>(&e);
      return std::make_unique<ComprehensionExpr>(c.range, cloneOrNull(c.body), cloneIterators(c.iterators));
    }
    case ExprKind::If: {
      auto& i = *cast<IfExpr>(&e);
      return std::make_unique<IfExpr>(i.range, cloneAll(i.conditions), cloneAll(i.values), cloneOrNull(i.elseValue));
    }
    case ExprKind::End: return std::make_unique<EndExpr>(e.range);
  }
  return nullptr;
}

}  // namespace qdot::ast
