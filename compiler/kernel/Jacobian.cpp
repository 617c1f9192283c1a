// differentiate: each scalar row's gradient over the unknowns it contains comes from one sparse pass
// (sym::PartialDerivatives), so the work is proportional to the nonzeros and to what they depend
// on, not to n² (nor to n per symbol, as Context::diff would be once symbols alias in the mask).
// A template block is differentiated once; its rows' entries are only counted and placed, never
// listed one by one, so the pattern of a model of 10⁶ elements costs its CSC arrays and little else.
#include "kernel/Jacobian.h"

#include <algorithm>
#include <optional>

#include "kernel/SymbolSlots.h"
#include "support/Assert.h"
#include "symbolic/NodeMap.h"

namespace qdot::kernel {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

// The distinct unknowns the scalar rows read, for sym::PartialDerivatives: every y and y' when no
// template serves rows (each is read somewhere), else those found in one walk of the scalar rows
// (a few boundary rows next to millions of template elements).
std::vector<sym::Expr> scalarUnknowns(const dae::Dae& dae, std::span<const int32_t> rows, const UnknownSymbols& unknowns) {
  std::vector<sym::Expr> out;
  sym::NodeSet seen;
  auto visit = [&](sym::Expr s) {
    if (seen.insert(s)) out.push_back(s);
  };
  if (!dae.templated()) {
    for (const dae::Variable& v : dae.variables) {
      visit(v.y);
      if (v.yp) visit(v.yp);
    }
    return out;
  }
  std::vector<sym::Expr> stack;
  auto push = [&](sym::Expr e) {
    if (e->symbolMask && seen.insert(e)) stack.push_back(e);
  };
  for (int32_t i : rows) push(dae.equations[i].residual);
  while (!stack.empty()) {
    sym::Expr n = stack.back();
    stack.pop_back();
    if (n->isSymbol() && unknowns.find(n)) out.push_back(n);
    for (sym::Expr c : n->args) push(c);
    for (sym::Expr c : n->exps()) push(c);
  }
  return out;
}

// An entry of a scalar row before the pattern is laid out.
struct RowEntry {
  int32_t row, column;
  sym::Expr value;
};

// The entries of the scalar rows, in row order.
std::vector<RowEntry> scalarEntries(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj, const UnknownSymbols& unknowns) {
  std::vector<int32_t> rows;  // those with a residual of their own (not a template block's)
  for (size_t i = 0; i < dae.equations.size(); ++i)
    if (dae.equations[i].residual) rows.push_back(static_cast<int32_t>(i));
  std::vector<sym::Expr> symbols = scalarUnknowns(dae, rows, unknowns);
  std::vector<int32_t> variableOf;  // by position in symbols
  SymbolSlots<uint32_t> positionOf(kNone);
  for (sym::Expr s : symbols) {
    positionOf.at(s->symbolId) = static_cast<uint32_t>(variableOf.size());
    variableOf.push_back(static_cast<int32_t>(unknowns.find(s)->variable));
  }
  sym::PartialDerivatives partial(ctx, symbols);
  std::vector<sym::Expr> byPosition(symbols.size(), ctx.zero());  // the row's gradient
  auto derivative = [&](sym::Expr s) {
    uint32_t k = positionOf.get(s->symbolId);
    return k == kNone ? ctx.zero() : byPosition[k];
  };
  sym::NodeMap<sym::Expr> timesCj;  // dF/dy' -> cj*dF/dy' (few distinct ones in a regular model)
  auto cjTimes = [&](sym::Expr dyp) {
    if (const sym::Expr* known = timesCj.find(dyp)) return *known;
    sym::Expr r = ctx.mul(cj, dyp);
    timesCj.insert(dyp, r);
    return r;
  };
  std::vector<RowEntry> entries;
  std::vector<int32_t> candidates;
  std::vector<char> seen(dae.variables.size(), 0);
  for (int32_t i : rows) {
    sym::Expr f = dae.equations[i].residual;
    std::span<const sym::Expr> gradient = partial.gradient(f);
    std::span<const uint32_t> listed = partial.symbolsIn(f);
    candidates.clear();
    for (size_t k = 0; k < listed.size(); ++k) {
      byPosition[listed[k]] = gradient[k];
      int32_t j = variableOf[listed[k]];
      if (!seen[j]) seen[j] = 1, candidates.push_back(j);
    }
    for (int32_t j : candidates) {
      seen[j] = 0;
      const dae::Variable& v = dae.variables[j];
      sym::Expr d = derivative(v.y), dyp = v.yp ? derivative(v.yp) : ctx.zero();
      if (dyp != ctx.zero()) d = ctx.add(d, cjTimes(dyp));  // d + cj*0 is d
      if (!d->isZero()) entries.push_back({i, j, d});
    }
    for (uint32_t k : listed) byPosition[k] = ctx.zero();
  }
  return entries;
}

using ElementBase = std::pair<int, bool>;  // (variable − linear index, y') of an array's elements

// The base every element of array `a` shares when all of them are consecutive unknowns of one kind
// (as a coordinate array's elements are): found once per array, whereas several relative symbols
// of several blocks read each array.
std::optional<ElementBase> uniformBase(const flat::ArrayVariable& a, const UnknownSymbols& unknowns) {
  std::optional<ElementBase> base;
  for (size_t k = 0; k < a.elements.size(); ++k) {
    std::optional<UnknownSymbols::Unknown> e = unknowns.find(a.elements[k]);
    if (!e) return std::nullopt;
    ElementBase at{static_cast<int>(e->variable) - static_cast<int>(k), e->derivative};
    if (base && *base != at) return std::nullopt;
    base = at;
  }
  return base;
}

// Where relative symbol `rel` of a template over `region` reads: the unknown of the array element
// with linear index 0 (possibly not an element the template reads, or not an unknown at all: only
// an index base) and whether it is y'. Every element it reads — the region shifted by the
// pattern's offsets — must be the unknown base + its linear index, of one kind: the loop
// addresses them so.
ElementBase unknownsRead(const flat::Box& region, const flat::RelativeElement& rel, const flat::ArrayVariable& a,
                         const UnknownSymbols& unknowns) {
  std::optional<ElementBase> base;
  flat::forEachPoint(region, [&](std::span<const long> p, size_t) {
    long k = 0;
    for (size_t d = 0; d < p.size(); ++d) k = k * a.shape[d] + (p[d] + rel.dims[d].offset - 1);
    std::optional<UnknownSymbols::Unknown> e = unknowns.find(a.elements[static_cast<size_t>(k)]);
    if (!e) QDOT_UNREACHABLE("a template reads an array element that is not an unknown");
    ElementBase at{static_cast<int>(e->variable) - static_cast<int>(k), e->derivative};
    if (base && *base != at) QDOT_UNREACHABLE("a template reads array elements that are not consecutive unknowns");
    base = at;
  });
  return base.value_or(ElementBase{0, false});
}

// The parameter index of the first element of an array whose element k is parameter first + k
// (ldpl reads p[first + linear index]), or -1. `parameterOf`: by symbol id, the parameter or -1.
int parameterBase(const flat::ArrayVariable& a, const std::vector<int>& parameterOf) {
  auto of = [&](sym::Expr e) {
    return e->isSymbol() && e->symbolId < parameterOf.size() ? parameterOf[e->symbolId] : -1;
  };
  int first = a.elements.empty() ? -1 : of(a.elements[0]);
  for (size_t k = 1; first >= 0 && k < a.elements.size(); ++k)
    if (of(a.elements[k]) != first + static_cast<int>(k)) return -1;
  return first;
}

// Subscript d is the template's iterator d plus a constant, and the array has the template's
// strides (its shape in more than one dimension): element index = the linear index + the offset.
bool loopsAlong(const flat::RelativeElement& rel, const flat::ArrayVariable& a, const std::vector<int>& shape) {
  if (rel.dims.size() != shape.size() || (rel.dims.size() > 1 && a.shape != shape)) return false;
  for (size_t d = 0; d < rel.dims.size(); ++d)
    if (rel.dims[d].iterator != static_cast<int>(d)) return false;
  return true;
}

// Per symbol id, the index of the parameter it is (-1: none); empty without templates.
std::vector<int> parameterIndices(const dae::Dae& dae) {
  std::vector<int> of;
  if (!dae.patterns) return of;
  for (size_t k = 0; k < dae.parameters.size(); ++k) {
    uint32_t id = dae.parameters[k].symbol->symbolId;
    if (of.size() <= id) of.resize(id + 1, -1);
    of[id] = static_cast<int>(k);
  }
  return of;
}

}  // namespace

LoopOperands::LoopOperands(const dae::Dae& dae, const sym::Context& ctx, const UnknownSymbols& unknowns)
    : dae_(dae), ctx_(ctx), unknowns_(unknowns), parameterOf_(parameterIndices(dae)) {
  size_t arrays = dae.patterns ? dae.patterns->arrays.size() : 0;
  looked_.assign(arrays, 0);
  uniform_.assign(arrays, std::nullopt);
  parameters_.assign(arrays, -1);
}

// The relative symbols of a template with where they are read: an array of unknowns, or of
// parameters consecutive in p, indexed by the template's iterators in order (of its shape in more
// than one dimension) — the pipeline keeps templates only then.
std::vector<TemplateOperand> LoopOperands::read(const std::vector<int>& shape, const flat::Box& region, sym::Expr e) {
  std::vector<TemplateOperand> out;
  for (sym::Expr s : ctx_.freeSymbols(e)) {
    const flat::RelativeElement* rel = dae_.patterns ? dae_.patterns->find(s) : nullptr;
    if (!rel) continue;
    const flat::ArrayVariable& a = dae_.patterns->arrays[rel->array];
    if (!looked_[rel->array]) {
      looked_[rel->array] = 1;
      parameters_[rel->array] = parameterBase(a, parameterOf_);
      if (parameters_[rel->array] < 0) uniform_[rel->array] = uniformBase(a, unknowns_);
    }
    long offset = 0;
    for (size_t d = 0; d < rel->dims.size(); ++d) offset = offset * shape[d] + rel->dims[d].offset;
    if (int first = parameters_[rel->array]; first >= 0) {
      QDOT_ASSERT(loopsAlong(*rel, a, shape), "a template reads a parameter array across its iterators");
      out.push_back({s, first, false, true, offset});
      continue;
    }
    auto [variable, derivative] = uniform_[rel->array] ? *uniform_[rel->array] : unknownsRead(region, *rel, a, unknowns_);
    out.push_back({s, variable, derivative, false, offset});
  }
  return out;
}

namespace {

// The entries of block b: ∂F/∂y + cj ∂F/∂y' per column pattern (positions are sized, not yet
// given): the relative symbols' (the operands), then the unknowns the rows read as themselves.
void templateEntries(const dae::Dae& dae, sym::Context& ctx, sym::Expr cj, size_t b, std::span<const TemplateOperand> operands,
                     const UnknownSymbols& unknowns, std::vector<TemplateEntry>& out) {
  const dae::TemplateBlock& block = dae.templateBlocks[b];
  size_t first = out.size();
  auto add = [&](sym::Expr symbol, bool derivative, int variable, long offset, bool fixed) {
    sym::Expr d = ctx.diff(block.residual, symbol);
    if (d->isZero()) return;
    if (derivative) d = ctx.mul(cj, d);
    auto same = std::find_if(out.begin() + static_cast<long>(first), out.end(), [&](const TemplateEntry& e) {
      return e.fixed == fixed && e.variable == variable && e.offset == offset;
    });
    if (same != out.end()) same->value = ctx.add(same->value, d);
    else out.push_back({static_cast<int>(b), d, variable, offset, {}, fixed});
  };
  for (const TemplateOperand& op : operands)
    if (!op.parameter) add(op.symbol, op.derivative, op.variable, op.offset, false);
  for (sym::Expr s : ctx.freeSymbols(block.residual))
    if (std::optional<UnknownSymbols::Unknown> u = unknowns.find(s))
      add(s, u->derivative, static_cast<int>(u->variable), 0, true);
  for (size_t e = first; e < out.size(); ++e) out[e].positions.resize(flat::pointCount(block.region));
}

// The CSC pattern: rowIndices ascending within each column, so the entries are placed row by row.
// A template block's row at linear index `at` of its array has, per entry e, column
// e.variable + at + e.offset; nothing per nonzero is kept but the CSC arrays themselves.
class PatternLayout {
 public:
  PatternLayout(const dae::Dae& dae, JacobianEntries& J) : dae_(dae), J_(J), blockOf_(dae.equations.size(), -1) {
    entriesOf_.assign(dae.templateBlocks.size() + 1, 0);
    for (const TemplateEntry& e : J.templateEntries) ++entriesOf_[e.block + 1];
    for (size_t b = 0; b < dae.templateBlocks.size(); ++b) entriesOf_[b + 1] += entriesOf_[b];
    for (size_t b = 0; b < dae.templateBlocks.size(); ++b) {
      const dae::TemplateBlock& block = dae.templateBlocks[b];
      flat::forEachPoint(block.region, [&](std::span<const long> p, size_t) {
        blockOf_[block.firstRow + flat::linearIndex(block.shape, p)] = static_cast<int32_t>(b);
      });
    }
  }

  // The scalar rows' entries (in row order) are placed with the template rows'.
  void run(const std::vector<RowEntry>& scalar) {
    countColumns(scalar);
    std::vector<int32_t> next(J_.columnStarts.begin(), J_.columnStarts.end() - 1);
    J_.rowIndices.resize(static_cast<size_t>(J_.columnStarts.back()));
    std::vector<uint32_t> point(dae_.templateBlocks.size(), 0);  // per block: the point of its next row
    auto place = [&](int32_t row, int32_t column) {
      int32_t at = next[column]++;
      J_.rowIndices[at] = row;
      return static_cast<uint32_t>(at);
    };
    std::vector<uint32_t> position(scalar.size());  // of scalar[k]
    size_t s = 0;
    for (int32_t row = 0; row < static_cast<int32_t>(blockOf_.size()); ++row) {
      int32_t b = blockOf_[row];
      if (b < 0) {
        for (; s < scalar.size() && scalar[s].row == row; ++s) position[s] = place(row, scalar[s].column);
        continue;
      }
      uint32_t c = point[b]++;
      long at = row - dae_.templateBlocks[b].firstRow;
      for (size_t e = entriesOf_[b]; e < entriesOf_[b + 1]; ++e) {
        TemplateEntry& t = J_.templateEntries[e];
        t.positions[c] = place(row, t.column(at));
      }
    }
    J_.scalarEntries = inPositionOrder(scalar, position);
  }

 private:
  void countColumns(const std::vector<RowEntry>& scalar) {
    std::vector<int32_t>& starts = J_.columnStarts;
    starts.assign(dae_.variables.size() + 1, 0);
    for (const RowEntry& e : scalar) ++starts[e.column + 1];
    for (size_t b = 0; b < dae_.templateBlocks.size(); ++b) {
      const dae::TemplateBlock& block = dae_.templateBlocks[b];
      flat::forEachPoint(block.region, [&](std::span<const long> p, size_t) {
        long at = flat::linearIndex(block.shape, p);
        for (size_t e = entriesOf_[b]; e < entriesOf_[b + 1]; ++e) {
          const TemplateEntry& t = J_.templateEntries[e];
          ++starts[t.column(at) + 1];
        }
      });
    }
    for (size_t j = 0; j + 1 < starts.size(); ++j) starts[j + 1] += starts[j];
  }

  // Position order is column order, rows ascending: a stable counting sort of the row-ordered list.
  std::vector<ScalarEntry> inPositionOrder(const std::vector<RowEntry>& scalar, const std::vector<uint32_t>& position) const {
    std::vector<uint32_t> start(dae_.variables.size() + 1, 0);
    for (const RowEntry& e : scalar) ++start[e.column + 1];
    for (size_t j = 0; j + 1 < start.size(); ++j) start[j + 1] += start[j];
    std::vector<ScalarEntry> sorted(scalar.size());
    for (size_t k = 0; k < scalar.size(); ++k) sorted[start[scalar[k].column]++] = {position[k], scalar[k].row, scalar[k].value};
    return sorted;
  }

  const dae::Dae& dae_;
  JacobianEntries& J_;
  std::vector<int32_t> blockOf_;    // per row: the template block serving it, or -1 (a scalar row)
  std::vector<size_t> entriesOf_;  // block b's entries: templateEntries[entriesOf_[b], entriesOf_[b + 1])
};

}  // namespace

JacobianEntries differentiate(const dae::Dae& dae, const UnknownSymbols& unknowns, sym::Context& ctx, sym::Expr cj) {
  std::vector<RowEntry> scalar = scalarEntries(dae, ctx, cj, unknowns);
  JacobianEntries J;
  LoopOperands operands(dae, ctx, unknowns);
  for (const dae::TemplateBlock& block : dae.templateBlocks)
    J.templateOperands.push_back(operands.read(block.shape, block.region, block.residual));
  for (size_t b = 0; b < dae.templateBlocks.size(); ++b)
    templateEntries(dae, ctx, cj, b, J.templateOperands[b], unknowns, J.templateEntries);
  PatternLayout(dae, J).run(scalar);
  return J;
}

}  // namespace qdot::kernel
