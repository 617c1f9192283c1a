// The symbolic Jacobian J = dF/dy + cj*dF/dy' of a DAE in compressed sparse column form: column j
// is variable j; an entry exists where the derivative is not identically zero (for a state both
// dF/dy_j and cj*dF/dy'_j land in the same entry).
#pragma once

#include "dae/Dae.h"

namespace qdot::kernel {

struct JacobianEntries {
  std::vector<int32_t> columnStarts;  ///< [nVariables + 1]
  std::vector<int32_t> rowIndices;    ///< ascending within each column
  std::vector<sym::Expr> values;      ///< one expression per nonzero, in CSC order (uses the symbol cj)
};

/// Differentiates every residual with respect to the variables it mentions: one sparse forward pass
/// (sym::PartialDerivatives), O(Σ over the residuals' nodes of the unknowns each contains).
JacobianEntries differentiate(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj);

}  // namespace qdot::kernel
