// Rows that repeat become loops again (issue 15, docs/loops.md "Rerolled rows"). A model the
// flattener expanded to scalars — arrays of components, a form the templates do not take — still
// has rows that are one row shifted along its unknowns and parameters: the spring-damper chain of
// library parts has a row per mass, each the one before over the next mass, link and parameters.
// Such runs of rows become TemplateBlocks, so that the kernels loop over them (one derivation of
// the Jacobian per run, code independent of n) whatever the earlier stages kept.
#pragma once

#include <cstddef>

#include "dae/Dae.h"

namespace qdot::dae {

struct RerollResult {
  size_t blocks = 0;        ///< template blocks made
  size_t rows = 0;          ///< rows they hold
  size_t outputBlocks = 0;  ///< output blocks made
  size_t outputs = 0;       ///< outputs they hold
};

/// Finds runs of at least `minimumRun` rows that are one expression over consecutive unknowns (the
/// same unknown, or the next one in the DAE's order, from row to row) and parameters (the same, or
/// one at a constant stride), and makes each a TemplateBlock: its rows are moved next to each other
/// (the derivative links and the Euler–Lagrange rows' coordinates move with them), its parameters
/// made consecutive in `parameters` where a stride separated them. The DAE must be scalar (no
/// template blocks), of index 1 (no differentiated rows) and without initial equations; otherwise,
/// or if nothing repeats, it is left as it was. Then the same for runs of consecutive outputs (their order is the result
/// columns', so it is kept), along the unknowns and parameters that are consecutive: OutputBlocks.
RerollResult rerollRows(Dae& dae, sym::Context& ctx, size_t minimumRun = 16);

}  // namespace qdot::dae
