// The DAE of an explicit ODE whose `for` equations stayed templates (TemplateOde.h): the check
// that it is one, and its unknowns and rows, row j defining the derivative of unknown j.
#include "dae/TemplateOde.h"

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

// Time, parameters, and unknowns that are states (every der() a variable of its own).
bool unknownsAreStates(const flat::FlatModel& m) {
  for (const flat::Variable& v : m.variables) {
    bool ok = v.role == VarRole::Time || v.role == VarRole::Parameter || v.role == VarRole::Derivative ||
              (v.role == VarRole::Unknown && v.derivative >= 0);
    if (!ok || v.alias) return false;
  }
  return true;
}

bool onlyEquations(const flat::FlatModel& m) {
  return m.indexedSums.empty() && m.kinetic.empty() && m.potential.empty() && m.dissipation.empty() &&
         m.forces.empty() && m.constraints.empty() && m.initialEquations.empty() && m.components.size() <= 1;
}

class OdeCheck {
 public:
  OdeCheck(const flat::FlatModel& m, const sym::Context& ctx) : m_(m), ctx_(ctx), firstUnknown_(m.patterns->arrays.size(), -2) {}

  // The unknown a scalar row `der(x) = rhs` defines (rhs over unknowns, parameters and time), or -1.
  int scalarRow(const flat::Equation& e) const {
    if (!e.lhs || !e.rhs) return -1;
    for (Expr s : ctx_.freeSymbols(e.rhs))
      if (int v = m_.variableOf(s); v < 0 || m_.variables[v].role == VarRole::Derivative) return -1;
    return unknownOfRate(m_, e.lhs);
  }

  // The unknown of the first element of the array whose derivatives a template `der(x)[%1,…] = rhs`
  // defines, or -1.
  int templateRow(const flat::EquationTemplate& t) {
    const flat::RelativeElement* own = m_.relativeElement(t.lhs);
    if (!own || !indexedInOrder(*own, t.box.size())) return -1;
    for (const auto& dim : own->dims)
      if (dim.offset != 0) return -1;
    const flat::ArrayVariable& rates = m_.patterns->arrays[own->array];
    int first = firstOfConsecutive(rates, [&](Expr e) { return unknownOfRate(m_, e); });
    for (Expr s : ctx_.freeSymbols(t.rhs)) {
      if (const flat::RelativeElement* rel = m_.relativeElement(s)) {
        const flat::ArrayVariable& a = m_.patterns->arrays[rel->array];
        bool shaped = t.box.size() == 1 || a.shape == rates.shape;
        if (!indexedInOrder(*rel, t.box.size()) || !shaped || firstUnknown(rel->array) < 0) return -1;
        continue;
      }
      int v = m_.variableOf(s);
      if (v < 0 || (m_.variables[v].role != VarRole::Parameter && m_.variables[v].role != VarRole::Time)) return -1;
    }
    return first;
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

const flat::ArrayVariable& definedArray(const flat::FlatModel& m, const flat::EquationTemplate& t) {
  return m.patterns->arrays[m.relativeElement(t.lhs)->array];
}

}  // namespace

bool isTemplatedOde(const flat::FlatModel& m, const sym::Context& ctx) {
  if (m.equationTemplates.empty() || !onlyEquations(m) || !unknownsAreStates(m)) return false;
  std::vector<int> rows(m.variables.size(), 0);  // per unknown: the rows defining its derivative
  OdeCheck check(m, ctx);
  for (const flat::Equation& e : m.equations) {
    int x = check.scalarRow(e);
    if (x < 0) return false;
    ++rows[x];
  }
  for (const flat::EquationTemplate& t : m.equationTemplates) {
    int first = check.templateRow(t);
    if (first < 0) return false;
    const std::vector<int>& shape = definedArray(m, t).shape;
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
    dae.variables.push_back({.name = std::string(f.name), .kind = VarKind::State, .role = UnknownRole::State, .flatVar = i,
                             .y = f.symbol, .yp = m.variables[f.derivative].symbol, .declaration = Declaration::of(m, i)});
  }
  dae.equations.resize(dae.variables.size());
  std::vector<char> placed(dae.equations.size(), 0);
  auto place = [&](int row) {
    QDOT_ASSERT(row >= 0 && !placed[row], "a row of a templated ODE defined twice");
    placed[row] = 1;
  };
  for (const flat::Equation& e : m.equations) {
    int row = unknown[unknownOfRate(m, e.lhs)];
    place(row);
    dae.equations[row] = e;
  }
  for (const flat::EquationTemplate& t : m.equationTemplates) {
    const flat::ArrayVariable& rates = definedArray(m, t);
    int first = unknown[unknownOfRate(m, rates.elements[0])];
    dae.templateBlocks.push_back({first, rates.shape, t.box, ctx.sub(t.lhs, t.rhs), flat::OriginKind::Equation, t.origin.range});
    flat::forEachPoint(t.box, [&](std::span<const long> p, size_t) {
      int row = first + static_cast<int>(flat::linearIndex(rates.shape, p));
      place(row);
      dae.equations[row].origin = t.origin;
    });
  }
  for (char p : placed) QDOT_ASSERT(p, "a row of a templated ODE without an equation");
  dae.patterns = m.patterns;
}

}  // namespace qdot::dae
