// Sema: scope building, declaration checks and name/call checks for one flat model.
// Error codes E02xx (see compiler/sema/README.md).
#include "sema/Sema.h"

#include <algorithm>
#include <functional>

namespace qdot::sema {
namespace {

using namespace qdot::ast;

const BuiltinFunction kBuiltins[] = {
    {"sin", 1, 1},      {"cos", 1, 1},       {"tan", 1, 1},   {"asin", 1, 1},   {"acos", 1, 1},
    {"atan", 1, 1},     {"atan2", 2, 2},     {"sinh", 1, 1},  {"cosh", 1, 1},   {"tanh", 1, 1},
    {"exp", 1, 1},      {"log", 1, 1},       {"log10", 1, 1}, {"sqrt", 1, 1},   {"abs", 1, 1},
    {"sign", 1, 1},     {"min", 1, 2},       {"max", 1, 2},   {"der", 1, 1},    {"sum", 1, 1},
    {"product", 1, 1},  {"fill", 2, -1},     {"zeros", 1, -1}, {"ones", 1, -1}, {"cross", 2, 2},
    {"dot", 2, 2},      {"transpose", 1, 1}, {"diagonal", 1, 1}, {"identity", 1, 1}, {"size", 1, 2},
};

// Names that parse as calls but belong to events, which qdot does not compile.
bool isEventFunction(std::string_view n) {
  return n == "pre" || n == "reinit" || n == "initial" || n == "edge" || n == "sample" || n == "change";
}

std::string typeNameOf(const Declaration& d) {
  std::string s;
  for (size_t i = 0; i < d.typeName.size(); ++i) s += (i ? "." : "") + d.typeName[i];
  return s;
}

/// Walks one model: declarations first (scope), then every expression with iterator scopes.
class Checker {
 public:
  Checker(CheckedModel& m, DiagnosticEngine& diags) : m_(m), diags_(diags) {}

  void run() {
    for (const auto& d : m_.cls->declarations) declare(d);
    for (const auto& e : m_.cls->extends)
      diags_.error(e.range, DiagCode::E0290, "'extends' is not supported yet",
                   "inline the base model: copy its declarations and equations into this model");
    for (const auto* d : m_.declarations) checkDeclaration(*d);
    for (const auto& eq : m_.cls->equations) checkEquation(eq);
    for (const auto& eq : m_.cls->initialEquations) checkEquation(eq);
    for (const auto& st : m_.cls->mechanics) checkMechanics(st);
  }

 private:
  CheckedModel& m_;
  DiagnosticEngine& diags_;
  std::vector<std::string> iterators_;

  void declare(const Declaration& d) {
    auto [it, inserted] = m_.symbols.try_emplace(d.name);
    if (!inserted) {
      auto& diag = diags_.error(d.nameRange, DiagCode::E0201, "'" + d.name + "' is declared twice",
                                "rename one of the two declarations");
      diag.notes.push_back({it->second.decl->nameRange, "first declared here"});
      return;
    }
    ModelSymbol& s = it->second;
    s.decl = &d;
    std::string t = typeNameOf(d);
    s.type = t == "Integer" ? BaseType::Integer : t == "Boolean" ? BaseType::Boolean : BaseType::Real;
    if (d.variability == Variability::Constant) s.kind = SymbolKind::Constant;
    else if (d.causality == Causality::Input && !d.binding && d.variability == Variability::Continuous &&
             s.type == BaseType::Real && !d.isCoordinate)
      s.kind = SymbolKind::Input;
    else if (d.variability == Variability::Parameter)
      s.kind = s.type == BaseType::Integer ? SymbolKind::IntegerParameter : SymbolKind::Parameter;
    else if (d.isCoordinate) s.kind = SymbolKind::Coordinate;
    else if (d.binding) s.kind = SymbolKind::Definition;
    else s.kind = SymbolKind::Unknown;
    m_.declarations.push_back(&d);
  }

  void checkDeclaration(const Declaration& d) {
    const ModelSymbol& s = m_.symbols.at(d.name);
    if (s.decl != &d) return;  // duplicate, already reported
    if (!checkType(d)) return;
    for (const auto& dim : d.typeDims) checkSize(*dim);
    for (const auto& dim : d.dims) checkSize(*dim);
    for (const auto& mod : d.mods) checkModification(d, mod);
    if (d.binding) checkExpr(*d.binding);
    checkKindRules(d, s);
  }

  bool checkType(const Declaration& d) {
    std::string t = typeNameOf(d);
    if (t == "Real" || t == "Integer" || t == "Boolean") return true;
    diags_.error(d.typeRange, DiagCode::E0290, "component type '" + t + "' is not supported yet",
                 "write the component's equations in this model instead, with Real, Integer or Boolean variables");
    return false;
  }

  void checkKindRules(const Declaration& d, const ModelSymbol& s) {
    if (d.isFlow)
      diags_.error(d.range, DiagCode::E0290, "'flow' variables are not supported yet",
                   "declare a plain Real and write the balance equation yourself, e.g. i1 + i2 = 0;");
    if (d.causality == Causality::Input && d.isCoordinate)
      diags_.error(d.range, DiagCode::E0206, "a coordinate cannot be an input",
                   "remove 'input', or declare a plain 'input Real' and use it in a force");
    if (d.isCoordinate && s.type != BaseType::Real)
      diags_.error(d.typeRange, DiagCode::E0205, "coordinate '" + d.name + "' must be of type Real",
                   "declare it as: coordinate Real " + d.name + ";");
    if (d.isCoordinate && d.binding)
      diags_.error(d.binding->range, DiagCode::E0206, "coordinate '" + d.name + "' cannot have a binding equation",
                   "give its initial value instead: coordinate Real " + d.name + "(start = ...);");
    if (d.isCoordinate && d.variability != Variability::Continuous)
      diags_.error(d.range, DiagCode::E0206, "a coordinate cannot be a parameter or constant",
                   "remove 'parameter'/'constant' from the declaration of '" + d.name + "'");
    if ((s.kind == SymbolKind::Constant || s.kind == SymbolKind::IntegerParameter ||
         s.kind == SymbolKind::Parameter) && !d.binding)
      diags_.error(d.nameRange, DiagCode::E0207, "parameter '" + d.name + "' has no value",
                   "give it a default value, e.g. parameter Real " + d.name + " = 1;");
    if (s.kind == SymbolKind::Unknown && s.type != BaseType::Real)
      diags_.error(d.typeRange, DiagCode::E0205, "time-varying variable '" + d.name + "' must be of type Real",
                   "make it a parameter, or declare it Real");
  }

  void checkModification(const Declaration& d, const Modification& mod) {
    static const char* kAttrs[] = {"start", "fixed", "min", "max", "nominal", "unit", "displayUnit",
                                   "quantity", "stateSelect"};
    bool known = std::any_of(std::begin(kAttrs), std::end(kAttrs), [&](const char* a) { return mod.name == a; });
    if (!known) {
      diags_.error(mod.nameRange, DiagCode::E0208, "'" + mod.name + "' is not an attribute of '" + d.name + "'",
                   "attributes are start, fixed, min, max, nominal and unit");
      return;
    }
    if (mod.value) checkExpr(*mod.value);
  }

  // Array sizes must be Integer expressions of literals, Integer parameters and constants.
  void checkSize(const Expr& e) {
    checkExpr(e);
    std::string why;
    if (!isIntegerExpr(e, why))
      diags_.error(e.range, DiagCode::E0203, "array size must be an Integer expression" + why,
                   "sizes are integer literals or 'parameter Integer' values, e.g. parameter Integer n = 3;");
  }

  bool isIntegerExpr(const Expr& e, std::string& why) {
    if (auto* n = dyn_cast<NumberExpr>(&e)) return n->isInteger;
    if (auto* n = dyn_cast<NameExpr>(&e)) {
      if (n->parts.size() != 1) return false;
      if (std::find(iterators_.begin(), iterators_.end(), n->parts[0]) != iterators_.end()) return true;
      auto it = m_.symbols.find(n->parts[0]);
      if (it == m_.symbols.end()) return true;  // already reported as unknown
      bool ok = it->second.type == BaseType::Integer &&
                (it->second.kind == SymbolKind::IntegerParameter || it->second.kind == SymbolKind::Constant);
      if (!ok) why = "; '" + n->parts[0] + "' is not an Integer parameter or constant";
      return ok;
    }
    if (auto* u = dyn_cast<UnaryExpr>(&e)) return u->op != UnaryOp::Not && isIntegerExpr(*u->operand, why);
    if (auto* b = dyn_cast<BinaryExpr>(&e))
      return (b->op == BinaryOp::Add || b->op == BinaryOp::Sub || b->op == BinaryOp::Mul) &&
             isIntegerExpr(*b->lhs, why) && isIntegerExpr(*b->rhs, why);
    if (auto* c = dyn_cast<CallExpr>(&e)) return c->callee->dotted() == "size";
    return false;
  }

  void checkEquation(const Equation& eq) {
    switch (eq.kind) {
      case EquationKind::Simple:
        if (eq.lhs) checkExpr(*eq.lhs);
        if (eq.rhs) checkExpr(*eq.rhs);
        return;
      case EquationKind::For:
        withIterators(eq.iterators, [&] { for (const auto& b : eq.body) checkEquation(b); });
        return;
      case EquationKind::Connect:
        diags_.error(eq.range, DiagCode::E0290, "'connect' is not supported yet",
                     "write the equations the connection stands for: equal potentials (v1 = v2;) and flows "
                     "that sum to zero (i1 + i2 = 0;)");
        return;
      case EquationKind::When:
        diags_.error(eq.range, DiagCode::E0290, "'when' equations are not supported yet",
                     "for a switch that depends on the state, write an if-expression: f = if x > 0 then -k*x else 0;");
        return;
      case EquationKind::If:
        diags_.error(eq.range, DiagCode::E0290, "'if' equations are not supported yet",
                     "write the equation with an if-expression: x = if c then a else b;");
        return;
    }
  }

  void checkMechanics(const MechanicsStmt& st) {
    if (st.kind == MechanicsKind::For) {
      withIterators(st.iterators, [&] { for (const auto& b : st.body) checkMechanics(b); });
      return;
    }
    if (st.value) checkExpr(*st.value);
    if (st.rhs) checkExpr(*st.rhs);
    if (st.kind == MechanicsKind::Force && st.target) checkForceTarget(*st.target);
  }

  void checkForceTarget(const Expr& target) {
    checkExpr(target);
    const Expr* base = &target;
    if (auto* ix = dyn_cast<IndexExpr>(base)) base = ix->base.get();
    auto* name = dyn_cast<NameExpr>(base);
    if (!name || name->parts.size() != 1) {
      diags_.error(target.range, DiagCode::E0209, "force(...) must name a coordinate",
                   "write force(q) = expr; or force(q[i]) = expr; with q a coordinate");
      return;
    }
    auto it = m_.symbols.find(name->parts[0]);
    if (it != m_.symbols.end() && it->second.kind != SymbolKind::Coordinate)
      diags_.error(target.range, DiagCode::E0209, "'" + name->parts[0] + "' is not a coordinate",
                   "generalized forces act on coordinates: declare it 'coordinate Real " + name->parts[0] + "'");
  }

  void withIterators(const std::vector<Iterator>& its, const std::function<void()>& body) {
    for (const auto& it : its)
      if (it.range) checkExpr(*it.range);
    for (const auto& it : its) iterators_.push_back(it.name);
    body();
    iterators_.resize(iterators_.size() - its.size());
  }

  void checkName(const NameExpr& n) {
    const std::string& first = n.parts[0];
    if (n.parts.size() > 1) {
      diags_.error(n.range, DiagCode::E0290, "dotted name '" + n.dotted() + "' is not supported yet",
                   "write the component's variables and equations in this model and use their plain names");
      return;
    }
    if (first == "time" || first == "pi") return;
    if (std::find(iterators_.begin(), iterators_.end(), first) != iterators_.end()) return;
    if (m_.symbols.count(first)) return;
    std::vector<std::string> candidates(iterators_);
    for (const auto& [k, v] : m_.symbols) candidates.push_back(k);
    std::string guess = closestName(first, candidates);
    diags_.error(n.partRanges.empty() ? n.range : n.partRanges[0], DiagCode::E0202, "unknown name '" + first + "'",
                 isEnergyKeyword(first) ? "'" + first + " = expr;' states an energy: write it in the mechanics section"
                 : guess.empty()        ? "declare it, e.g. parameter Real " + first + " = 1;"
                                        : "did you mean '" + guess + "'?");
  }

  // The words that start a mechanics statement; written in an equation section they are names.
  static bool isEnergyKeyword(const std::string& name) {
    return name == "kinetic" || name == "potential" || name == "dissipation";
  }

  void checkCall(const CallExpr& c) {
    std::string name = c.callee->dotted();
    for (const auto& na : c.namedArgs)
      diags_.error(na.nameRange, DiagCode::E0211, "named arguments are not allowed in a call to '" + name + "'",
                   "pass the arguments by position");
    if (isEventFunction(name)) {
      diags_.error(c.callee->range, DiagCode::E0290, "'" + name + "' is not supported yet",
                   "events are not available: write the behaviour as an if-expression in an equation");
      return;
    }
    const BuiltinFunction* f = findBuiltin(name);
    if (!f) {
      std::vector<std::string> names;
      for (const auto& b : kBuiltins) names.push_back(b.name);
      std::string guess = closestName(name, names);
      diags_.error(c.callee->range, DiagCode::E0210, "unknown function '" + name + "'",
                   guess.empty() ? "see docs/language.md for the built-in functions"
                                 : "did you mean '" + guess + "'?");
    } else {
      int n = static_cast<int>(c.args.size());
      if (n < f->minArgs || (f->maxArgs >= 0 && n > f->maxArgs))
        diags_.error(c.range, DiagCode::E0212,
                     "'" + name + "' takes " + arityText(*f) + ", but " + std::to_string(n) + " given");
    }
    for (const auto& a : c.args) checkExpr(*a);
  }

  static std::string arityText(const BuiltinFunction& f) {
    auto plural = [](int k) { return std::to_string(k) + (k == 1 ? " argument" : " arguments"); };
    if (f.maxArgs < 0) return "at least " + plural(f.minArgs);
    if (f.minArgs == f.maxArgs) return plural(f.minArgs);
    return std::to_string(f.minArgs) + " or " + plural(f.maxArgs);
  }

  void checkExpr(const Expr& e) {
    switch (e.kind) {
      case ExprKind::Number: case ExprKind::Bool: case ExprKind::End: return;
      case ExprKind::String:
        diags_.error(e.range, DiagCode::E0213, "a string is not allowed here", "strings appear only in descriptions and unit attributes");
        return;
      case ExprKind::Name: return checkName(*cast<NameExpr>(&e));
      case ExprKind::Member:
        diags_.error(e.range, DiagCode::E0290, "component member access is not supported yet",
                     "write the component's variables and equations in this model and use their plain names");
        return;
      case ExprKind::Index: {
        auto* ix = cast<IndexExpr>(&e);
        checkExpr(*ix->base);
        for (const auto& s : ix->subscripts) checkExpr(*s);
        return;
      }
      case ExprKind::Unary: return checkExpr(*cast<UnaryExpr>(&e)->operand);
      case ExprKind::Binary: {
        auto* b = cast<BinaryExpr>(&e);
        checkExpr(*b->lhs);
        checkExpr(*b->rhs);
        return;
      }
      case ExprKind::Call: return checkCall(*cast<CallExpr>(&e));
      case ExprKind::Range: {
        auto* r = cast<RangeExpr>(&e);
        for (const Expr* p : {r->start.get(), r->step.get(), r->stop.get()})
          if (p) checkExpr(*p);
        return;
      }
      case ExprKind::Array:
        for (const auto& el : cast<ArrayExpr>(&e)->elements) checkExpr(*el);
        return;
      case ExprKind::Comprehension: {
        auto* c = cast<ComprehensionExpr>(&e);
        withIterators(c->iterators, [&] { checkExpr(*c->body); });
        return;
      }
      case ExprKind::If: {
        auto* i = cast<IfExpr>(&e);
        for (const auto& c : i->conditions) checkExpr(*c);
        for (const auto& v : i->values) checkExpr(*v);
        if (i->elseValue) checkExpr(*i->elseValue);
        return;
      }
    }
  }
};

const ClassDef* findModel(const StoredDefinition& file, std::string_view name) {
  const ClassDef* last = nullptr;
  std::function<const ClassDef*(const std::vector<std::unique_ptr<ClassDef>>&, const std::string&)> find;
  find = [&](const std::vector<std::unique_ptr<ClassDef>>& classes, const std::string& prefix) -> const ClassDef* {
    for (const auto& c : classes) {
      std::string full = prefix + c->name;
      if (c->kind == ClassKind::Model) {
        if (!name.empty() && (full == name || c->name == name)) return c.get();
        last = c.get();
      }
      if (auto* r = find(c->classes, full + ".")) return r;
    }
    return nullptr;
  };
  const ClassDef* found = find(file.classes, "");
  return name.empty() ? last : found;
}

}  // namespace

const BuiltinFunction* findBuiltin(std::string_view name) {
  for (const auto& b : kBuiltins)
    if (name == b.name) return &b;
  return nullptr;
}

std::string closestName(std::string_view name, const std::vector<std::string>& candidates) {
  auto distance = [](std::string_view a, std::string_view b) {
    std::vector<size_t> row(b.size() + 1);
    for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (size_t i = 1; i <= a.size(); ++i) {
      size_t diag = row[0];
      row[0] = i;
      for (size_t j = 1; j <= b.size(); ++j) {
        size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] != b[j - 1])});
        diag = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  size_t bestDist = std::max<size_t>(1, name.size() / 3) + 1;
  for (const auto& c : candidates) {
    size_t d = distance(name, c);
    if (d < bestDist || (d == bestDist && c < best)) {
      bestDist = d;
      best = c;
    }
  }
  return best;
}

std::optional<CheckedModel> checkModel(const StoredDefinition& file, std::string_view modelName,
                                       DiagnosticEngine& diags) {
  const ClassDef* cls = findModel(file, modelName);
  if (!cls) return std::nullopt;
  CheckedModel m;
  m.cls = cls;
  Checker(m, diags).run();
  return m;
}

}  // namespace qdot::sema
