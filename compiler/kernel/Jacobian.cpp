// differentiate: each equation's gradient over the unknowns it contains comes from one sparse pass
// (sym::PartialDerivatives), so the work is proportional to the nonzeros and to what they depend
// on, not to n² (nor to n per symbol, as Context::diff would be once symbols alias in the mask).
#include "kernel/Jacobian.h"

#include <algorithm>
#include <optional>
#include <unordered_map>

#include "support/Assert.h"
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
  int32_t templateEntry = -1;  // ≥ 0: JacobianEntries::templateEntries[templateEntry] at point `point`
  uint32_t point = 0;
};

// Row order (stable) by counting: template entries come block by block, not in row order.
std::vector<Entry> sortedByRow(const std::vector<Entry>& entries, size_t rows) {
  std::vector<uint32_t> start(rows + 1, 0);
  for (const Entry& e : entries) ++start[e.row + 1];
  for (size_t r = 0; r < rows; ++r) start[r + 1] += start[r];
  std::vector<Entry> sorted(entries.size());
  for (const Entry& e : entries) sorted[start[e.row]++] = e;
  return sorted;
}

// CSC order from entries that are already in row order: a stable counting sort by column.
JacobianEntries compress(const std::vector<Entry>& entries, size_t columns, std::vector<TemplateEntry> templates) {
  JacobianEntries J;
  J.templateEntries = std::move(templates);
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
    if (e.templateEntry >= 0) J.templateEntries[e.templateEntry].positions[e.point] = static_cast<uint32_t>(at);
  }
  return J;
}

// Where relative symbol `rel` of `block` reads: the unknown of the array element with linear index
// 0 (possibly not an element the block reads, or not an unknown at all: only an index base) and
// whether it is y'. Every element the block reads — its region shifted by the pattern's offsets —
// must be the unknown base + its linear index, of one kind: the loop addresses them so.
std::pair<int, bool> unknownsRead(const dae::TemplateBlock& block, const flat::RelativeElement& rel,
                                  const flat::ArrayVariable& a,
                                  const std::unordered_map<sym::Expr, std::pair<int, bool>>& unknownOf) {
  std::optional<std::pair<int, bool>> base;
  flat::forEachPoint(block.region, [&](std::span<const long> p, size_t) {
    long k = 0;
    for (size_t d = 0; d < p.size(); ++d) k = k * a.shape[d] + (p[d] + rel.dims[d].offset - 1);
    auto e = unknownOf.find(a.elements[static_cast<size_t>(k)]);
    if (e == unknownOf.end()) QDOT_UNREACHABLE("a template reads an array element that is not an unknown");
    std::pair<int, bool> at{e->second.first - static_cast<int>(k), e->second.second};
    if (base && *base != at) QDOT_UNREACHABLE("a template reads array elements that are not consecutive unknowns");
    base = at;
  });
  return base.value_or(std::pair{0, false});
}

// The entries of block b: ∂F/∂y + cj ∂F/∂y' per column pattern, then one Entry per point.
void templateEntries(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj, size_t b, std::span<const TemplateOperand> operands,
                     std::vector<TemplateEntry>& out, std::vector<Entry>& entries) {
  const dae::TemplateBlock& block = dae.templateBlocks[b];
  size_t first = out.size();
  for (const TemplateOperand& op : operands) {
    sym::Expr d = ctx.diff(block.residual, op.symbol);
    if (d->isZero()) continue;
    if (op.derivative) d = ctx.mul(cj, d);
    auto same = std::find_if(out.begin() + static_cast<long>(first), out.end(),
                             [&](const TemplateEntry& e) { return e.variable == op.variable && e.offset == op.offset; });
    if (same != out.end()) same->value = ctx.add(same->value, d);
    else out.push_back({static_cast<int>(b), d, op.variable, op.offset, {}});
  }
  size_t points = flat::pointCount(block.region);
  for (size_t e = first; e < out.size(); ++e) out[e].positions.resize(points);
  flat::forEachPoint(block.region, [&](std::span<const long> p, size_t c) {
    long at = flat::linearIndex(block.shape, p);
    for (size_t e = first; e < out.size(); ++e)
      entries.push_back({static_cast<int32_t>(block.firstRow + at), static_cast<int32_t>(out[e].variable + at + out[e].offset),
                         nullptr, static_cast<int32_t>(e), static_cast<uint32_t>(c)});
  });
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
    if (!f) continue;  // a template block's row
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
  std::vector<TemplateEntry> templates;
  std::vector<std::vector<TemplateOperand>> operands = templateOperands(dae, ctx);
  for (size_t b = 0; b < dae.templateBlocks.size(); ++b) templateEntries(dae, ctx, cj, b, operands[b], templates, entries);
  if (!templates.empty()) entries = sortedByRow(entries, dae.equations.size());
  JacobianEntries J = compress(entries, n, std::move(templates));
  J.templateOperands = std::move(operands);
  return J;
}

std::vector<std::vector<TemplateOperand>> templateOperands(const dae::Dae& dae, const sym::Context& ctx) {
  std::vector<std::vector<TemplateOperand>> out(dae.templateBlocks.size());
  if (out.empty()) return out;
  std::unordered_map<sym::Expr, std::pair<int, bool>> unknownOf;  // element symbol → variable, is y'
  unknownOf.reserve(2 * dae.variables.size());
  for (int j = 0; j < static_cast<int>(dae.variables.size()); ++j) {
    unknownOf.emplace(dae.variables[j].y, std::pair{j, false});
    if (dae.variables[j].yp) unknownOf.emplace(dae.variables[j].yp, std::pair{j, true});
  }
  for (size_t b = 0; b < out.size(); ++b) {
    const dae::TemplateBlock& block = dae.templateBlocks[b];
    for (sym::Expr s : ctx.freeSymbols(block.residual)) {
      const flat::RelativeElement* rel = dae.patterns->find(s);
      if (!rel) continue;
      auto [variable, derivative] = unknownsRead(block, *rel, dae.patterns->arrays[rel->array], unknownOf);
      long offset = 0;
      for (size_t d = 0; d < rel->dims.size(); ++d) offset = offset * block.shape[d] + rel->dims[d].offset;
      out[b].push_back({s, variable, derivative, offset});
    }
  }
  return out;
}

}  // namespace qdot::kernel
