// --exact: the right side is parsed as the binding of a declaration in a one-line wrapper model
// (the parser's only entry point is a whole file), and its diagnostics are moved back into a buffer
// holding what the user typed, so a caret points into the --exact text itself.
#include "driver/WorkPrecisionExact.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "syntax/Parser.h"

namespace qdot::driver {
namespace {

constexpr std::string_view kWrapperHead = "model QdotExact\n  Real value = ";
constexpr std::string_view kWrapperTail = ";\nend QdotExact;\n";

struct Function {
  std::size_t arity;
  std::function<double(const std::vector<double>&)> apply;
};

const std::map<std::string, Function, std::less<>>& functions() {
  using A = const std::vector<double>&;
  static const std::map<std::string, Function, std::less<>> table = {
      {"sin", {1, [](A a) { return std::sin(a[0]); }}},      {"cos", {1, [](A a) { return std::cos(a[0]); }}},
      {"tan", {1, [](A a) { return std::tan(a[0]); }}},      {"asin", {1, [](A a) { return std::asin(a[0]); }}},
      {"acos", {1, [](A a) { return std::acos(a[0]); }}},    {"atan", {1, [](A a) { return std::atan(a[0]); }}},
      {"atan2", {2, [](A a) { return std::atan2(a[0], a[1]); }}},
      {"sinh", {1, [](A a) { return std::sinh(a[0]); }}},    {"cosh", {1, [](A a) { return std::cosh(a[0]); }}},
      {"tanh", {1, [](A a) { return std::tanh(a[0]); }}},    {"exp", {1, [](A a) { return std::exp(a[0]); }}},
      {"log", {1, [](A a) { return std::log(a[0]); }}},      {"log10", {1, [](A a) { return std::log10(a[0]); }}},
      {"sqrt", {1, [](A a) { return std::sqrt(a[0]); }}},    {"abs", {1, [](A a) { return std::abs(a[0]); }}},
      {"sign", {1, [](A a) { return double((a[0] > 0) - (a[0] < 0)); }}},
      {"min", {2, [](A a) { return std::min(a[0], a[1]); }}}, {"max", {2, [](A a) { return std::max(a[0], a[1]); }}},
  };
  return table;
}

/// Walks an expression: with `diags`, reports what cannot be evaluated (the check); without, computes.
class Evaluator {
 public:
  Evaluator(double time, const NameValues& names, DiagnosticEngine* diags) : time_(time), names_(names), diags_(diags) {}

  double value(const ast::Expr& e) {
    using K = ast::ExprKind;
    switch (e.kind) {
      case K::Number: return ast::cast<ast::NumberExpr>(&e)->value;
      case K::Name: return name(ast::cast<ast::NameExpr>(&e)->dotted(), e.range);
      case K::Index: return element(*ast::cast<ast::IndexExpr>(&e));
      case K::Unary: return unary(*ast::cast<ast::UnaryExpr>(&e));
      case K::Binary: return binary(*ast::cast<ast::BinaryExpr>(&e));
      case K::Call: return call(*ast::cast<ast::CallExpr>(&e));
      case K::If: return choice(*ast::cast<ast::IfExpr>(&e));
      default: return unsupported(e.range);
    }
  }

 private:
  double name(const std::string& text, SourceRange range) {
    if (text == "time") return time_;
    if (text == "pi") return M_PI;
    if (auto it = names_.find(text); it != names_.end()) return it->second;
    if (diags_)
      diags_->error(range, DiagCode::E0202, fmt::format("unknown name '{}' in an exact solution", text),
                    "an exact solution may use time, pi and the model's parameters (qdot equations lists them)");
    return 0;
  }

  // m[2] or m[1, 2]: a parameter array element, by its name in the parameter list.
  double element(const ast::IndexExpr& e) {
    const auto* base = ast::dyn_cast<ast::NameExpr>(e.base.get());
    std::string text = base ? base->dotted() + "[" : "";
    for (std::size_t i = 0; base && i < e.subscripts.size(); ++i) {
      const auto* n = ast::dyn_cast<ast::NumberExpr>(e.subscripts[i].get());
      if (!n || !n->isInteger) return unsupported(e.subscripts[i]->range);
      text += fmt::format("{}{}", i ? "," : "", static_cast<long>(n->value));
    }
    if (!base) return unsupported(e.range);
    return name(text + "]", e.range);
  }

  double unary(const ast::UnaryExpr& e) {
    double v = value(*e.operand);
    if (e.op == ast::UnaryOp::Not) return v == 0;
    return e.op == ast::UnaryOp::Neg ? -v : v;
  }

  double binary(const ast::BinaryExpr& e) {
    double a = value(*e.lhs), b = value(*e.rhs);
    using O = ast::BinaryOp;
    switch (e.op) {
      case O::Add: return a + b;
      case O::Sub: return a - b;
      case O::Mul: return a * b;
      case O::Div: return a / b;
      case O::Pow: return std::pow(a, b);
      case O::Lt: return a < b;
      case O::Le: return a <= b;
      case O::Gt: return a > b;
      case O::Ge: return a >= b;
      case O::Eq: return a == b;
      case O::Ne: return a != b;
      case O::And: return a != 0 && b != 0;
      case O::Or: return a != 0 || b != 0;
    }
    return 0;
  }

  double call(const ast::CallExpr& e) {
    std::string callee = e.callee->dotted();
    auto it = functions().find(callee);
    if (it == functions().end()) {
      if (diags_)
        diags_->error(e.callee->range, DiagCode::E0210, fmt::format("unknown function '{}' in an exact solution", callee),
                      "the functions are sin, cos, tan, asin, acos, atan, atan2, sinh, cosh, tanh, exp, log, log10, "
                      "sqrt, abs, sign, min, max");
      return 0;
    }
    if (e.args.size() != it->second.arity || !e.namedArgs.empty()) {
      if (diags_)
        diags_->error(e.range, DiagCode::E0212,
                      fmt::format("{} takes {} argument{}", callee, it->second.arity, it->second.arity == 1 ? "" : "s"));
      return 0;
    }
    std::vector<double> args;
    for (const ast::ExprPtr& a : e.args) args.push_back(value(*a));
    return it->second.apply(args);
  }

  double choice(const ast::IfExpr& e) {
    double chosen = 0;
    bool found = false;
    for (std::size_t i = 0; i < e.conditions.size(); ++i) {
      bool holds = value(*e.conditions[i]) != 0;
      double v = value(*e.values[i]);  // every branch is walked, so the check sees them all
      if (holds && !found) chosen = v, found = true;
    }
    double otherwise = value(*e.elseValue);
    return found ? chosen : otherwise;
  }

  double unsupported(SourceRange range) {
    if (diags_)
      diags_->error(range, DiagCode::E0290, "an exact solution is a scalar expression",
                    "use numbers, time, pi, parameters (m[2] for an element), + - * / ^, functions and if-expressions");
    return 0;
  }

  double time_;
  const NameValues& names_;
  DiagnosticEngine* diags_;
};

/// Moves a diagnostic of the wrapper model (file `wrapper`, the expression at `head`) into the
/// --exact buffer (the expression at `valueBegin`), clamping ranges that fall on the wrapper's text.
Diagnostic relocated(Diagnostic d, uint32_t exactFile, uint32_t valueBegin, uint32_t valueLength) {
  auto move = [&](uint32_t offset) {
    uint32_t head = static_cast<uint32_t>(kWrapperHead.size());
    uint32_t within = offset < head ? 0 : std::min(offset - head, valueLength);
    return valueBegin + within;
  };
  if (d.range.valid()) d.range = {exactFile, move(d.range.begin), move(d.range.end)};
  d.notes.clear();  // notes point at the wrapper model, which the user never wrote
  return d;
}

const ast::Expr* bindingOf(const ast::StoredDefinition& tree) {
  if (tree.classes.empty() || tree.classes.front()->declarations.empty()) return nullptr;
  return tree.classes.front()->declarations.front().binding.get();
}

}  // namespace

std::optional<ExactSolution> parseExact(const std::string& text, const std::vector<std::string>& columns,
                                        const NameValues& names, SourceManager& sources, DiagnosticEngine& diags) {
  uint32_t file = sources.addBuffer("--exact", text);
  std::size_t eq = text.find('=');
  if (eq == std::string::npos) {
    diags.error({file, 0, static_cast<uint32_t>(text.size())}, DiagCode::E0290,
                "--exact expects NAME = EXPRESSION", "e.g. --exact 'x = 0.05*cos(20*time)'");
    return std::nullopt;
  }
  ExactSolution exact;
  std::size_t first = text.find_first_not_of(" \t");
  std::size_t last = text.find_last_not_of(" \t", eq == 0 ? 0 : eq - 1);
  exact.column = first < eq ? text.substr(first, last + 1 - first) : "";
  if (std::find(columns.begin(), columns.end(), exact.column) == columns.end()) {
    uint32_t b = static_cast<uint32_t>(first < eq ? first : 0), e = static_cast<uint32_t>(first < eq ? last + 1 : eq);
    diags.error({file, b, e}, DiagCode::E0202, fmt::format("'{}' is not a result column of the model", exact.column),
                "the left side names a variable or output, as in the CSV header of qdot run (e.g. x, der(x))");
    return std::nullopt;
  }
  std::string value = text.substr(eq + 1);
  SourceManager wrapperSources;
  uint32_t wrapper = wrapperSources.addBuffer("--exact", std::string(kWrapperHead) + value + std::string(kWrapperTail));
  DiagnosticEngine wrapperDiags;
  std::shared_ptr<ast::StoredDefinition> tree = syntax::parse(wrapperSources, wrapper, wrapperDiags);
  const ast::Expr* expr = wrapperDiags.hasErrors() ? nullptr : bindingOf(*tree);
  if (expr) Evaluator(0.0, names, &wrapperDiags).value(*expr);  // the check: names, functions, forms
  else if (!wrapperDiags.hasErrors())  // e.g. a right side that ends the declaration early
    wrapperDiags.error({wrapper, static_cast<uint32_t>(kWrapperHead.size()), static_cast<uint32_t>(kWrapperHead.size())},
                       DiagCode::E0290, "--exact expects an expression after '='", "e.g. --exact 'x = 0.05*cos(20*time)'");
  for (const Diagnostic& d : wrapperDiags.diagnostics())
    diags.report(relocated(d, file, static_cast<uint32_t>(eq + 1), static_cast<uint32_t>(value.size())));
  if (wrapperDiags.hasErrors() || !expr) return std::nullopt;
  exact.tree = std::move(tree);
  exact.value = expr;
  return exact;
}

double evaluateExact(const ExactSolution& exact, double time, const NameValues& names) {
  return Evaluator(time, names, nullptr).value(*exact.value);
}

}  // namespace qdot::driver
