// Exact solutions for `qdot wp --exact 'x = 0.05*cos(20*time)'`: the right side is a qdot
// expression of `time`, `pi` and the model's parameters, parsed by the project's parser (so it is
// written exactly as in a model) and evaluated directly on its syntax tree.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ast/AST.h"
#include "support/Diagnostic.h"
#include "support/SourceManager.h"

namespace qdot::driver {

/// One `NAME = EXPRESSION`, parsed and checked.
struct ExactSolution {
  std::string column;  ///< the result column it gives (a variable or output of the model)
  std::shared_ptr<const ast::StoredDefinition> tree;  ///< owns `value`
  const ast::Expr* value = nullptr;                   ///< the right side
};

/// The values names may take in an exact solution: the model's parameters by name (array
/// elements as `m[2]`).
using NameValues = std::map<std::string, double, std::less<>>;

/// Parses `text` given with --exact. Every problem is a diagnostic located in a buffer named
/// "--exact" holding `text` (missing '=', a syntax error, a column that is not in `columns`, an
/// unknown name or function, a wrong number of arguments); then nullopt.
std::optional<ExactSolution> parseExact(const std::string& text, const std::vector<std::string>& columns,
                                        const NameValues& names, SourceManager& sources, DiagnosticEngine& diags);

/// The value of a checked exact solution at time t.
double evaluateExact(const ExactSolution& exact, double time, const NameValues& names);

}  // namespace qdot::driver
