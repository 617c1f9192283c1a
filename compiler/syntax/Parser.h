// Public entry point of the front end: text of one .qd file in, ast::StoredDefinition and
// diagnostics out. The grammar and the error codes are in compiler/syntax/README.md.
#pragma once

#include <cstdint>
#include <memory>

#include "ast/AST.h"
#include "support/Diagnostic.h"
#include "support/SourceManager.h"

namespace qdot::syntax {

/// Parses one file. Reports problems into diags and always returns a tree (possibly partial).
/// In a tree parsed with errors, any expression field may be null; without errors, every
/// expression that the grammar requires is present.
std::unique_ptr<ast::StoredDefinition> parse(const SourceManager& sm, uint32_t file, DiagnosticEngine& diags);

/// The deepest nesting of expressions, modifications, equation blocks and classes the parser
/// accepts before it reports E0110.
inline constexpr int kMaxNestingDepth = 256;

}  // namespace qdot::syntax
