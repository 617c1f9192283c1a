// `--emit=dae`: variables and equations numbered as the kernels and the solver see them, so a
// residual index in a solver message can be looked up here.
#include "dae/PrintDae.h"

#include <ostream>

#include "flatten/FlatPrinter.h"

namespace qdot::dae {
namespace {

std::string at(const SourceManager& sm, SourceRange r) {
  std::string line = flat::lineOf(sm, r);
  return line.empty() ? "" : "   (" + line + ")";
}

void printVariable(std::ostream& os, size_t i, const Variable& v, const sym::Context& ctx, const SourceManager& sm) {
  std::string kind = v.kind == VarKind::State ? "state" : "algebraic";
  os << "  " << i << " " << v.name << ": " << kind;
  if (kind != roleName(v.role)) os << ", " << roleName(v.role);
  if (v.yp) os << ", derivative " << sym::toString(ctx, v.yp);
  const Declaration& d = v.declaration;
  if (d.start) os << ", start = " << sym::toString(ctx, d.start);
  if (d.fixed) os << ", fixed";
  if (d.nominal) os << ", nominal = " << sym::toString(ctx, d.nominal);
  os << at(sm, d.declRange) << "\n";
}

// "Euler-Lagrange row of x", "equation element [2]", "constraint".
std::string originText(const Dae& dae, size_t i, const flat::Origin& o) {
  std::string s = flat::originKindName(o.kind);
  if (o.kind == flat::OriginKind::EulerLagrange && i < dae.rowCoordinates.size()) s += " of " + dae.rowCoordinates[i];
  if (o.kind == flat::OriginKind::Kinematic)
    for (const Variable& v : dae.variables)
      if (v.flatVar == o.variable) s += " of " + v.name;
  if (!o.element.empty()) s += (o.kind == flat::OriginKind::Connection ? " " : " element ") + o.element;
  if (o.differentiated > 0) s += ", differentiated " + std::to_string(o.differentiated) + "x";
  return s;
}

void printEquation(std::ostream& os, size_t i, const Dae& dae, const Equation& e, const sym::Context& ctx,
                   const SourceManager& sm) {
  os << "  " << i << " " << sym::toString(ctx, e.residual) << " = 0   [" << originText(dae, i, e.origin) << "]"
     << at(sm, e.origin.range) << "\n";
}

}  // namespace

void printDae(std::ostream& os, const Dae& dae, const sym::Context& ctx, const SourceManager& sm) {
  os << "dae " << dae.name;
  if (!dae.description.empty()) os << " \"" << dae.description << "\"";
  os << "\n\nvariables (" << dae.variables.size() << ", " << dae.stateCount() << " states):\n";
  for (size_t i = 0; i < dae.variables.size(); ++i) printVariable(os, i, dae.variables[i], ctx, sm);
  os << "\nequations F = 0 (" << dae.equations.size() << "):\n";
  for (size_t i = 0; i < dae.equations.size(); ++i) printEquation(os, i, dae, dae.equations[i], ctx, sm);
  os << "\ninitial equations (" << dae.initialEquations.size() << "):\n";
  for (size_t i = 0; i < dae.initialEquations.size(); ++i)
    printEquation(os, i, dae, dae.initialEquations[i], ctx, sm);
  os << "\nparameters (" << dae.parameters.size() << "):\n";
  for (const Parameter& p : dae.parameters)
    os << "  " << p.name << " = " << sym::toString(ctx, p.value) << at(sm, p.declRange) << "\n";
  os << "\noutputs (" << dae.outputs.size() << "):\n";
  for (const auto& o : dae.outputs) {
    os << "  " << o.name << " = " << sym::toString(ctx, o.value);
    for (const flat::IndexedTerm& sum : o.sums) os << " + " << flat::sumText(sum, ctx);
    os << at(sm, o.range) << "\n";
  }
  os << "\ninvariants (" << dae.invariants.size() << "):\n";
  for (const Invariant& inv : dae.invariants)
    os << "  " << inv.name << " (" << inv.kind << ") = " << sym::toString(ctx, inv.value) << "\n";
  os << "\n";
  flat::printExperiment(os, dae.experiment);
}

}  // namespace qdot::dae
