// Text form of a FlatModel (`--emit=flat`, golden tests): one item per line in the model's own
// order, expressions printed as `qdot equations` prints them, each item followed by the line it
// came from (`utube.qd:14`).
#pragma once

#include <iosfwd>
#include <string>

#include "flatten/FlatModel.h"
#include "support/SourceManager.h"

namespace qdot::flat {

/// Writes every variable (role, start, fixed, nominal, bounds, parameter binding), the T, V and D
/// terms, the forces, equations, constraints, outputs and the experiment of `m`.
void printFlatModel(std::ostream& os, const FlatModel& m, const sym::Context& ctx, const SourceManager& sm);

/// "utube.qd:14": the file and line where `r` begins ("" for an invalid range). The later stages'
/// printers use it too, so every stage shows origins alike.
std::string lineOf(const SourceManager& sm, SourceRange r);

/// "experiment: StopTime = 10, Interval = 0.01" (the annotation's values, shortest round-trip form).
void printExperiment(std::ostream& os, const Experiment& e);

/// "sum(body for %1 in 1:9)": a sum kept as a template (an output's), its iterators as %1, %2, ….
std::string sumText(const IndexedTerm& sum, const sym::Context& ctx);

/// The kind of an equation's origin in words: "equation", "Euler-Lagrange row", "constraint" ...
const char* originKindName(OriginKind k);

}  // namespace qdot::flat
