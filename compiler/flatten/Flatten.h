// Flatten: expands a checked model into a FlatModel (see FlatModel.h).
#pragma once

#include <optional>

#include "flatten/FlatModel.h"
#include "sema/Sema.h"
#include "support/Diagnostic.h"
#include "symbolic/Expr.h"

namespace qdot::flat {

/// Limits that keep hostile input from exhausting memory (a clear error instead).
struct FlattenLimits {
  size_t maxScalars = 20'000'000;  ///< total scalar elements across all arrays and loops
};

/// Expands arrays, loops, reductions and comprehensions; substitutes definitions and constants;
/// builds T, V, D, forces and equations. Returns nullopt if errors were reported.
std::optional<FlatModel> flatten(const sema::CheckedModel& model, sym::Context& ctx, DiagnosticEngine& diags,
                                 FlattenLimits limits = {});

}  // namespace qdot::flat
