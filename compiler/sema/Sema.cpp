// Sema: scope building, declaration checks and name/call checks for one flat model.
// Error codes E02xx (see compiler/sema/README.md).
#include "sema/Sema.h"

#include <algorithm>
#include <functional>
#include <sstream>
#include <unordered_set>

#include "sema/ClassLookup.h"

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
    {"eulerZXZ", 3, 3},
};

// Names that parse as calls but belong to events, which qdot does not compile.
bool isEventFunction(std::string_view n) {
  return n == "pre" || n == "reinit" || n == "initial" || n == "edge" || n == "sample" || n == "change";
}

std::string dottedName(const std::vector<std::string>& parts) {
  std::string s;
  for (size_t i = 0; i < parts.size(); ++i) s += (i ? "." : "") + parts[i];
  return s;
}

std::optional<BaseType> builtinType(const std::string& t) {
  if (t == "Real") return BaseType::Real;
  if (t == "Integer") return BaseType::Integer;
  if (t == "Boolean") return BaseType::Boolean;
  return std::nullopt;
}

class ClassChecker;

/// Checks the model compiled and, on first use, every class its components use (each once).
class ModelChecker {
 public:
  ModelChecker(const StoredDefinition& file, DiagnosticEngine& diags, const Library& library, CheckedModel& out)
      : lookup_(file, library), diags_(diags), library_(library), out_(out) {}

  /// The checked class, or null while it is being checked (a class that contains itself).
  const CheckedClass* check(const ClassDef& cls, bool root = false);
  /// The checked function, or null while it is being checked (a function that calls itself).
  const CheckedFunction* checkFunction(const ClassDef& cls);
  void recordCall(const CallExpr& c, FunctionCall call) { out_.calls[&c] = std::move(call); }
  void checkFileImports(const std::vector<ImportClause>& imports);
  ClassLookup& lookup() { return lookup_; }
  DiagnosticEngine& diags() { return diags_; }
  const Library& library() const { return library_; }

 private:
  ClassLookup lookup_;
  DiagnosticEngine& diags_;
  const Library& library_;
  CheckedModel& out_;
  std::unordered_map<const ClassDef*, const CheckedClass*> done_;
  std::unordered_map<const ClassDef*, const CheckedFunction*> doneFunctions_;
  std::unordered_set<const ClassDef*> inProgress_;
};

/// Walks one class: what it inherits, its declarations (scope), then every expression with
/// iterator scopes, every modifier against the class it modifies, every connect.
class ClassChecker {
 public:
  ClassChecker(ModelChecker& model, CheckedClass& c, bool root)
      : model_(model), c_(c), diags_(model.diags()), root_(root) {}

  void run() {
    checkImports(c_.cls->imports);
    for (const auto& e : c_.cls->extends) inherit(e);
    for (const auto& d : c_.cls->declarations) declare(d);
    for (const auto& d : c_.cls->declarations) checkDeclaration(d);
    for (const auto& e : c_.cls->extends) checkExtendsModifiers(e);
    for (const auto& eq : c_.cls->equations) {
      c_.equations.push_back(&eq);
      checkEquation(eq);
    }
    for (const auto& eq : c_.cls->initialEquations) {
      c_.initialEquations.push_back(&eq);
      checkEquation(eq);
    }
    inMechanics_ = true;
    for (const auto& st : c_.cls->mechanics) {
      c_.mechanics.push_back(&st);
      checkMechanics(st);
    }
    inMechanics_ = false;
  }

  /// A function's variables: inputs (a binding is the default), one output and protected locals,
  /// each bound to an expression of the function's own variables. No sections, no `extends`.
  CheckedFunction runFunction() {
    inFunction_ = true;
    CheckedFunction f;
    f.scope = &c_;
    checkImports(c_.cls->imports);
    for (const auto& e : c_.cls->extends)
      functionError(e.range, "a function cannot extend a class", "write the function's inputs and output in it");
    for (const auto& d : c_.cls->declarations) declareFunctionVariable(d, f);
    for (const auto& d : c_.cls->declarations)
      if (c_.symbols.at(d.name).decl == &d) checkDeclaration(d);
    if (!f.output)
      functionError(c_.cls->nameRange, "function '" + c_.fullName + "' has no output",
                    "declare its result: output Real y = expression;");
    const Equation* eq = !c_.cls->equations.empty() ? &c_.cls->equations[0]
                         : !c_.cls->initialEquations.empty() ? &c_.cls->initialEquations[0] : nullptr;
    if (eq) functionError(eq->range, "a function has no equations", "bind the output to an expression: output Real y = ...;");
    if (!c_.cls->mechanics.empty())
      functionError(c_.cls->mechanics[0].range, "a function has no mechanics section",
                    "functions compute a value; energies belong in a model");
    return f;
  }

 private:
  ModelChecker& model_;
  CheckedClass& c_;
  DiagnosticEngine& diags_;
  bool root_;  ///< the model compiled (a component's parameters may get their values from modifiers)
  std::vector<std::string> iterators_;
  bool inMechanics_ = false;
  bool componentAllowed_ = false;  ///< inside connect(...): references may name connectors
  bool inFunction_ = false;        ///< checking a function: only its own variables, no time, no der
  std::unordered_map<const ExtendsClause*, const CheckedClass*> bases_;

  // --- classes ---------------------------------------------------------------------------------

  /// The class a type name means here, reporting an unknown one (with the search path).
  const ClassDef* resolveClass(const std::vector<std::string>& parts, SourceRange where) {
    if (const ClassDef* cls = model_.lookup().resolve(parts, c_.cls)) return cls;
    std::string name = dottedName(parts);
    const std::string& path = model_.library().searchPath;
    diags_.error(where, DiagCode::E0220, "unknown class '" + name + "'",
                 path.empty() ? "declare it in this file, or check the spelling"
                              : "declare it in this file, import it (import Vibration.*;), or put its package on the "
                                "library path; searched: " + path);
    return nullptr;
  }

  const CheckedClass* checkedClass(const ClassDef& cls, SourceRange where, const std::string& via) {
    const CheckedClass* checked = model_.check(cls);
    if (!checked)
      diags_.error(where, DiagCode::E0223,
                   "class '" + model_.lookup().fullName(&cls) + "' contains itself (through " + via + ")",
                   "a component cannot contain an instance of its own class, directly or through others");
    return checked;
  }

  void inherit(const ExtendsClause& e) {
    if (builtinType(dottedName(e.baseName))) return;  // type Length = Real(unit = "m")
    const ClassDef* base = resolveClass(e.baseName, e.range);
    if (base && base->kind == ClassKind::Function && c_.cls->kind != ClassKind::Function)
      diags_.error(e.range, DiagCode::E0217, "'" + dottedName(e.baseName) + "' is a function; a class cannot extend it",
                   "call it in an expression instead");
    if (!base || base->kind == ClassKind::Function) return;
    const CheckedClass* b = checkedClass(*base, e.range, "extends " + dottedName(e.baseName));
    if (!b) return;
    bases_[&e] = b;
    for (const Declaration* d : b->declarations) addSymbol(*d, b->symbols.at(d->name));
    c_.equations.insert(c_.equations.end(), b->equations.begin(), b->equations.end());
    c_.initialEquations.insert(c_.initialEquations.end(), b->initialEquations.begin(), b->initialEquations.end());
    c_.mechanics.insert(c_.mechanics.end(), b->mechanics.begin(), b->mechanics.end());
    c_.extendsModifiers.insert(b->extendsModifiers.begin(), b->extendsModifiers.end());
    for (const auto& p : b->energyPotentials) addEnergyPotential(p);
  }

  // Every import names a class or package (a typo would otherwise show only where it is used).
  void checkImports(const std::vector<ImportClause>& imports) {
    for (const auto& imp : imports)
      if (!imp.path.empty() && !model_.lookup().resolve(imp.path, nullptr)) {
        const std::string& path = model_.library().searchPath;
        diags_.error(imp.range, DiagCode::E0220, "'" + dottedName(imp.path) + "' names no class or package",
                     path.empty() ? "check the spelling" : "check the spelling; the library path searched: " + path);
      }
  }

 public:
  void checkFileImports(const std::vector<ImportClause>& imports) { checkImports(imports); }

 private:
  // `extends Base(k = 1)`: each name an element of Base, values checked here.
  void checkExtendsModifiers(const ExtendsClause& e) {
    auto it = bases_.find(&e);
    if (it == bases_.end()) return;
    for (const auto& mod : e.mods) {
      const ModelSymbol* s = checkModifier(mod, *it->second);
      if (s) c_.extendsModifiers[s->decl] = &mod;
    }
  }

  // --- declarations ----------------------------------------------------------------------------

  bool addSymbol(const Declaration& d, ModelSymbol s) {
    s.index = static_cast<int>(c_.declarations.size());
    auto [it, inserted] = c_.symbols.try_emplace(d.name, s);
    if (!inserted) {
      auto& diag = diags_.error(d.nameRange, DiagCode::E0201, "'" + d.name + "' is declared twice",
                                "rename one of the two declarations");
      diag.notes.push_back({it->second.decl->nameRange, "first declared here"});
      return false;
    }
    c_.declarations.push_back(&d);
    return true;
  }

  void declare(const Declaration& d) {
    ModelSymbol s;
    s.decl = &d;
    std::string t = dottedName(d.typeName);
    std::optional<BaseType> builtin = builtinType(t);
    const ClassDef* cls = builtin ? nullptr : resolveClass(d.typeName, d.typeRange);
    if (cls && cls->kind == ClassKind::Type) {  // type Length = Real(...): a Real
      builtin = BaseType::Real;
      for (const auto& e : cls->extends) builtin = builtinType(dottedName(e.baseName)).value_or(BaseType::Real);
      cls = nullptr;
    }
    s.type = builtin.value_or(BaseType::Real);
    if (cls && cls->kind == ClassKind::Function) {
      diags_.error(d.typeRange, DiagCode::E0217, "'" + t + "' is a function, not a model or connector",
                   "call it in an expression: Real y = " + t + "(...);");
      cls = nullptr;
    }
    if (!builtin) {
      s.kind = SymbolKind::Component;
      if (cls) s.component = checkedClass(*cls, d.typeRange, "component '" + d.name + "'");
    } else if (d.variability == Variability::Constant) {
      s.kind = SymbolKind::Constant;
    } else if (d.variability == Variability::Parameter) {
      s.kind = s.type == BaseType::Integer ? SymbolKind::IntegerParameter : SymbolKind::Parameter;
    } else if (d.causality == Causality::Input && !d.binding && s.type == BaseType::Real && !d.isCoordinate) {
      s.kind = SymbolKind::Input;
    } else if (d.isCoordinate) {
      s.kind = SymbolKind::Coordinate;
    } else if (d.binding) {
      s.kind = SymbolKind::Definition;
    } else {
      s.kind = SymbolKind::Unknown;
    }
    addSymbol(d, s);
  }

  void functionError(SourceRange where, std::string msg, std::string help) {
    diags_.error(where, DiagCode::E0214, std::move(msg), std::move(help));
  }

  // Scalar Real/Integer/Boolean; an input, the one output, or a protected local with a binding.
  void declareFunctionVariable(const Declaration& d, CheckedFunction& f) {
    ModelSymbol s;
    s.decl = &d;
    std::optional<BaseType> type = builtinType(dottedName(d.typeName));
    const ClassDef* cls = type ? nullptr : model_.lookup().resolve(d.typeName, c_.cls);
    if (cls && cls->kind == ClassKind::Type) type = BaseType::Real;  // type Length = Real(unit = "m")
    s.type = type.value_or(BaseType::Real);
    bool input = d.causality == Causality::Input && !d.isProtected;
    s.kind = input ? SymbolKind::Input : SymbolKind::Definition;
    if (!addSymbol(d, s)) return;
    if (!type)
      functionError(d.typeRange, "a function's variables are Real, Integer or Boolean, not '" + dottedName(d.typeName) + "'",
                    "pass the values the function needs as Real inputs");
    if (!d.dims.empty() || !d.typeDims.empty())
      functionError(d.range, "array inputs, outputs and locals of functions are not supported",
                    "declare scalars and call the function once per element: {f(x[i]) for i in 1:n}");
    if (d.variability != Variability::Continuous || d.isFlow || d.isCoordinate)
      functionError(d.range, "'" + d.name + "' of a function cannot be a parameter, constant, flow or coordinate",
                    "remove the prefix: a function's variables are inputs, its output, or protected locals");
    if (d.isProtected && d.causality != Causality::None)
      functionError(d.range, "protected '" + d.name + "' cannot be an input or output", "move it before 'protected'");
    else if (d.causality == Causality::None && !d.isProtected)
      functionError(d.range, "'" + d.name + "' must be an 'input' or the 'output' of the function",
                    "write 'input Real " + d.name + ";', or put local variables after 'protected'");
    else if (!input && !d.binding)
      functionError(d.nameRange, "'" + d.name + "' needs a value: a function is expression-bodied",
                    "bind it to an expression of the inputs: " + std::string(d.isProtected ? "Real " : "output Real ") +
                        d.name + " = ...;");
    if (input) f.inputs.push_back(&d);
    if (d.causality != Causality::Output || d.isProtected) return;
    if (f.output)
      functionError(d.nameRange, "a function has exactly one output; '" + f.output->name + "' is already its output",
                    "make '" + d.name + "' a separate function, or a protected local");
    else
      f.output = &d;
  }

  void checkDeclaration(const Declaration& d) {
    const ModelSymbol& s = c_.symbols.at(d.name);
    if (s.decl != &d) return;  // duplicate, already reported
    for (const auto& dim : d.typeDims) checkSize(*dim);
    for (const auto& dim : d.dims) checkSize(*dim);
    if (s.kind == SymbolKind::Component) return checkComponentDeclaration(d, s);
    for (const auto& mod : d.mods) checkModification(d, mod);
    if (d.binding) checkExpr(*d.binding);
    if (!inFunction_) checkKindRules(d, s);  // a function's variables have their own (declareFunctionVariable)
  }

  void checkComponentDeclaration(const Declaration& d, const ModelSymbol& s) {
    if (d.binding)
      diags_.error(d.binding->range, DiagCode::E0224, "component '" + d.name + "' cannot have a value",
                   "set its parameters with a modifier instead: " + dottedName(d.typeName) + " " + d.name + "(k = 1);");
    if (d.isCoordinate || d.variability != Variability::Continuous || d.isFlow)
      diags_.error(d.range, DiagCode::E0206, "component '" + d.name + "' cannot be a coordinate, parameter, constant or flow",
                   "remove the prefix: these apply to Real variables");
    if (c_.isConnector())
      diags_.error(d.typeRange, DiagCode::E0290, "a connector holding a component is not supported yet",
                   "declare the connector's variables directly: Real s; flow Real f;");
    if (!s.component) return;
    for (const auto& mod : d.mods) checkModifier(mod, *s.component);
  }

  // A modifier `name = value` or `name(nested...)` of an element of `target`; its value is an
  // expression of this class. Returns the element, or null after reporting.
  const ModelSymbol* checkModifier(const Modification& mod, const CheckedClass& target) {
    const ModelSymbol* s = target.find(mod.name);
    if (!s) {
      std::vector<std::string> names;
      for (const Declaration* d : target.declarations) names.push_back(d->name);
      std::string guess = closestName(mod.name, names);
      std::string list;
      for (size_t i = 0; i < names.size() && i < 12; ++i) list += (i ? ", " : "") + names[i];
      diags_.error(mod.nameRange, DiagCode::E0221, "'" + target.fullName + "' has no element '" + mod.name + "'",
                   guess.empty() ? "its elements are: " + list : "did you mean '" + guess + "'?");
      return nullptr;
    }
    if (s->kind == SymbolKind::Component) {
      if (mod.value)
        diags_.error(mod.value->range, DiagCode::E0224, "'" + mod.name + "' is a component and cannot be given a value",
                     "modify its elements instead: " + mod.name + "(name = value)");
      if (s->component)
        for (const auto& n : mod.nested) checkModifier(n, *s->component);
      return s;
    }
    if (mod.value) checkExpr(*mod.value);
    for (const auto& n : mod.nested) checkModification(*s->decl, n);
    return s;
  }

  void checkKindRules(const Declaration& d, const ModelSymbol& s) {
    if (d.isFlow && !c_.isConnector())
      diags_.error(d.range, DiagCode::E0290, "'flow' variables belong in connectors",
                   "declare '" + d.name + "' in a connector class (connector Flange Real s; flow Real f; end Flange;)");
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
    // A component's parameter may get its value from a modifier (Mass m1(m = 2)); the model
    // compiled must give every one (checked when it is instantiated, by flatten).
    if ((s.kind == SymbolKind::Constant || s.kind == SymbolKind::IntegerParameter ||
         s.kind == SymbolKind::Parameter) && !d.binding && root_)
      diags_.error(d.nameRange, DiagCode::E0207, "parameter '" + d.name + "' has no value",
                   "give it a default value, e.g. parameter Real " + d.name + " = 1;");
    if ((s.kind == SymbolKind::Unknown || s.kind == SymbolKind::Input) && s.type != BaseType::Real)
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
    // unit, displayUnit and quantity are texts (spec: `unit = "m"`); every other attribute a value.
    bool text = mod.name == "unit" || mod.name == "displayUnit" || mod.name == "quantity";
    if (!mod.value) return;
    if (!text) return checkExpr(*mod.value);
    if (mod.value->kind != ExprKind::String)
      diags_.error(mod.value->range, DiagCode::E0225, "'" + mod.name + "' of '" + d.name + "' takes a string",
                   "write it in quotes, e.g. " + mod.name + " = \"m\"");
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
      if (n->parts.size() == 1 && std::find(iterators_.begin(), iterators_.end(), n->parts[0]) != iterators_.end())
        return true;
      const ModelSymbol* s = lookupQuietly(n->parts);
      if (!s) return true;  // already reported as unknown
      bool ok = s->type == BaseType::Integer &&
                (s->kind == SymbolKind::IntegerParameter || s->kind == SymbolKind::Constant);
      if (!ok) why = "; '" + n->dotted() + "' is not an Integer parameter or constant";
      return ok;
    }
    if (auto* u = dyn_cast<UnaryExpr>(&e)) return u->op != UnaryOp::Not && isIntegerExpr(*u->operand, why);
    if (auto* b = dyn_cast<BinaryExpr>(&e))
      return (b->op == BinaryOp::Add || b->op == BinaryOp::Sub || b->op == BinaryOp::Mul) &&
             isIntegerExpr(*b->lhs, why) && isIntegerExpr(*b->rhs, why);
    if (auto* c = dyn_cast<CallExpr>(&e)) return c->callee->dotted() == "size";
    return false;
  }

  // --- equations and mechanics -----------------------------------------------------------------

  void checkEquation(const Equation& eq) {
    switch (eq.kind) {
      case EquationKind::Simple:
        if (eq.lhs) checkExpr(*eq.lhs);
        if (eq.rhs) checkExpr(*eq.rhs);
        return;
      case EquationKind::For:
        withIterators(eq.iterators, [&] { for (const auto& b : eq.body) checkEquation(b); });
        return;
      case EquationKind::Connect: return checkConnect(eq);
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

  void checkConnect(const Equation& eq) {
    if (!eq.lhs || !eq.rhs) return;
    size_t errors = diags_.errorCount();
    componentAllowed_ = true;
    checkExpr(*eq.lhs);
    checkExpr(*eq.rhs);
    componentAllowed_ = false;
    if (diags_.errorCount() > errors) return;
    const CheckedClass* a = connectorOf(*eq.lhs);
    const CheckedClass* b = connectorOf(*eq.rhs);
    if (!a || !b || a == b || compatible(*a, *b)) return;
    diags_.error(eq.range, DiagCode::E0222,
                 "cannot connect a '" + a->fullName + "' to a '" + b->fullName + "'",
                 "connect connectors of the same kind (their variables and flows must match)");
  }

  // The connector class a connect argument names, or null after reporting why it is not one.
  const CheckedClass* connectorOf(const Expr& e) {
    const ModelSymbol* s = referenceSymbol(e);
    if (s && s->kind == SymbolKind::Component && !s->component) return nullptr;  // its class is unknown: reported
    const CheckedClass* c = referenceClass(e);
    if (c && c->isConnector()) return c;
    diags_.error(e.range, DiagCode::E0222,
                 c ? "connect needs connectors, but this is a '" + c->fullName + "' component"
                   : "connect needs connectors, but this is a variable",
                 c ? "connect its connectors, e.g. the flanges a and b of a Vibration element"
                   : "connect(a, b) joins two connectors; to equate variables write an equation x = y;");
    return nullptr;
  }

  // Two connector classes that declare the same variables (names, types, flow prefixes, sizes).
  static bool compatible(const CheckedClass& a, const CheckedClass& b) {
    if (a.declarations.size() != b.declarations.size()) return false;
    for (size_t i = 0; i < a.declarations.size(); ++i) {
      const Declaration& x = *a.declarations[i];
      const Declaration& y = *b.declarations[i];
      if (x.name != y.name || x.isFlow != y.isFlow || x.typeName != y.typeName ||
          x.dims.size() != y.dims.size())
        return false;
    }
    return true;
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

  // force(q) acts on a coordinate (also of a component: m1.s, ms[i].s) or on one of this class's
  // connector potentials (force(a.s)), which then is a coordinate of the component.
  void checkForceTarget(const Expr& target) {
    checkExpr(target);
    const Expr* base = &target;
    if (auto* ix = dyn_cast<IndexExpr>(base)) base = ix->base.get();
    const ModelSymbol* s = nullptr;
    if (auto* name = dyn_cast<NameExpr>(base)) s = lookupQuietly(name->parts);
    else if (auto* m = dyn_cast<MemberExpr>(base))
      if (const CheckedClass* c = referenceClass(*m->base)) s = c->find(m->field);
    if (!s) {
      if (!dyn_cast<NameExpr>(base) && !dyn_cast<MemberExpr>(base))
        diags_.error(target.range, DiagCode::E0209, "force(...) must name a coordinate",
                     "write force(q) = expr; or force(q[i]) = expr; with q a coordinate");
      return;
    }
    bool potential = s->kind == SymbolKind::Unknown && !s->decl->isFlow;
    if (auto* name = dyn_cast<NameExpr>(base); potential && name && name->parts.size() == 2) {
      const ModelSymbol* owner = c_.find(name->parts[0]);
      if (owner && owner->component && owner->component->isConnector() && owner->decl->dims.empty())
        addEnergyPotential(name->dotted());  // force(a.s): a coordinate of this component
    }
    if (s->kind != SymbolKind::Coordinate && !potential) {
      std::string name = sourceText(*base);
      diags_.error(target.range, DiagCode::E0209, "'" + name + "' is not a coordinate",
                   "generalized forces act on coordinates: declare it 'coordinate Real " + name + "'");
    }
  }

  static std::string sourceText(const Expr& e) {
    if (auto* n = dyn_cast<NameExpr>(&e)) return n->dotted();
    if (auto* m = dyn_cast<MemberExpr>(&e)) return "…." + m->field;
    return "this";
  }

  void withIterators(const std::vector<Iterator>& its, const std::function<void()>& body) {
    for (const auto& it : its)
      if (it.range) checkExpr(*it.range);
    for (const auto& it : its) iterators_.push_back(it.name);
    body();
    iterators_.resize(iterators_.size() - its.size());
  }

  // --- names -----------------------------------------------------------------------------------

  /// The symbol a dotted name ends at (through components), or null; reports nothing.
  const ModelSymbol* lookupQuietly(const std::vector<std::string>& parts) const {
    const ModelSymbol* s = c_.find(parts[0]);
    for (size_t i = 1; s && i < parts.size(); ++i)
      s = s->kind == SymbolKind::Component && s->component ? s->component->find(parts[i]) : nullptr;
    return s;
  }

  /// The declaration an expression ends at (`m1`, `ms[2]`, `sys.m1.a`, `m1.s`), or null.
  const ModelSymbol* referenceSymbol(const Expr& e) const {
    if (auto* n = dyn_cast<NameExpr>(&e)) {
      if (n->parts.size() == 1 && std::find(iterators_.begin(), iterators_.end(), n->parts[0]) != iterators_.end())
        return nullptr;
      return lookupQuietly(n->parts);
    }
    if (auto* ix = dyn_cast<IndexExpr>(&e)) return referenceSymbol(*ix->base);
    if (auto* m = dyn_cast<MemberExpr>(&e)) {
      const CheckedClass* base = referenceClass(*m->base);
      return base ? base->find(m->field) : nullptr;
    }
    return nullptr;
  }

  /// The class of the component(s) an expression names, or null.
  const CheckedClass* referenceClass(const Expr& e) const {
    const ModelSymbol* s = referenceSymbol(e);
    return s && s->kind == SymbolKind::Component ? s->component : nullptr;
  }

  void addEnergyPotential(const std::string& p) {
    if (std::find(c_.energyPotentials.begin(), c_.energyPotentials.end(), p) == c_.energyPotentials.end())
      c_.energyPotentials.push_back(p);
  }

  void checkName(const NameExpr& n) {
    const std::string& first = n.parts[0];
    if (n.parts.size() == 1 && first == "time" && inFunction_)
      return functionError(n.range, "'time' is not available inside a function", "pass it as an argument: f(time)");
    if (n.parts.size() == 1 && (first == "time" || first == "pi")) return;
    if (n.parts.size() == 1 && std::find(iterators_.begin(), iterators_.end(), first) != iterators_.end()) return;
    const ModelSymbol* s = c_.find(first);
    if (!s) return reportUnknown(n, 0, c_);
    for (size_t i = 1; i < n.parts.size(); ++i) {
      if (s->kind != SymbolKind::Component) {
        diags_.error(n.partRanges[i], DiagCode::E0224,
                     "'" + dottedPrefix(n, i) + "' is not a component, so it has no element '" + n.parts[i] + "'",
                     "only components (instances of models and connectors) have elements");
        return;
      }
      if (!s->component) return;  // its class did not resolve: reported
      const CheckedClass& owner = *s->component;
      const ModelSymbol* next = owner.find(n.parts[i]);
      if (!next) return reportUnknown(n, i, owner);
      if (inMechanics_ && i == 1 && n.parts.size() == 2 && owner.isConnector() && s->decl->dims.empty() &&
          next->kind == SymbolKind::Unknown && !next->decl->isFlow)
        addEnergyPotential(n.dotted());
      s = next;
    }
    if (s->kind == SymbolKind::Component && !componentAllowed_)
      diags_.error(n.range, DiagCode::E0224, "'" + n.dotted() + "' is a component, not a value",
                   "use one of its variables, e.g. " + n.dotted() + "." + firstVariableOf(s->component));
  }

  static std::string firstVariableOf(const CheckedClass* c) {
    if (c)
      for (const Declaration* d : c->declarations)
        if (c->symbols.at(d->name).kind != SymbolKind::Component) return d->name;
    return "x";
  }

  static std::string dottedPrefix(const NameExpr& n, size_t count) {
    std::string s;
    for (size_t i = 0; i < count; ++i) s += (i ? "." : "") + n.parts[i];
    return s;
  }

  void reportUnknown(const NameExpr& n, size_t part, const CheckedClass& scope) {
    const std::string& name = n.parts[part];
    std::vector<std::string> candidates;
    if (part == 0) candidates = iterators_;
    for (const auto& [k, v] : scope.symbols) candidates.push_back(k);
    std::string guess = closestName(name, candidates);
    SourceRange where = n.partRanges.size() > part ? n.partRanges[part] : n.range;
    if (part > 0) {
      diags_.error(where, DiagCode::E0202, "'" + scope.fullName + "' has no element '" + name + "'",
                   guess.empty() ? "see the class's declarations" : "did you mean '" + guess + "'?");
      return;
    }
    diags_.error(where, DiagCode::E0202, "unknown name '" + name + "'",
                 isEnergyKeyword(name) ? "'" + name + " = expr;' states an energy: write it in the mechanics section"
                 : guess.empty()       ? "declare it, e.g. parameter Real " + name + " = 1;"
                                       : "did you mean '" + guess + "'?");
  }

  // The words that start a mechanics statement; written in an equation section they are names.
  static bool isEnergyKeyword(const std::string& name) {
    return name == "kinetic" || name == "potential" || name == "dissipation";
  }

  void checkMember(const MemberExpr& m) {
    bool allowed = componentAllowed_;
    componentAllowed_ = true;  // the base names a component
    checkExpr(*m.base);
    componentAllowed_ = allowed;
    const CheckedClass* c = referenceClass(*m.base);
    if (!c) {
      if (!isa<NameExpr>(m.base.get()) || lookupQuietly(cast<NameExpr>(m.base.get())->parts))
        diags_.error(m.fieldRange, DiagCode::E0224, "this is not a component, so it has no element '" + m.field + "'",
                     "only components (instances of models and connectors) have elements");
      return;
    }
    const ModelSymbol* s = c->find(m.field);
    if (!s) {
      std::vector<std::string> names;
      for (const auto& [k, v] : c->symbols) names.push_back(k);
      std::string guess = closestName(m.field, names);
      diags_.error(m.fieldRange, DiagCode::E0202, "'" + c->fullName + "' has no element '" + m.field + "'",
                   guess.empty() ? "see the class's declarations" : "did you mean '" + guess + "'?");
      return;
    }
    if (s->kind == SymbolKind::Component && !componentAllowed_)
      diags_.error(m.range, DiagCode::E0224, "this is a component, not a value",
                   "use one of its variables, e.g. ." + m.field + "." + firstVariableOf(s->component));
  }
  void checkCall(const CallExpr& c) {
    std::string name = c.callee->dotted();
    bool allowed = componentAllowed_;
    componentAllowed_ = false;  // arguments are values
    struct Restore {
      bool& flag;
      bool value;
      ~Restore() { flag = value; }
    } restore{componentAllowed_, allowed};
    if (isEventFunction(name)) {
      diags_.error(c.callee->range, DiagCode::E0290, "'" + name + "' is not supported yet",
                   "events are not available: write the behaviour as an if-expression in an equation");
      return;
    }
    if (inFunction_ && name == "der")
      functionError(c.callee->range, "der() is not available inside a function",
                    "pass the derivative as an argument: f(der(x))");
    const BuiltinFunction* f = findBuiltin(name);
    if (!f) return checkFunctionCall(c);
    for (const auto& na : c.namedArgs)
      diags_.error(na.nameRange, DiagCode::E0211, "named arguments are not allowed in a call to '" + name + "'",
                   "pass the arguments by position");
    {
      int n = static_cast<int>(c.args.size());
      if (n < f->minArgs || (f->maxArgs >= 0 && n > f->maxArgs))
        diags_.error(c.range, DiagCode::E0212,
                     "'" + name + "' takes " + arityText(*f) + ", but " + std::to_string(n) + " given");
    }
    for (const auto& a : c.args) checkExpr(*a);
  }

  // A call of a user function: its class must be a function, not (through others) the one being
  // checked; every argument binds one input.
  void checkFunctionCall(const CallExpr& c) {
    for (const auto& a : c.args) checkExpr(*a);
    for (const auto& na : c.namedArgs) checkExpr(*na.value);
    std::string name = c.callee->dotted();
    const ClassDef* cls = model_.lookup().resolve(c.callee->parts, c_.cls);
    if (!cls) return reportUnknownFunction(c);
    if (cls->kind != ClassKind::Function) {
      diags_.error(c.callee->range, DiagCode::E0217, "'" + name + "' is a class, not a function",
                   "declare a component of it (" + name + " x(...);) and use its variables");
      return;
    }
    const CheckedFunction* fn = model_.checkFunction(*cls);
    if (!fn) {
      diags_.error(c.callee->range, DiagCode::E0216, "'" + name + "' calls itself through this call",
                   "a function is inlined where it is called, so it cannot call itself, directly or through others");
      return;
    }
    bindArguments(c, *fn);
  }

  void reportUnknownFunction(const CallExpr& c) {
    std::vector<std::string> names;
    const auto& parts = c.callee->parts;
    const ClassDef* owner =
        parts.size() > 1 ? model_.lookup().resolve({parts.begin(), parts.end() - 1}, c_.cls) : nullptr;
    std::string prefix = owner ? dottedName({parts.begin(), parts.end() - 1}) + "." : "";
    if (owner)
      for (const auto& n : owner->classes)
        if (n->kind == ClassKind::Function) names.push_back(prefix + n->name);
    if (!owner)
      for (const auto& b : kBuiltins) names.push_back(b.name);
    std::string guess = closestName(c.callee->dotted(), names);
    diags_.error(c.callee->range, DiagCode::E0210, "unknown function '" + c.callee->dotted() + "'",
                 !guess.empty() ? "did you mean '" + guess + "'?"
                 : owner        ? "'" + dottedName({parts.begin(), parts.end() - 1}) + "' declares no such function"
                                : "see docs/language.md for the built-in functions; a function of a package is "
                                  "called by its full name (Fluid.gateForce) or after import Fluid.*;");
  }

  // Positional arguments bind the inputs in order, named ones by name; defaults fill the rest.
  void bindArguments(const CallExpr& c, const CheckedFunction& fn) {
    const std::string& name = fn.scope->fullName;
    FunctionCall call{&fn, std::vector<const Expr*>(fn.inputs.size(), nullptr)};
    bool ok = true;
    if (c.args.size() > fn.inputs.size()) {
      diags_.error(c.args[fn.inputs.size()]->range, DiagCode::E0212,
                   "'" + name + "' takes " + inputsText(fn) + ", but " + std::to_string(c.args.size()) + " given",
                   "its inputs: " + signatureText(fn));
      ok = false;
    }
    for (size_t i = 0; i < c.args.size() && i < fn.inputs.size(); ++i) call.arguments[i] = c.args[i].get();
    for (const auto& na : c.namedArgs) ok &= bindNamed(na, fn, call);
    for (size_t i = 0; ok && i < fn.inputs.size(); ++i)
      if (!call.arguments[i] && !fn.inputs[i]->binding) {
        diags_.error(c.range, DiagCode::E0212, "missing argument '" + fn.inputs[i]->name + "' of '" + name + "'",
                     "its inputs: " + signatureText(fn));
        ok = false;
      }
    if (ok) model_.recordCall(c, std::move(call));
  }

  bool bindNamed(const NamedArg& na, const CheckedFunction& fn, FunctionCall& call) {
    const std::string& name = fn.scope->fullName;
    auto it = std::find_if(fn.inputs.begin(), fn.inputs.end(), [&](const Declaration* d) { return d->name == na.name; });
    if (it == fn.inputs.end()) {
      std::vector<std::string> names;
      for (const Declaration* d : fn.inputs) names.push_back(d->name);
      std::string guess = closestName(na.name, names);
      diags_.error(na.nameRange, DiagCode::E0215, "'" + name + "' has no input '" + na.name + "'",
                   guess.empty() ? "its inputs: " + signatureText(fn) : "did you mean '" + guess + "'?");
      return false;
    }
    const Expr*& slot = call.arguments[it - fn.inputs.begin()];
    if (slot) {
      auto& d = diags_.error(na.nameRange, DiagCode::E0215, "input '" + na.name + "' of '" + name + "' is given twice",
                             "give each input once, by position or by name");
      d.notes.push_back({slot->range, "first given here"});
      return false;
    }
    slot = na.value.get();
    return true;
  }

  static std::string inputsText(const CheckedFunction& fn) {
    size_t required = 0;
    for (const Declaration* d : fn.inputs) required += d->binding ? 0 : 1;
    auto plural = [](size_t k) { return std::to_string(k) + (k == 1 ? " argument" : " arguments"); };
    if (required == fn.inputs.size()) return plural(required);
    return std::to_string(required) + " to " + plural(fn.inputs.size());
  }

  // "width, depthTop, rho = 1000, g = …" (a default that is not a number shows as …)
  static std::string signatureText(const CheckedFunction& fn) {
    std::string s;
    for (const Declaration* d : fn.inputs) {
      s += (s.empty() ? "" : ", ") + d->name;
      auto* number = d->binding ? dyn_cast<NumberExpr>(d->binding.get()) : nullptr;
      if (d->binding) s += " = " + (number ? numberText(number->value) : std::string("…"));
    }
    return s.empty() ? "none" : s;
  }

  static std::string numberText(double v) {
    std::ostringstream os;
    os << v;
    return os.str();
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
      case ExprKind::Member: return checkMember(*cast<MemberExpr>(&e));
      case ExprKind::Index: {
        auto* ix = cast<IndexExpr>(&e);
        bool allowed = componentAllowed_;
        if (referenceClass(*ix->base)) componentAllowed_ = true;  // ms[i] of an array of components
        checkExpr(*ix->base);
        componentAllowed_ = false;  // subscripts are values
        for (const auto& s : ix->subscripts) checkExpr(*s);
        componentAllowed_ = allowed;
        if (referenceClass(*ix->base) && !componentAllowed_)
          diags_.error(e.range, DiagCode::E0224, "this is a component, not a value",
                       "use one of its variables, e.g. " + sourceText(*ix->base) + "[...]." + firstVariableOf(referenceClass(*ix->base)));
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
  const ClassDef* lastNested = nullptr;  // the default when the file has no top-level model
  std::function<const ClassDef*(const std::vector<std::unique_ptr<ClassDef>>&, const std::string&)> find;
  find = [&](const std::vector<std::unique_ptr<ClassDef>>& classes, const std::string& prefix) -> const ClassDef* {
    for (const auto& c : classes) {
      std::string full = prefix + c->name;
      if (c->kind == ClassKind::Model) {
        if (!name.empty() && (full == name || c->name == name)) return c.get();
        (prefix.empty() ? last : lastNested) = c.get();  // the default: the file's last top-level model
      }
      if (auto* r = find(c->classes, full + ".")) return r;
    }
    return nullptr;
  };
  const ClassDef* found = find(file.classes, "");
  return name.empty() ? (last ? last : lastNested) : found;
}

void ModelChecker::checkFileImports(const std::vector<ImportClause>& imports) {
  CheckedClass scratch;  // a class with no elements: only its imports are checked
  ClassChecker(*this, scratch, false).checkFileImports(imports);
}

const CheckedFunction* ModelChecker::checkFunction(const ClassDef& cls) {
  if (auto it = doneFunctions_.find(&cls); it != doneFunctions_.end()) return it->second;
  if (inProgress_.count(&cls)) return nullptr;
  inProgress_.insert(&cls);
  out_.classes.push_back(std::make_unique<CheckedClass>());
  CheckedClass& c = *out_.classes.back();
  c.cls = &cls;
  c.fullName = lookup_.fullName(&cls);
  out_.functions.push_back(std::make_unique<CheckedFunction>(ClassChecker(*this, c, false).runFunction()));
  inProgress_.erase(&cls);
  doneFunctions_.emplace(&cls, out_.functions.back().get());
  return out_.functions.back().get();
}

const CheckedClass* ModelChecker::check(const ClassDef& cls, bool root) {
  if (auto it = done_.find(&cls); it != done_.end()) return it->second;
  if (inProgress_.count(&cls)) return nullptr;
  inProgress_.insert(&cls);
  out_.classes.push_back(std::make_unique<CheckedClass>());
  CheckedClass& c = *out_.classes.back();
  c.cls = &cls;
  c.fullName = lookup_.fullName(&cls);
  ClassChecker(*this, c, root).run();
  inProgress_.erase(&cls);
  done_.emplace(&cls, &c);
  return &c;
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
                                       DiagnosticEngine& diags, const Library& library) {
  const ClassDef* cls = findModel(file, modelName);
  if (!cls) return std::nullopt;
  CheckedModel m;
  ModelChecker checker(file, diags, library, m);
  m.root = checker.check(*cls, true);
  checker.checkFileImports(file.imports);
  return m;
}

}  // namespace qdot::sema
