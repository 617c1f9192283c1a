// `--emit=flat`: the flattened model, one item per line. Variables in index order (time first,
// then as the flattener created them), each term and equation in the order of the model text.
#include "flatten/FlatPrinter.h"
#include "qdot/number_text.hpp"

#include <ostream>

namespace qdot::flat {
namespace {

// "  (utube.qd:14)", or nothing when the item has no place in the text.
std::string at(const SourceManager& sm, SourceRange r) {
  std::string line = lineOf(sm, r);
  return line.empty() ? "" : "   (" + line + ")";
}

void printVariable(std::ostream& os, const Variable& v, const VariableAttributes& a, const sym::Context& ctx,
                   const SourceManager& sm) {
  os << "  " << v.name << ": " << roleName(v.role);
  if (v.value) os << " = " << sym::toString(ctx, v.value);
  if (v.start) os << ", start = " << sym::toString(ctx, v.start);
  if (v.fixed) os << ", fixed";
  if (a.nominal) os << ", nominal = " << sym::toString(ctx, a.nominal);
  if (a.min) os << ", min = " << sym::toString(ctx, a.min);
  if (a.max) os << ", max = " << sym::toString(ctx, a.max);
  if (!a.unit.empty()) os << ", unit \"" << a.unit << "\"";
  if (v.alias) os << ", is " << sym::toString(ctx, v.alias);
  os << at(sm, v.declRange) << "\n";
}

void printTerms(std::ostream& os, const char* title, const std::vector<Term>& terms, const sym::Context& ctx,
                const SourceManager& sm) {
  os << title << " (" << terms.size() << "):\n";
  for (const Term& t : terms) os << "  " << sym::toString(ctx, t.value) << at(sm, t.range) << "\n";
}

void printEquations(std::ostream& os, const char* title, const std::vector<Equation>& equations,
                    const sym::Context& ctx, const SourceManager& sm) {
  os << title << " (" << equations.size() << "):\n";
  for (const Equation& e : equations) {
    os << "  ";
    if (e.lhs) os << sym::toString(ctx, e.lhs) << " = " << sym::toString(ctx, e.rhs);
    else os << sym::toString(ctx, e.residual) << " = 0";
    os << at(sm, e.origin.range);
    if (!e.origin.element.empty())
      os << (e.origin.kind == OriginKind::Connection ? " connection " : " element ") << e.origin.element;
    os << "\n";
  }
}

}  // namespace

std::string lineOf(const SourceManager& sm, SourceRange r) {
  if (!r.valid()) return "";
  return sm.name(r.file) + ":" + std::to_string(sm.lineCol(r.file, r.begin).line);
}

void printExperiment(std::ostream& os, const Experiment& e) {
  os << "experiment:";
  const std::pair<const char*, const std::optional<double>*> fields[] = {
      {"StartTime", &e.startTime}, {"StopTime", &e.stopTime}, {"Interval", &e.interval}, {"Tolerance", &e.tolerance}};
  bool any = false;
  for (const auto& [name, value] : fields)
    if (value->has_value()) os << (any ? ", " : " ") << name << " = " << shortestText(**value), any = true;
  os << (any ? "\n" : " (none)\n");
}

std::string sumText(const IndexedTerm& sum, const sym::Context& ctx) {
  std::string box;
  for (size_t d = 0; d < sum.box.size(); ++d)
    box += (d ? ", %" : "%") + std::to_string(d + 1) + " in " + std::to_string(sum.box[d].first) + ":" + std::to_string(sum.box[d].second);
  return "sum(" + sym::toString(ctx, sum.body) + " for " + box + ")";
}

const char* originKindName(OriginKind k) {
  switch (k) {
    case OriginKind::Equation: return "equation";
    case OriginKind::InitialEquation: return "initial equation";
    case OriginKind::EulerLagrange: return "Euler-Lagrange row";
    case OriginKind::Kinematic: return "kinematic";
    case OriginKind::Constraint: return "constraint";
    case OriginKind::Connection: return "connection";
  }
  return "?";
}

void printFlatModel(std::ostream& os, const FlatModel& m, const sym::Context& ctx, const SourceManager& sm) {
  os << "flat model " << m.name;
  if (!m.description.empty()) os << " \"" << m.description << "\"";
  os << "\n\nvariables (" << m.variables.size() << "):\n";
  for (const Variable& v : m.variables) printVariable(os, v, m.attributesOf(v), ctx, sm);
  os << "\n";
  printTerms(os, "kinetic", m.kinetic, ctx, sm);
  printTerms(os, "potential", m.potential, ctx, sm);
  printTerms(os, "dissipation", m.dissipation, ctx, sm);
  os << "forces (" << m.forces.size() << "):\n";
  for (const auto& [q, t] : m.forces)
    os << "  force(" << m.variables[q].name << ") = " << sym::toString(ctx, t.value) << at(sm, t.range) << "\n";
  os << "\n";
  printEquations(os, "equations", m.equations, ctx, sm);
  printEquations(os, "initial equations", m.initialEquations, ctx, sm);
  printEquations(os, "constraints", m.constraints, ctx, sm);
  os << "outputs (" << m.outputs.size() << "):\n";
  for (const Output& o : m.outputs) {
    os << "  " << o.name << " = " << sym::toString(ctx, o.value);
    for (const IndexedTerm& sum : o.sums) os << " + " << sumText(sum, ctx);
    os << at(sm, o.range) << "\n";
  }
  os << "\n";
  printExperiment(os, m.experiment);
}

}  // namespace qdot::flat
