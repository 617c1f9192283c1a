// Balance check of the DAE via structural matching (see Balance.h).
#include "dae/Balance.h"

#include <unordered_map>

#include "structural/Matching.h"

namespace qdot::dae {
namespace {

std::string equationLabel(const Dae& dae, const Equation& eq, const sym::Context& ctx) {
  switch (eq.origin.kind) {
    case flat::OriginKind::EulerLagrange: return "the Euler–Lagrange equation of a coordinate";
    case flat::OriginKind::Kinematic: return "a kinematic equation";
    case flat::OriginKind::Constraint: return "this constraint";
    default: break;
  }
  std::string text = eq.lhs ? sym::toString(ctx, eq.lhs) + " = " + sym::toString(ctx, eq.rhs)
                            : sym::toString(ctx, eq.residual) + " = 0";
  return "equation " + text + (eq.origin.element.empty() ? "" : " (element " + eq.origin.element + ")");
}

std::string joinNames(const Dae& dae, const std::vector<int>& vars, size_t limit = 12) {
  std::string s;
  for (size_t i = 0; i < vars.size() && i < limit; ++i) s += (i ? ", " : "") + dae.variables[vars[i]].name;
  if (vars.size() > limit) s += ", … (" + std::to_string(vars.size() - limit) + " more)";
  return s;
}

structural::BipartiteGraph incidence(const Dae& dae, sym::Context& ctx) {
  std::unordered_map<const sym::Node*, int> unknownOf;
  for (int i = 0; i < static_cast<int>(dae.variables.size()); ++i) {
    const Variable& v = dae.variables[i];
    unknownOf[v.kind == VarKind::State ? v.yp : v.y] = i;
  }
  std::vector<structural::Edge> edges;
  for (int e = 0; e < static_cast<int>(dae.equations.size()); ++e)
    for (sym::Expr s : ctx.freeSymbols(dae.equations[e].residual))
      if (auto it = unknownOf.find(s); it != unknownOf.end()) edges.push_back({e, it->second});
  return structural::BipartiteGraph(static_cast<int>(dae.equations.size()), static_cast<int>(dae.variables.size()),
                                    edges);
}

}  // namespace

bool checkBalance(const Dae& dae, sym::Context& ctx, DiagnosticEngine& diags) {
  structural::BipartiteGraph g = incidence(dae, ctx);
  structural::Matching m = structural::maximumMatching(g);
  if (m.isPerfect()) return true;
  structural::DulmageMendelsohn dm = structural::dulmageMendelsohn(g, m);
  size_t neq = dae.equations.size(), nvar = dae.variables.size();
  std::string counts = std::to_string(neq) + " equation" + (neq == 1 ? "" : "s") + " for " + std::to_string(nvar) +
                       " unknown" + (nvar == 1 ? "" : "s");
  std::vector<int> undetermined;
  for (int v : dm.underVariables)
    if (m.matchOfVariable[v] == structural::kUnmatched) undetermined.push_back(v);
  if (!dm.underVariables.empty()) {
    auto& d = diags.error(dae.range, neq < nvar ? "E0501" : "E0503",
                          (neq < nvar ? "too few equations: " : "structurally singular system: ") + counts +
                              "; nothing determines " + joinNames(dae, undetermined),
                          "add an equation for each of them, or make them parameters or definitions");
    for (int v : dm.underVariables)
      if (d.notes.size() < 12)
        d.notes.push_back({dae.variables[v].declRange, "'" + dae.variables[v].name + "' is not determined by the equations"});
  }
  if (!dm.overEquations.empty()) {
    std::vector<int> extra;
    for (int e : dm.overEquations)
      if (m.matchOfEquation[e] == structural::kUnmatched) extra.push_back(e);
    auto& d = diags.error(dae.range, neq > nvar ? "E0502" : "E0503",
                          (neq > nvar ? "too many equations: " : "structurally singular system: ") + counts +
                              (dm.overVariables.empty()
                                   ? "; " + std::to_string(extra.size()) + " equation(s) determine no unknown"
                                   : "; the equations involving " + joinNames(dae, dm.overVariables) +
                                         " over-determine them"),
                          "remove the redundant equation(s), or turn a parameter they fix into an unknown");
    for (int e : dm.overEquations)
      if (d.notes.size() < 12)
        d.notes.push_back({dae.equations[e].origin.range, equationLabel(dae, dae.equations[e], ctx) +
                                                              " is one of " + std::to_string(dm.overEquations.size()) +
                                                              " equations for " + std::to_string(dm.overVariables.size()) +
                                                              " unknowns"});
  }
  return false;
}

}  // namespace qdot::dae
