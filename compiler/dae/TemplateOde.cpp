// The DAE of a model whose `for` equations stayed templates (TemplateOde.h): the check that each
// row is matched to an unknown of its own, and its unknowns and rows, row j matched to unknown j.
#include "dae/TemplateOde.h"

#include <algorithm>
#include <initializer_list>

#include "flatten/Flatten.h"
#include "support/Assert.h"

namespace qdot::dae {
namespace {

using flat::VarRole;
using sym::Expr;

// The unknown whose derivative `rate` is, or -1.
int unknownOfRate(const flat::FlatModel& m, Expr rate) {
  int d = m.variableOf(rate);
  return d >= 0 && m.variables[d].role == VarRole::Derivative ? m.variables[d].derivativeOf : -1;
}

// The first unknown of an array whose element k is the unknown first + k (`unknownOf` maps an
// element to its unknown), or -1.
template <class UnknownOf>
int firstOfConsecutive(const flat::ArrayVariable& a, UnknownOf&& unknownOf) {
  int first = a.elements.empty() ? -1 : unknownOf(a.elements[0]);
  for (size_t k = 1; first >= 0 && k < a.elements.size(); ++k)
    if (unknownOf(a.elements[k]) != first + static_cast<int>(k)) return -1;
  return first;
}

// Subscript d is iterator d plus a constant, for each of the template's `iterators` dimensions.
bool indexedInOrder(const flat::RelativeElement& rel, size_t iterators) {
  if (rel.dims.size() != iterators) return false;
  for (size_t d = 0; d < iterators; ++d)
    if (rel.dims[d].iterator != static_cast<int>(d)) return false;
  return true;
}

// Time, parameters, and unknowns: states (every der() a variable of its own) and algebraic ones.
bool onlyUnknownsAndParameters(const flat::FlatModel& m) {
  for (const flat::Variable& v : m.variables) {
    bool ok = v.role == VarRole::Time || v.role == VarRole::Parameter || v.role == VarRole::Derivative ||
              v.role == VarRole::Unknown;
    if (!ok || v.alias) return false;
  }
  return true;
}

bool isAlgebraic(const flat::FlatModel& m, int v) {
  return v >= 0 && m.variables[v].role == VarRole::Unknown && m.variables[v].derivative < 0;
}

bool onlyEquations(const flat::FlatModel& m) {
  return m.indexedSums.empty() && m.kinetic.empty() && m.potential.empty() && m.dissipation.empty() &&
         m.forces.empty() && m.constraints.empty() && m.components.size() <= 1;
}

// The derivative symbols of a row (scalar variables or relative symbols of arrays of derivatives)
// and the other symbols it reads.
struct RowSymbols {
  std::vector<Expr> rates, others;
};

RowSymbols rowSymbols(const flat::FlatModel& m, const sym::Context& ctx, std::initializer_list<Expr> sides) {
  RowSymbols r;
  std::vector<Expr> symbols;
  for (Expr side : sides)
    for (Expr s : ctx.freeSymbols(side))
      if (std::find(symbols.begin(), symbols.end(), s) == symbols.end()) symbols.push_back(s);
  for (Expr s : symbols) {
    const flat::RelativeElement* rel = m.relativeElement(s);
    Expr element = rel ? m.patterns->arrays[rel->array].elements[0] : s;
    int v = m.variableOf(element);
    (v >= 0 && m.variables[v].role == VarRole::Derivative ? r.rates : r.others).push_back(s);
  }
  return r;
}

// `x[%1,…]`: subscripted by the iterators in order, without offsets.
bool ownElement(const flat::RelativeElement& rel, size_t iterators) {
  if (!indexedInOrder(rel, iterators)) return false;
  for (const auto& dim : rel.dims)
    if (dim.offset != 0) return false;
  return true;
}

// The unknown a row is matched to: the one whose derivative is its only derivative (a state's
// row: `der(x) = f`, `m*der(v)[%1] = f`), or, in a row without derivative, its only algebraic
// unknown (`f = k*(x - x0)`, `f[%1] = k*(x[%1] - x[%1-1])`): ∂F/∂y' (resp. ∂F/∂y of the algebraic
// unknowns) is then diagonal. For a template, the array (its first element's unknown).
class OdeCheck {
 public:
  OdeCheck(const flat::FlatModel& m, const sym::Context& ctx) : m_(m), ctx_(ctx), firstUnknown_(m.patterns->arrays.size(), -2) {}

  // The unknown a scalar row is matched to (over unknowns, parameters and time), or -1.
  int scalarRow(const flat::Equation& e) const {
    RowSymbols s = rowSymbols(m_, ctx_, {e.residual});
    int algebraic = -1, count = 0;
    for (Expr other : s.others) {
      int v = m_.variableOf(other);
      if (v < 0) return -1;
      if (isAlgebraic(m_, v)) algebraic = v, ++count;
    }
    if (s.rates.size() == 1) return unknownOfRate(m_, s.rates[0]);
    return s.rates.empty() && count == 1 ? algebraic : -1;
  }

  // The unknown of the first element of the array a template row is matched to, or -1. The row
  // reads arrays of unknowns and of parameters (ldpl) by the template's iterators in order.
  int templateRow(const flat::EquationTemplate& t) {
    RowSymbols s = rowSymbols(m_, ctx_, {t.lhs, t.rhs});
    const flat::ArrayVariable* own = ownArray(s, t.box.size());
    if (!own) return -1;
    int first = unknownOfElement(own->elements[0]);
    for (Expr other : s.others) {
      if (const flat::RelativeElement* rel = m_.relativeElement(other)) {
        if (flat::loopableParameters(m_, *rel, t.box.size(), own->shape)) continue;
        const flat::ArrayVariable& a = m_.patterns->arrays[rel->array];
        bool shaped = t.box.size() == 1 || a.shape == own->shape;
        if (!indexedInOrder(*rel, t.box.size()) || !shaped || firstUnknown(rel->array) < 0) return -1;
        continue;
      }
      if (m_.patterns->iteratorOf(other) >= 0) continue;  // an iterator's value: the loop gives it
      int v = m_.variableOf(other);
      if (v < 0 || (m_.variables[v].role != VarRole::Parameter && m_.variables[v].role != VarRole::Time)) return -1;
    }
    return first;
  }

  // The array whose elements' rows a template gives (of derivatives or of algebraic unknowns),
  // consecutive unknowns, or null.
  const flat::ArrayVariable* ownArray(const flat::EquationTemplate& t) {
    return ownArray(rowSymbols(m_, ctx_, {t.lhs, t.rhs}), t.box.size());
  }
  const flat::ArrayVariable* ownArray(const RowSymbols& s, size_t iterators) {
    const flat::RelativeElement* own = nullptr;
    if (s.rates.size() == 1) {
      own = m_.relativeElement(s.rates[0]);
    } else if (s.rates.empty()) {
      for (Expr other : s.others) {
        const flat::RelativeElement* rel = m_.relativeElement(other);
        if (!rel || !isAlgebraic(m_, m_.variableOf(m_.patterns->arrays[rel->array].elements[0]))) continue;
        if (own) return nullptr;  // two algebraic arrays, or two elements of one
        own = rel;
      }
    }
    if (!own || !ownElement(*own, iterators)) return nullptr;
    const flat::ArrayVariable& a = m_.patterns->arrays[own->array];
    return firstOfConsecutive(a, [&](Expr e) { return unknownOfElement(e); }) >= 0 ? &a : nullptr;
  }

  // The unknown an element stands for: x for der(x), the unknown itself otherwise; -1 if none.
  int unknownOfElement(Expr e) const {
    int v = m_.variableOf(e);
    if (v >= 0 && m_.variables[v].role == VarRole::Derivative) return m_.variables[v].derivativeOf;
    return v >= 0 && m_.variables[v].role == VarRole::Unknown ? v : -1;
  }

 private:
  const flat::FlatModel& m_;
  const sym::Context& ctx_;
  std::vector<int> firstUnknown_;  ///< per array: its first unknown if consecutive unknowns, -1 if not, -2 not yet known

  int firstUnknown(int array) {
    int& first = firstUnknown_[array];
    if (first == -2)
      first = firstOfConsecutive(m_.patterns->arrays[array], [&](Expr e) {
        int v = m_.variableOf(e);
        return v >= 0 && m_.variables[v].role == VarRole::Unknown ? v : -1;
      });
    return first;
  }
};

}  // namespace

bool initialEquationsAreStartValues(const flat::FlatModel& m, const sym::Context& ctx) {
  auto isState = [&](Expr s) {
    int v = m.variableOf(s);
    if (v < 0 || m.variables[v].alias) return false;
    VarRole r = m.variables[v].role;
    return r == VarRole::Coordinate || r == VarRole::Velocity || (r == VarRole::Unknown && m.variables[v].derivative >= 0);
  };
  auto overParameters = [&](Expr e) {
    for (Expr s : ctx.freeSymbols(e))
      if (int v = m.variableOf(s); v < 0 || (m.variables[v].role != VarRole::Parameter && m.variables[v].role != VarRole::Time))
        return false;
    return true;
  };
  return std::all_of(m.initialEquations.begin(), m.initialEquations.end(), [&](const flat::Equation& e) {
    return e.lhs && e.rhs && ((isState(e.lhs) && overParameters(e.rhs)) || (isState(e.rhs) && overParameters(e.lhs)));
  });
}

bool isTemplatedOde(const flat::FlatModel& m, const sym::Context& ctx) {
  if (m.equationTemplates.empty() || !onlyEquations(m) || !onlyUnknownsAndParameters(m) ||
      !initialEquationsAreStartValues(m, ctx))
    return false;
  std::vector<int> rows(m.variables.size(), 0);  // per unknown: the rows matched to it
  OdeCheck check(m, ctx);
  for (const flat::Equation& e : m.equations) {
    int x = check.scalarRow(e);
    if (x < 0) return false;
    ++rows[x];
  }
  for (const flat::EquationTemplate& t : m.equationTemplates) {
    int first = check.templateRow(t);
    if (first < 0) return false;
    const std::vector<int>& shape = check.ownArray(t)->shape;
    flat::forEachPoint(t.box, [&](std::span<const long> p, size_t) { ++rows[first + flat::linearIndex(shape, p)]; });
  }
  for (size_t i = 0; i < m.variables.size(); ++i)
    if (m.variables[i].role == VarRole::Unknown && rows[i] != 1) return false;
  return true;
}

void addTemplatedOde(const flat::FlatModel& m, sym::Context& ctx, Dae& dae) {
  std::vector<int> unknown(m.variables.size(), -1);  // flat variable → DAE variable
  for (int i = 0; i < static_cast<int>(m.variables.size()); ++i) {
    const flat::Variable& f = m.variables[i];
    if (f.role != VarRole::Unknown) continue;
    unknown[i] = static_cast<int>(dae.variables.size());
    bool state = f.derivative >= 0;
    dae.variables.push_back({.name = std::string(f.name), .kind = state ? VarKind::State : VarKind::Algebraic,
                             .role = state ? UnknownRole::State : UnknownRole::Algebraic, .flatVar = i, .y = f.symbol,
                             .yp = state ? m.variables[f.derivative].symbol : nullptr,
                             .declaration = Declaration::of(m, i)});
  }
  dae.equations.resize(dae.variables.size());
  std::vector<char> placed(dae.equations.size(), 0);
  auto place = [&](int row) {
    QDOT_ASSERT(row >= 0 && !placed[row], "a row of a templated ODE defined twice");
    placed[row] = 1;
  };
  OdeCheck check(m, ctx);
  for (const flat::Equation& e : m.equations) {
    int row = unknown[check.scalarRow(e)];
    place(row);
    dae.equations[row] = e;
  }
  for (const flat::EquationTemplate& t : m.equationTemplates) {
    const flat::ArrayVariable& own = *check.ownArray(t);
    int first = unknown[check.unknownOfElement(own.elements[0])];
    dae.templateBlocks.push_back({first, own.shape, t.box, ctx.sub(t.lhs, t.rhs), flat::OriginKind::Equation, t.origin.range});
    flat::forEachPoint(t.box, [&](std::span<const long> p, size_t) {
      int row = first + static_cast<int>(flat::linearIndex(own.shape, p));
      place(row);
      dae.equations[row].origin = t.origin;
    });
  }
  for (char p : placed) QDOT_ASSERT(p, "a row of a templated ODE without an equation");
  dae.initialEquations = m.initialEquations;  // start values (initialEquationsAreStartValues)
  dae.patterns = m.patterns;
}

}  // namespace qdot::dae
