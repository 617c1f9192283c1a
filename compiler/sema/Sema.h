// Sema: the semantic checks of one flat model (spec §3–§6) before anything is expanded.
// Takes the parsed tree, picks the model to compile, builds its scope and checks declarations
// (duplicates, types, array sizes) and every name and call in every expression, with located
// diagnostics. Hands a CheckedModel (scope + the class) to flatten; it evaluates nothing.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "ast/AST.h"
#include "support/Diagnostic.h"

namespace qdot::sema {

/// What a declared name is, which decides how flatten treats it.
enum class SymbolKind {
  Constant,          ///< `constant` (any type): folded at compile time
  IntegerParameter,  ///< `parameter Integer`: sizes arrays, folded at compile time
  Parameter,         ///< `parameter Real|Boolean`: a run-time input
  Coordinate,        ///< `coordinate Real`: a generalized coordinate
  Unknown,           ///< `Real x;` without binding (state or algebraic)
  Definition,        ///< `Real y = expr;` (also `output Real y = expr;`): substituted
  Input,             ///< `input Real u;` without binding: of the model compiled, a run-time input
                     ///< (a parameter whose default is 0, the B columns of `qdot linearize`)
};

enum class BaseType { Real, Integer, Boolean };

struct ModelSymbol {
  const ast::Declaration* decl = nullptr;
  SymbolKind kind = SymbolKind::Unknown;
  BaseType type = BaseType::Real;
};

/// The model to compile with its scope. Points into the AST, which must outlive it.
struct CheckedModel {
  const ast::ClassDef* cls = nullptr;
  std::unordered_map<std::string, ModelSymbol> symbols;
  std::vector<const ast::Declaration*> declarations;  ///< in source order
};

/// Chooses the model named `modelName` (or, if empty, the last model of the file) and checks it.
/// Returns nullopt if there is no such model; otherwise the checked model even if errors were
/// reported (the caller decides by diags.hasErrors()).
std::optional<CheckedModel> checkModel(const ast::StoredDefinition& file, std::string_view modelName,
                                       DiagnosticEngine& diags);

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
