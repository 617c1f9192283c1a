// toString: Modelica-like infix text with minimal parentheses, written by an explicit task stack
// (no recursion, output-linear time). Sums print as `a - 2*b + 1` (constant last), products as
// `-a*b`, negative constant powers as division `a/(b*c)`, x^0.5 as `sqrt(x)`, selects as
// `if c then a else b`. Term and factor order is the canonical (structural) order of the node.
#include <cmath>
#include <deque>
#include <functional>
#include <string_view>
#include <vector>

#include "symbolic/ContextImpl.h"
#include "qdot/number_text.hpp"

namespace qdot::sym {

namespace {

// Precedence levels, loosest first.
enum Prec : int { IfExpr, OrP, AndP, NotP, Relation, Additive, Multiplicative, Power, Primary };

bool isNegativeConstant(Expr e) { return e->isConstant() && e->value < 0.0; }

int precedence(Expr n) {
  switch (n->kind) {
    case Kind::Constant: return n->value < 0.0 ? Additive : Primary;
    case Kind::Symbol: return Primary;
    case Kind::Add: return Additive;
    case Kind::Mul: return n->value < 0.0 ? Additive : Multiplicative;
    case Kind::Pow:
      if (isNegativeConstant(n->args[1])) return Multiplicative;
      return n->args[1]->isConstant() && n->args[1]->value == 0.5 ? Primary : Power;
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
    case Kind::Atan2:
    case Kind::Min:
    case Kind::Max: return Primary;
    case Kind::Lt:
    case Kind::Le:
    case Kind::Eq:
    case Kind::Ne: return Relation;
    case Kind::And: return AndP;
    case Kind::Or: return OrP;
    case Kind::Not: return NotP;
    case Kind::Select: return IfExpr;
  }
  return Primary;
}

// A pending piece of output: text (a literal, a symbol name or a number kept by the Printer), or a
// node to print at a minimum precedence.
struct Task {
  std::string_view text;
  Expr node = nullptr;
  int minPrec = 0;
};

class Printer {
 public:
  explicit Printer(const Context& ctx) : ctx_(ctx) {}
  /// Prints the terms of the sum `s` ordered by group(term) (stable: canonical order within one).
  Printer(const Context& ctx, Expr s, const std::function<int(Expr)>& group) : ctx_(ctx), grouped_(s), group_(&group) {}

  std::string run(Expr root) {
    stack_.push_back({"", root, IfExpr});
    while (!stack_.empty()) {
      Task t = stack_.back();
      stack_.pop_back();
      if (t.node)
        expand(t.node, t.minPrec);
      else
        out_ += t.text;
    }
    return std::move(out_);
  }

 private:
  void text(std::string_view s) { seq_.push_back({s, nullptr, 0}); }
  void numberText(double v) { text(numbers_.emplace_back(shortestText(v))); }
  void node(Expr n, int minPrec) { seq_.push_back({{}, n, minPrec}); }

  // Schedules the pieces of n (in reading order) on the stack.
  void expand(Expr n, int minPrec) {
    seq_.clear();
    bool parens = precedence(n) < minPrec;
    if (parens) text("(");
    body(n);
    if (parens) text(")");
    stack_.insert(stack_.end(), seq_.rbegin(), seq_.rend());
  }

  // base^exp for a factor of a product; expValue is the (positive) exponent when constant.
  void power(Expr base, Expr exp, double expValue) {
    if (!exp && expValue == 1.0) return node(base, Power);
    if (!exp && expValue == 0.5) {
      text("sqrt(");
      node(base, IfExpr);
      return text(")");
    }
    node(base, Primary);
    text("^");
    if (exp)
      node(exp, Primary);
    else
      numberText(expValue);
  }

  // |coef| * Π b_i^e_i with negative constant exponents moved to a denominator.
  void product(double absCoef, std::span<const Expr> bases, std::span<const Expr> exps) {
    bool any = false;
    if (absCoef != 1.0) numberText(absCoef), any = true;
    size_t denominators = 0;
    for (size_t i = 0; i < bases.size(); ++i) {
      if (isNegativeConstant(exps[i])) {
        ++denominators;
        continue;
      }
      if (any) text("*");
      power(bases[i], exps[i]->isConstant() ? nullptr : exps[i], exps[i]->value);
      any = true;
    }
    if (!any) text("1");
    if (!denominators) return;
    text(denominators > 1 ? "/(" : "/");
    bool first = true;
    for (size_t i = 0; i < bases.size(); ++i) {
      if (!isNegativeConstant(exps[i])) continue;
      if (!first) text("*");
      power(bases[i], nullptr, -exps[i]->value);
      first = false;
    }
    if (denominators > 1) text(")");
  }

  // One term of a sum with its coefficient's magnitude (the sign is printed by the caller).
  void term(double absCoef, Expr t) {
    if (t->kind == Kind::Mul) return product(absCoef, t->args, t->exps());  // coefficient is 1
    if (t->kind == Kind::Pow) return product(absCoef, std::span<const Expr>(&t->args[0], 1),
                                             std::span<const Expr>(&t->args[1], 1));
    if (absCoef == 1.0) return node(t, Multiplicative);
    Expr one = ctx_.one();
    product(absCoef, std::span<const Expr>(&t, 1), std::span<const Expr>(&one, 1));
  }

  void sum(Expr n) {
    std::vector<size_t> order(n->args.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    if (n == grouped_) {
      std::vector<int> g(order.size());
      for (size_t i = 0; i < order.size(); ++i) g[i] = (*group_)(n->args[i]);
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return g[a] < g[b]; });
    }
    for (size_t k = 0; k < order.size(); ++k) {
      size_t i = order[k];
      double c = n->coefs()[i];
      if (k > 0) text(c < 0.0 ? " - " : " + ");
      else if (c < 0.0) text("-");
      term(std::fabs(c), n->args[i]);
    }
    if (n->value == 0.0) return;
    text(n->value < 0.0 ? " - " : " + ");
    numberText(std::fabs(n->value));
  }

  void call(Expr n) {
    text(kindSpelling(n->kind));
    text("(");
    for (size_t i = 0; i < n->args.size(); ++i) {
      if (i) text(", ");
      node(n->args[i], IfExpr);
    }
    text(")");
  }

  void infix(Expr n, const char* op, int leftPrec, int rightPrec) {
    node(n->args[0], leftPrec);
    text(op);
    node(n->args[1], rightPrec);
  }

  void body(Expr n) {
    switch (n->kind) {
      case Kind::Constant: return numberText(n->value);
      case Kind::Symbol: return text(ctx_.symbolName(n));
      case Kind::Add: return sum(n);
      case Kind::Mul:
        if (n->value < 0.0) text("-");
        return product(std::fabs(n->value), n->args, n->exps());
      case Kind::Pow:
        return product(1.0, std::span<const Expr>(&n->args[0], 1), std::span<const Expr>(&n->args[1], 1));
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
      case Kind::Atan2:
      case Kind::Min:
      case Kind::Max: return call(n);
      case Kind::Lt: return infix(n, " < ", Additive, Additive);
      case Kind::Le: return infix(n, " <= ", Additive, Additive);
      case Kind::Eq: return infix(n, " == ", Additive, Additive);
      case Kind::Ne: return infix(n, " <> ", Additive, Additive);
      case Kind::And: return infix(n, " and ", AndP, NotP);
      case Kind::Or: return infix(n, " or ", OrP, AndP);
      case Kind::Not:
        text("not ");
        return node(n->args[0], Relation);
      case Kind::Select:
        text("if ");
        node(n->args[0], OrP);
        text(" then ");
        node(n->args[1], OrP);
        text(" else ");
        return node(n->args[2], IfExpr);
    }
  }

  const Context& ctx_;
  Expr grouped_ = nullptr;
  const std::function<int(Expr)>* group_ = nullptr;
  std::vector<Task> stack_, seq_;
  std::deque<std::string> numbers_;  // storage behind number Tasks (stable addresses)
  std::string out_;
};

}  // namespace

std::string toString(const Context& ctx, Expr e) { return Printer(ctx).run(e); }

std::string toStringGrouped(const Context& ctx, Expr e, const std::function<int(Expr term)>& group) {
  Expr sum = e->kind == Kind::Add ? e : nullptr;
  if (e->kind == Kind::Mul) {
    for (size_t i = 0; i < e->args.size(); ++i) {
      if (e->args[i]->kind != Kind::Add || !e->exps()[i]->isOne()) continue;
      if (sum) return toString(ctx, e);  // two sum factors: no one sum to order
      sum = e->args[i];
    }
  }
  return Printer(ctx, sum, group).run(e);
}

}  // namespace qdot::sym
