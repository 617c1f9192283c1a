// differentiate: each equation's gradient over the unknowns it contains comes from one sparse pass
// (sym::PartialDerivatives), so the work is proportional to the nonzeros and to what they depend
// on, not to n² (nor to n per symbol, as Context::diff would be once symbols alias in the mask).
#include "kernel/Jacobian.h"

#include "symbolic/NodeMap.h"

namespace qdot::kernel {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The DAE's unknowns as distinct symbols (every y and y'), with the variable each one belongs to.
// A symbol listed twice belongs to the last variable naming it.
struct Unknowns {
  std::vector<sym::Expr> symbols;
  std::vector<int32_t> variableOf;   // by position in symbols
  std::vector<uint32_t> positionOf;  // by symbolId; kNone: not an unknown

  explicit Unknowns(const dae::Dae& dae) {
    for (int32_t j = 0; j < static_cast<int32_t>(dae.variables.size()); ++j) {
      add(dae.variables[j].y, j);
      if (dae.variables[j].yp) add(dae.variables[j].yp, j);
    }
  }
  void add(sym::Expr s, int32_t j) {
    if (positionOf.size() <= s->symbolId) positionOf.resize(s->symbolId + 1, kNone);
    uint32_t& k = positionOf[s->symbolId];
    if (k == kNone) k = static_cast<uint32_t>(symbols.size()), symbols.push_back(s), variableOf.push_back(j);
    else variableOf[k] = j;
  }
};

struct Entry {
  int32_t row, column;
  sym::Expr value;
};

// CSC order from entries that are already in row order: a stable counting sort by column.
JacobianEntries compress(const std::vector<Entry>& entries, size_t columns) {
  JacobianEntries J;
  J.columnStarts.assign(columns + 1, 0);
  for (const Entry& e : entries) ++J.columnStarts[e.column + 1];
  for (size_t j = 0; j < columns; ++j) J.columnStarts[j + 1] += J.columnStarts[j];
  std::vector<int32_t> next(J.columnStarts.begin(), J.columnStarts.end() - 1);
  J.rowIndices.resize(entries.size());
  J.values.resize(entries.size());
  for (const Entry& e : entries) {
    int32_t at = next[e.column]++;
    J.rowIndices[at] = e.row;
    J.values[at] = e.value;
  }
  return J;
}

}  // namespace

JacobianEntries differentiate(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj) {
  size_t n = dae.variables.size();
  Unknowns unknowns(dae);
  sym::PartialDerivatives partial(ctx, unknowns.symbols);
  std::vector<sym::Expr> byPosition(unknowns.symbols.size(), ctx.zero());  // the row's gradient
  auto derivative = [&](sym::Expr s) { return byPosition[unknowns.positionOf[s->symbolId]]; };
  sym::NodeMap<sym::Expr> timesCj;  // dF/dy' -> cj*dF/dy' (few distinct ones in a regular model)
  auto cjTimes = [&](sym::Expr dyp) {
    if (const sym::Expr* known = timesCj.find(dyp)) return *known;
    sym::Expr r = ctx.mul(cj, dyp);
    timesCj.insert(dyp, r);
    return r;
  };
  std::vector<Entry> entries;
  std::vector<int32_t> candidates;
  std::vector<char> seen(n, 0);
  for (size_t i = 0; i < dae.equations.size(); ++i) {
    sym::Expr f = dae.equations[i].residual;
    std::span<const sym::Expr> gradient = partial.gradient(f);
    std::span<const uint32_t> symbols = partial.symbolsIn(f);
    candidates.clear();
    for (size_t k = 0; k < symbols.size(); ++k) {
      byPosition[symbols[k]] = gradient[k];
      int32_t j = unknowns.variableOf[symbols[k]];
      if (!seen[j]) seen[j] = 1, candidates.push_back(j);
    }
    for (int32_t j : candidates) {
      seen[j] = 0;
      const dae::Variable& v = dae.variables[j];
      sym::Expr d = derivative(v.y), dyp = v.yp ? derivative(v.yp) : ctx.zero();
      if (dyp != ctx.zero()) d = ctx.add(d, cjTimes(dyp));  // d + cj*0 is d
      if (!d->isZero()) entries.push_back({static_cast<int32_t>(i), j, d});
    }
    for (uint32_t k : symbols) byPosition[k] = ctx.zero();
  }
  return compress(entries, n);
}

}  // namespace qdot::kernel
