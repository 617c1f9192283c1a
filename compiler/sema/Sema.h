// Sema: the semantic checks of a model and the classes it uses (spec §3–§7) before anything is
// expanded. Takes the parsed tree, picks the model to compile, resolves class names (nested
// classes, imports, the file, the library), builds each class's scope with what it inherits, and
// checks declarations (duplicates, types, array sizes, modifiers), every name and call in every
// expression and every connect, with located diagnostics. Hands a CheckedModel (the checked
// classes) to flatten; it evaluates nothing.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "ast/AST.h"
#include "support/Diagnostic.h"

namespace qdot::sema {

struct CheckedClass;

/// What a declared name is, which decides how flatten treats it.
enum class SymbolKind {
  Constant,          ///< `constant` (any type): folded at compile time
  IntegerParameter,  ///< `parameter Integer`: sizes arrays, folded at compile time
  Parameter,         ///< `parameter Real|Boolean`: a run-time input
  Coordinate,        ///< `coordinate Real`: a generalized coordinate
  Unknown,           ///< `Real x;` without binding (state or algebraic)
  Definition,        ///< `Real y = expr;` (also `output Real y = expr;`): substituted
  Input,             ///< `input Real u;` without binding: of the model compiled, a run-time input
                     ///< (a parameter whose default is 0, the B columns of `qdot linearize`); of a
                     ///< component, an unknown its modifier (`Force f(F = ...)`) or an equation gives
  Component,         ///< `Mass m1(m = 2);`, `Flange a;`: an instance of a model or connector class
};

enum class BaseType { Real, Integer, Boolean };

struct ModelSymbol {
  const ast::Declaration* decl = nullptr;
  SymbolKind kind = SymbolKind::Unknown;
  BaseType type = BaseType::Real;
  const CheckedClass* component = nullptr;  ///< Component: its class (null if it did not resolve)
  int index = -1;  ///< the declaration's position in its class's CheckedClass::declarations
};

/// One class as instances see it: its own elements and those it inherits (`extends`), with every
/// name in them checked. Points into the AST, which must outlive it.
struct CheckedClass {
  const ast::ClassDef* cls = nullptr;
  std::string fullName;  ///< "Vibration.Mass"
  std::unordered_map<std::string, ModelSymbol> symbols;
  std::vector<const ast::Declaration*> declarations;  ///< inherited first, then its own, in source order
  std::vector<const ast::Equation*> equations, initialEquations;
  std::vector<const ast::MechanicsStmt*> mechanics;
  /// `extends Base(k = 1)`: the modification of an inherited declaration, written in this class.
  std::unordered_map<const ast::Declaration*, const ast::Modification*> extendsModifiers;
  /// Connector potentials the mechanics statements use, as "a.s": they become coordinates of the
  /// component (spec §7: their Euler–Lagrange expression equals the connector's flow).
  std::vector<std::string> energyPotentials;

  bool isConnector() const { return cls->kind == ast::ClassKind::Connector; }
  const ModelSymbol* find(const std::string& name) const {
    auto it = symbols.find(name);
    return it == symbols.end() ? nullptr : &it->second;
  }
};

/// A function: pure and expression-bodied (its output and protected locals are bound to
/// expressions of its inputs), so flatten inlines each call symbolically.
struct CheckedFunction {
  const CheckedClass* scope = nullptr;          ///< its variables (inputs, output, locals) as a class
  std::vector<const ast::Declaration*> inputs;  ///< in declaration order: the positional arguments
  const ast::Declaration* output = nullptr;     ///< exactly one
};

/// One call of a function: per input, the argument written (by position or name), or null where
/// the input's default applies.
struct FunctionCall {
  const CheckedFunction* function = nullptr;
  std::vector<const ast::Expr*> arguments;
};

/// The model to compile and every class its components use.
struct CheckedModel {
  std::vector<std::unique_ptr<CheckedClass>> classes;  ///< owns them all
  std::vector<std::unique_ptr<CheckedFunction>> functions;
  std::unordered_map<const ast::CallExpr*, FunctionCall> calls;  ///< every call of a function checked
  const CheckedClass* root = nullptr;                  ///< the model compiled
};

/// Where classes not declared in the file come from: the driver searches the library path
/// (QDOT_PATH, the standard library) for a top-level package or class and parses it on first use.
struct Library {
  std::function<const ast::ClassDef*(const std::string& name)> find;
  std::string searchPath;  ///< the directories searched, for "not found" messages
};

/// Chooses the model named `modelName` (or, if empty, the last model of the file) and checks it
/// and every class it uses. Returns nullopt if there is no such model; otherwise the checked model
/// even if errors were reported (the caller decides by diags.hasErrors()).
std::optional<CheckedModel> checkModel(const ast::StoredDefinition& file, std::string_view modelName,
                                       DiagnosticEngine& diags, const Library& library = {});

/// The built-in functions a model may call and their arities (min, max; max -1 = any).
struct BuiltinFunction {
  const char* name;
  int minArgs;
  int maxArgs;
};
const BuiltinFunction* findBuiltin(std::string_view name);

/// Closest candidate by edit distance (for "did you mean"), or empty if none is close.
std::string closestName(std::string_view name, const std::vector<std::string>& candidates);

}  // namespace qdot::sema
