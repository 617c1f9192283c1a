// Helpers shared by the syntax tests: parse a string, find diagnostics by position, and print an
// expression as a fully parenthesised S-expression so tests can check the tree's shape.
#pragma once

#include <gtest/gtest.h>

#include <memory>
#include <sstream>
#include <string>

#include "ast/AST.h"
#include "ast/ASTPrinter.h"
#include "support/Diagnostic.h"
#include "syntax/Parser.h"

namespace qdot::testing {

/// One parsed buffer with everything needed to inspect it.
struct Parsed {
  SourceManager sm;
  DiagnosticEngine diags;
  uint32_t file = 0;
  std::unique_ptr<ast::StoredDefinition> def;

  /// All diagnostics rendered as the driver would print them.
  std::string rendered() const {
    std::ostringstream os;
    diags.render(os, sm);
    return os.str();
  }
  /// "line:col" of a diagnostic's primary range.
  std::string where(const Diagnostic& d) const {
    LineCol lc = sm.lineCol(d.range.file, d.range.begin);
    return std::to_string(lc.line) + ":" + std::to_string(lc.col);
  }
  /// "line:col" of a range.
  std::string where(SourceRange r) const {
    LineCol lc = sm.lineCol(r.file, r.begin);
    return std::to_string(lc.line) + ":" + std::to_string(lc.col);
  }
  const ast::ClassDef& cls(size_t i = 0) const { return *def->classes.at(i); }
};

inline std::unique_ptr<Parsed> parseText(const std::string& text, size_t errorLimit = 50) {
  auto p = std::make_unique<Parsed>();
  p->diags = DiagnosticEngine(errorLimit);
  p->file = p->sm.addBuffer("test.qd", text);
  p->def = syntax::parse(p->sm, p->file, p->diags);
  return p;
}

/// Fully parenthesised prefix form: (+ a (* b c)), (call der x), (index x i), (neg x).
inline std::string sexpr(const ast::Expr* e) {
  using namespace ast;
  if (!e) return "<null>";
  auto list = [](const std::string& head, const std::vector<ExprPtr>& v) {
    std::string s = "(";
    s += head;
    for (const auto& x : v) s.append(" ").append(sexpr(x.get()));
    return s + ")";
  };
  switch (e->kind) {
    case ExprKind::Number: case ExprKind::Bool: case ExprKind::String: case ExprKind::Name: case ExprKind::End:
      return toSource(*e);
    case ExprKind::Member: return "(. " + sexpr(cast<MemberExpr>(e)->base.get()) + " " + cast<MemberExpr>(e)->field + ")";
    case ExprKind::Index: {
      auto* i = cast<IndexExpr>(e);
      return list("index " + sexpr(i->base.get()), i->subscripts);
    }
    case ExprKind::Unary: {
      auto* u = cast<UnaryExpr>(e);
      const char* op = u->op == UnaryOp::Neg ? "neg" : u->op == UnaryOp::Plus ? "pos" : "not";
      return std::string("(") + op + " " + sexpr(u->operand.get()) + ")";
    }
    case ExprKind::Binary: {
      auto* b = cast<BinaryExpr>(e);
      return std::string("(") + spelling(b->op) + " " + sexpr(b->lhs.get()) + " " + sexpr(b->rhs.get()) + ")";
    }
    case ExprKind::Call: {
      auto* c = cast<CallExpr>(e);
      std::string s = list("call " + c->callee->dotted(), c->args);
      s.pop_back();
      for (const auto& a : c->namedArgs) s += " " + a.name + "=" + sexpr(a.value.get());
      return s + ")";
    }
    case ExprKind::Range: {
      auto* r = cast<RangeExpr>(e);
      if (!r->start && !r->stop) return "(:)";
      std::string s = "(: " + sexpr(r->start.get());
      if (r->step) s += " " + sexpr(r->step.get());
      return s + " " + sexpr(r->stop.get()) + ")";
    }
    case ExprKind::Array: return list("array", cast<ArrayExpr>(e)->elements);
    case ExprKind::Comprehension: {
      auto* c = cast<ComprehensionExpr>(e);
      std::string s = "(for " + sexpr(c->body.get());
      for (const auto& it : c->iterators) s += " " + it.name + "=" + sexpr(it.range.get());
      return s + ")";
    }
    case ExprKind::If: {
      auto* i = cast<IfExpr>(e);
      std::string s = "(if";
      for (size_t k = 0; k < i->conditions.size(); ++k)
        s.append(" ").append(sexpr(i->conditions[k].get())).append(" ").append(sexpr(i->values[k].get()));
      return s.append(" ").append(sexpr(i->elseValue.get())).append(")");
    }
  }
  return "?";
}

/// Parses `text` as the binding of a declaration and returns its S-expression, or the rendered
/// diagnostics if there were errors.
inline std::string exprShape(const std::string& text) {
  auto p = parseText("model M\n  Real v = " + text + ";\nend M;\n");
  if (p->diags.hasErrors()) return "ERROR: " + p->rendered();
  return sexpr(p->cls().declarations.at(0).binding.get());
}

}  // namespace qdot::testing
