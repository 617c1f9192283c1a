// The symbolic Jacobian J = dF/dy + cj*dF/dy' of a DAE in compressed sparse column form: column j
// is variable j; an entry exists where the derivative is not identically zero (for a state both
// dF/dy_j and cj*dF/dy'_j land in the same entry).
#pragma once

#include "dae/Dae.h"
#include "kernel/Unknowns.h"

namespace qdot::kernel {

/// How a relative symbol of a template block is read: the unknown of its array's element with
/// linear index 0 (y or y'), or for an array of parameters that element's parameter (p), and the
/// linear offset of its pattern (Σ offset_d · stride_d).
struct TemplateOperand {
  sym::Expr symbol = nullptr;
  int variable = -1;        ///< an unknown, or with `parameter` an index into p
  bool derivative = false;  ///< y' (else y)
  bool parameter = false;   ///< p (a constant of the rows: no Jacobian column)
  long offset = 0;
};

/// One entry of a template block's rows: the value (over the block's relative symbols and cj) at
/// column variable + linear(row's subscripts) + offset, and its CSC position per point of the
/// block's region (row-major order, the order of the loop).
struct TemplateEntry {
  int block = -1;
  sym::Expr value = nullptr;
  int variable = -1;
  long offset = 0;
  std::vector<uint32_t> positions;
};

/// One entry of a row that is not a template's: its CSC position, its row and its value.
struct ScalarEntry {
  uint32_t position = 0;
  int32_t row = 0;
  sym::Expr value = nullptr;  ///< uses the symbol cj
};

struct JacobianEntries {
  std::vector<int32_t> columnStarts;  ///< [nVariables + 1]
  std::vector<int32_t> rowIndices;    ///< ascending within each column
  /// The entries of scalar rows, ascending position; the other positions are templateEntries'.
  std::vector<ScalarEntry> scalarEntries;
  std::vector<TemplateEntry> templateEntries;
  std::vector<std::vector<TemplateOperand>> templateOperands;  ///< per template block
};

/// Differentiates every residual with respect to the variables it mentions: one sparse forward pass
/// (sym::PartialDerivatives) over the scalar rows, O(Σ over their nodes of the unknowns each
/// contains), and one derivative per column pattern of each template block. `unknowns`: dae's.
JacobianEntries differentiate(const dae::Dae& dae, const UnknownSymbols& unknowns, sym::Context& ctx, sym::Expr cj);

}  // namespace qdot::kernel
