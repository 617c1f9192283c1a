// Balance check of the DAE via structural matching (see Balance.h).
#include "dae/Balance.h"

#include <algorithm>
#include <vector>

#include "dae/IndexReduction.h"
#include "structural/Matching.h"

namespace qdot::dae {
namespace {

std::string equationLabel(const Dae& dae, const Equation& eq, const sym::Context& ctx) {
  switch (eq.origin.kind) {
    case flat::OriginKind::EulerLagrange: return "the Euler–Lagrange equation of a coordinate";
    case flat::OriginKind::Kinematic: return "a kinematic equation";
    case flat::OriginKind::Constraint: return "this constraint";
    case flat::OriginKind::Connection: return "the flow balance " + sym::toString(ctx, eq.residual) + " = 0 of a connection";
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

// The equation–unknown edges. Unknowns are found by symbol id in a flat array (a hash map over the
// symbols of a large model missed the cache on nearly every lookup). Residuals are mostly small: they
// are walked here with a short visited list and reused buffers, since Context::freeSymbols builds a
// new vector per call (on the spring chain that was half of this stage); a residual with many nodes
// goes to freeSymbols. A symbol may be reported twice: the graph merges duplicate edges.
class IncidenceBuilder {
 public:
  IncidenceBuilder(const Dae& dae, const sym::Context& ctx) : ctx_(ctx), unknownOf_(ctx.symbolCount(), -1) {
    for (int i = 0; i < static_cast<int>(dae.variables.size()); ++i) {
      const Variable& v = dae.variables[i];
      unknownOf_[(v.kind == VarKind::State ? v.yp : v.y)->symbolId] = i;
    }
  }

  void addEquation(int equation, sym::Expr residual) {
    stack_.assign(1, residual);
    visited_.clear();
    while (!stack_.empty()) {
      sym::Expr n = stack_.back();
      stack_.pop_back();
      if (n->isSymbol()) {
        addSymbol(equation, n);
      } else if (n->symbolMask && std::find(visited_.begin(), visited_.end(), n) == visited_.end()) {
        if (visited_.size() == kSmall) return addAllSymbols(equation, residual);
        visited_.push_back(n);
        stack_.insert(stack_.end(), n->args.begin(), n->args.end());
        stack_.insert(stack_.end(), n->exps().begin(), n->exps().end());
      }
    }
  }

  std::vector<structural::Edge>& edges() { return edges_; }

 private:
  static constexpr size_t kSmall = 32;  ///< operation nodes walked here; a linear visited list stays cheap

  void addSymbol(int equation, sym::Expr s) {
    if (int unknown = unknownOf_[s->symbolId]; unknown >= 0) edges_.push_back({equation, unknown});
  }
  void addAllSymbols(int equation, sym::Expr residual) {
    for (sym::Expr s : ctx_.freeSymbols(residual)) addSymbol(equation, s);
  }

  const sym::Context& ctx_;
  std::vector<int> unknownOf_;  ///< by symbolId: the unknown it stands for, or -1
  std::vector<structural::Edge> edges_;
  std::vector<sym::Expr> stack_, visited_;
};



// A connector joined to nothing has flow 0; where that leaves its potential undetermined or its
// flow fixed twice (a Force acting on no node), the structural error is that connector's.
void noteUnconnected(const Dae& dae, const structural::DulmageMendelsohn& dm, DiagnosticEngine& diags) {
  std::vector<int> involved(dm.underVariables.begin(), dm.underVariables.end());
  involved.insert(involved.end(), dm.overVariables.begin(), dm.overVariables.end());
  for (const auto& [path, range] : dae.unconnected)
    for (int v : involved)
      if (dae.variables[v].name.rfind(path + ".", 0) == 0) {
        diags.error(range, DiagCode::E0504, "connector '" + path + "' is connected to nothing",
                    "its flow is then 0, which leaves '" + dae.variables[v].name +
                        "' undetermined or fixed twice: connect it to the node it acts on");
        break;
      }
}

}  // namespace

structural::BipartiteGraph incidence(const Dae& dae, const sym::Context& ctx) {
  IncidenceBuilder builder(dae, ctx);
  for (int e = 0; e < static_cast<int>(dae.equations.size()); ++e) builder.addEquation(e, dae.equations[e].residual);
  return structural::BipartiteGraph(static_cast<int>(dae.equations.size()), static_cast<int>(dae.variables.size()),
                                    builder.edges());
}

bool checkBalance(const Dae& dae, sym::Context& ctx, DiagnosticEngine& diags) {
  structural::BipartiteGraph g = incidence(dae, ctx);
  structural::Matching m = structural::maximumMatching(g);
  if (m.isPerfect()) return true;
  // Not solvable for the highest derivatives as written, but solvable once differentiated
  // (constraints: index > 1): index reduction's case, not an error.
  if (structural::chainsDetermined(chainStructure(dae, ctx).structure)) return true;
  structural::DulmageMendelsohn dm = structural::dulmageMendelsohn(g, m);
  size_t neq = dae.equations.size(), nvar = dae.variables.size();
  std::string counts = std::to_string(neq) + " equation" + (neq == 1 ? "" : "s") + " for " + std::to_string(nvar) +
                       " unknown" + (nvar == 1 ? "" : "s");
  std::vector<int> undetermined;
  for (int v : dm.underVariables)
    if (m.matchOfVariable[v] == structural::kUnmatched) undetermined.push_back(v);
  noteUnconnected(dae, dm, diags);
  if (!dm.underVariables.empty()) {
    auto& d = diags.error(dae.range, neq < nvar ? DiagCode::E0501 : DiagCode::E0503,
                          (neq < nvar ? "too few equations: " : "structurally singular system: ") + counts +
                              "; nothing determines " + joinNames(dae, undetermined),
                          "add an equation for each of them, or make them parameters or definitions");
    for (int v : dm.underVariables)
      if (d.notes.size() < 12)
        d.notes.push_back({dae.variables[v].declaration.declRange, "'" + dae.variables[v].name + "' is not determined by the equations"});
  }
  if (!dm.overEquations.empty()) {
    std::vector<int> extra;
    for (int e : dm.overEquations)
      if (m.matchOfEquation[e] == structural::kUnmatched) extra.push_back(e);
    auto& d = diags.error(dae.range, neq > nvar ? DiagCode::E0502 : DiagCode::E0503,
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
