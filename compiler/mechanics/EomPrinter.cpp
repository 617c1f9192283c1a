// `--emit=eom`: the rows in coordinate declaration order, then multipliers and first integrals in
// the order the mechanics stage found them.
#include "mechanics/EomPrinter.h"

#include <algorithm>
#include <ostream>
#include <vector>

#include "flatten/FlatPrinter.h"

namespace qdot::mech {
namespace {

std::string at(const SourceManager& sm, SourceRange r) {
  std::string line = flat::lineOf(sm, r);
  return line.empty() ? "" : "   (" + line + ")";
}

std::string text(const sym::Context& ctx, sym::Expr e) { return e ? sym::toString(ctx, e) : "0"; }

// The textbook's order of a row's terms: accelerations (the mass matrix), then velocities, then the
// rest (potential, forces); canonical order within each group.
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

// A sum printed in textbook order; a common factor times a sum keeps the factor in front.
std::string rowText(const flat::FlatModel& model, sym::Context& ctx, sym::Expr e) {
  if (e->kind == sym::Kind::Mul && e->args.size() >= 2) {
    size_t sums = 0, at = 0;
    for (size_t i = 0; i < e->args.size(); ++i)
      if (e->args[i]->kind == sym::Kind::Add && e->exps[i]->isOne()) ++sums, at = i;
    if (sums == 1) {
      std::vector<sym::Expr> rest;
      for (size_t i = 0; i < e->args.size(); ++i)
        if (i != at) rest.push_back(ctx.pow(e->args[i], e->exps[i]));
      sym::Expr factor = ctx.scale(e->value, ctx.mul(rest));
      std::string f = sym::toString(ctx, factor);
      return (f == "-1" ? "-" : f + "*") + "(" + rowText(model, ctx, e->args[at]) + ")";
    }
  }
  if (e->kind != sym::Kind::Add) return sym::toString(ctx, e);
  std::vector<std::pair<int, sym::Expr>> terms;
  for (size_t i = 0; i < e->args.size(); ++i) {
    sym::Expr t = ctx.scale(e->coefs[i], e->args[i]);
    terms.push_back({group(model, ctx, t), t});
  }
  if (e->value != 0.0) terms.push_back({3, ctx.constant(e->value)});
  std::stable_sort(terms.begin(), terms.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::string out;
  for (const auto& [g, t] : terms) {
    std::string piece = sym::toString(ctx, t);
    if (t->kind == sym::Kind::Add) piece = "(" + piece + ")";
    if (out.empty()) out = piece;
    else if (piece[0] == '-') out += " - " + piece.substr(1);
    else out += " + " + piece;
  }
  return out;
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
    // Printing builds the scaled terms (new interned nodes; existing ones never change).
    os << "  " << q.name << ": " << (row.residual ? rowText(model, const_cast<sym::Context&>(ctx), row.residual) : "0")
       << " = 0" << at(sm, q.declRange) << "\n";
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
