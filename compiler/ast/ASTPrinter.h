// Text forms of the AST: an indented tree dump with @line:col on every node (qdot --emit=ast,
// golden tests) and an expression printer back to source syntax (for messages).
#pragma once

#include <ostream>
#include <string>

#include "ast/AST.h"
#include "support/SourceManager.h"

namespace qdot::ast {

/// Writes a deterministic, indented dump of `def`: one node per line, two spaces per level,
/// each node followed by `@line:col` of its first character.
void printAST(std::ostream& os, const StoredDefinition& def, const SourceManager& sm);

/// Dumps one expression tree in the format of printAST, starting at `indent` levels.
void printExpr(std::ostream& os, const Expr& e, const SourceManager& sm, int indent = 0);

/// The expression in source syntax with the fewest parentheses that keep its structure:
/// `-x^2`, `(a + b)*c`, `sum(x[i] for i in 1:n)`, `{1, 2}`.
std::string toSource(const Expr& e);

/// A number as toSource writes it: integers without a fraction, others in shortest round-trip form.
std::string formatNumber(double value, bool isInteger);

}  // namespace qdot::ast
