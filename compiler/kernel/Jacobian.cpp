// differentiate: for each equation only the variables whose y or y' occurs in it are candidates
// (found with freeSymbols), so the work is proportional to the nonzeros, not to n².
#include "kernel/Jacobian.h"

#include <unordered_map>

namespace qdot::kernel {
namespace {

// Which variable a symbol is (as y or as y'), or -1.
class VariableIndex {
 public:
  explicit VariableIndex(const dae::Dae& dae) {
    for (int j = 0; j < static_cast<int>(dae.variables.size()); ++j) {
      index_[dae.variables[j].y] = j;
      if (dae.variables[j].yp) index_[dae.variables[j].yp] = j;
    }
  }
  int find(sym::Expr s) const {
    auto it = index_.find(s);
    return it == index_.end() ? -1 : it->second;
  }

 private:
  std::unordered_map<sym::Expr, int> index_;
};

}  // namespace

JacobianEntries differentiate(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj) {
  size_t n = dae.variables.size();
  VariableIndex index(dae);
  std::vector<std::vector<std::pair<int32_t, sym::Expr>>> columns(n);
  std::vector<char> seen(n, 0);
  for (size_t i = 0; i < dae.equations.size(); ++i) {
    sym::Expr f = dae.equations[i].residual;
    std::vector<int> candidates;
    for (sym::Expr s : ctx.freeSymbols(f)) {
      int j = index.find(s);
      if (j >= 0 && !seen[j]) seen[j] = 1, candidates.push_back(j);
    }
    for (int j : candidates) {
      seen[j] = 0;
      const dae::Variable& v = dae.variables[j];
      sym::Expr d = ctx.diff(f, v.y);
      if (v.yp) d = ctx.add(d, ctx.mul(cj, ctx.diff(f, v.yp)));
      if (!d->isZero()) columns[j].emplace_back(static_cast<int32_t>(i), d);
    }
  }
  JacobianEntries J;
  J.columnStarts.push_back(0);
  for (auto& col : columns) {  // rows were appended in increasing order
    for (auto& [row, value] : col) J.rowIndices.push_back(row), J.values.push_back(value);
    J.columnStarts.push_back(static_cast<int32_t>(J.rowIndices.size()));
  }
  return J;
}

}  // namespace qdot::kernel
