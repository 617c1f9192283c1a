// Pipeline: runs the compiler stages in order on one file and keeps every stage's result, so the
// command line, the tests and the benchmarks all drive the compiler the same way.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <string_view>

#include "ast/AST.h"
#include "dae/Dae.h"
#include "flatten/Flatten.h"
#include "mechanics/EulerLagrange.h"
#include "sema/Sema.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"

namespace qdot::driver {

enum class Stage { Parse, Check, Flatten, Derive, Dae };

/// Wall time of each stage in seconds.
struct StageTimes {
  double parse = 0, check = 0, flatten = 0, derive = 0, dae = 0;
};

/// Everything one compilation creates; later stages point into earlier ones, so it is not copyable.
struct Compilation {
  SourceManager sources;
  DiagnosticEngine diags;
  sym::Context ctx;
  std::unique_ptr<ast::StoredDefinition> ast;
  std::optional<sema::CheckedModel> checked;
  std::optional<flat::FlatModel> flat;
  std::optional<mech::EquationsOfMotion> eom;
  std::optional<dae::Dae> dae;
  StageTimes times;
  flat::FlattenLimits limits;  ///< size limits of flattening (tests and fuzzing lower them)

  Compilation() = default;
  Compilation(const Compilation&) = delete;
  Compilation& operator=(const Compilation&) = delete;
};

/// Reads `path` and runs the stages up to `until` on the model `model` (empty: the file's last
/// model). Returns false if any stage reported an error (see c.diags).
bool compileFile(Compilation& c, const std::string& path, std::string_view model, Stage until);
/// The same for text in memory (tests, fuzzing); `name` is used in diagnostics.
bool compileSource(Compilation& c, std::string name, std::string text, std::string_view model, Stage until);

}  // namespace qdot::driver
