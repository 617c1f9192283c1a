// `--emit=eom`: the rows in coordinate declaration order, then multipliers and first integrals in
// the order the mechanics stage found them.
#include "mechanics/EomPrinter.h"

#include <ostream>

#include "flatten/FlatPrinter.h"

namespace qdot::mech {
namespace {

std::string at(const SourceManager& sm, SourceRange r) {
  std::string line = flat::lineOf(sm, r);
  return line.empty() ? "" : "   (" + line + ")";
}

std::string text(const sym::Context& ctx, sym::Expr e) { return e ? sym::toString(ctx, e) : "0"; }

// The textbook's order of a row's terms: accelerations (the mass matrix), then velocities, then the
// rest (potential, forces).
int group(const flat::FlatModel& model, const sym::Context& ctx, sym::Expr term) {
  int g = 2;
  for (sym::Expr s : ctx.freeSymbols(term)) {
    int var = model.variableOf(s);
    if (var < 0) continue;
    if (model.variables[var].role == flat::VarRole::Acceleration) return 0;
    if (model.variables[var].role == flat::VarRole::Velocity) g = 1;
  }
  return g;
}

const char* kindName(FirstIntegral::Kind k) {
  return k == FirstIntegral::Kind::CyclicMomentum ? "cyclic momentum" : "Jacobi integral";
}

}  // namespace

void printEquationsOfMotion(std::ostream& os, const EquationsOfMotion& eom, const flat::FlatModel& model,
                            const sym::Context& ctx, const SourceManager& sm) {
  os << "equations of motion of " << model.name << "\n\n";
  os << "T = " << text(ctx, eom.kinetic) << "\n";
  os << "V = " << text(ctx, eom.potential) << "\n";
  os << "D = " << text(ctx, eom.dissipation) << "\n\n";
  os << "Euler-Lagrange rows, d/dt dL/dder(q) - dL/dq + dD/dder(q) - Q - sum lambda*dg/dq = 0 (" << eom.rows.size()
     << "):\n";
  for (const CoordinateRow& row : eom.rows) {
    const flat::Variable& q = model.variables[row.coordinate];
    auto byGroup = [&](sym::Expr term) { return group(model, ctx, term); };
    os << "  " << q.name << ": " << (row.residual ? sym::toStringGrouped(ctx, row.residual, byGroup) : "0") << " = 0"
       << at(sm, q.declRange) << "\n";
    os << "      momentum p(" << q.name << ") = " << text(ctx, row.momentum) << (row.inertial ? "" : ", no inertia")
       << "\n";
  }
  os << "\nmultipliers (" << eom.multipliers.size() << "):\n";
  for (const Multiplier& mult : eom.multipliers) {
    const flat::Equation& g = model.constraints[mult.constraint];
    os << "  " << mult.name << ": constraint " << text(ctx, g.residual) << " = 0" << at(sm, g.origin.range) << "\n";
  }
  os << "\nfirst integrals (" << eom.integrals.size() << "):\n";
  for (const FirstIntegral& fi : eom.integrals)
    os << "  " << fi.name << " (" << kindName(fi.kind) << ") = " << text(ctx, fi.value) << "\n";
}

}  // namespace qdot::mech
