// The symbolic Jacobian J = dF/dy + cj*dF/dy' of a DAE in compressed sparse column form: column j
// is variable j; an entry exists where the derivative is not identically zero (for a state both
// dF/dy_j and cj*dF/dy'_j land in the same entry).
#pragma once

#include <optional>
#include <utility>
#include <vector>

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

/// Reads the relative symbols of templates (template blocks, an invariant's sums) as loop operands;
/// what it finds per array is kept for the next template.
class LoopOperands {
 public:
  LoopOperands(const dae::Dae& dae, const sym::Context& ctx, const UnknownSymbols& unknowns);
  /// The relative symbols of `e`, a template over `region` (subscripts or iterator values) whose
  /// arrays have `shape`, each with where a loop reads it.
  std::vector<TemplateOperand> read(const std::vector<int>& shape, const flat::Box& region, sym::Expr e);

 private:
  const dae::Dae& dae_;
  const sym::Context& ctx_;
  const UnknownSymbols& unknowns_;
  std::vector<int> parameterOf_;  // by symbol id: the parameter, or -1
  std::vector<char> looked_;      // by array: its base is known
  std::vector<std::optional<std::pair<int, bool>>> uniform_;  // by array: (variable − linear index, y')
  std::vector<int> parameters_;   // by array: its first parameter, or -1
};

/// One entry of a template block's rows: the value (over the block's relative symbols and cj) at
/// column variable + linear(row's subscripts) + offset — or, `fixed`, at column `variable` in every
/// row (an unknown the rows read as itself, a rerolled run's common unknown) — and its CSC position
/// per point of the block's region (row-major order, the order of the loop).
struct TemplateEntry {
  int block = -1;
  sym::Expr value = nullptr;
  int variable = -1;
  long offset = 0;
  std::vector<uint32_t> positions;
  bool fixed = false;

  int32_t column(long at) const { return static_cast<int32_t>(fixed ? variable : variable + at + offset); }
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
