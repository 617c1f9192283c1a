// The initialization system's structure (see Initialization.h). Unknowns: y of every variable
// (ids 0..n-1) and y' of every state (ids n..). Equations: the DAE's rows, the initial rows, the
// required starts, then the default starts. A maximum matching of the required part first, then
// extended to everything (maximumMatching keeps every vertex it was given matched): default starts
// left unmatched are the ones the initial equations replace.
#include "dae/Initialization.h"

#include "structural/Matching.h"

namespace qdot::dae {
namespace {

class InitialGraph {
 public:
  InitialGraph(const Dae& dae, const sym::Context& ctx) : dae_(dae), ctx_(ctx), of_(ctx.symbolCount(), -1) {
    int n = static_cast<int>(dae.variables.size());
    unknowns_ = n;
    for (int j = 0; j < n; ++j) {
      of_[dae.variables[j].y->symbolId] = j;
      if (dae.variables[j].yp) of_[dae.variables[j].yp->symbolId] = unknowns_++, derivativeOf_.push_back(j);
    }
  }

  int unknowns() const { return unknowns_; }
  std::string unknownName(int u) const {
    int n = static_cast<int>(dae_.variables.size());
    return u < n ? dae_.variables[u].name : "der(" + dae_.variables[derivativeOf_[u - n]].name + ")";
  }
  SourceRange unknownRange(int u) const {
    int n = static_cast<int>(dae_.variables.size());
    return dae_.variables[u < n ? u : derivativeOf_[u - n]].declaration.declRange;
  }

  void addEquation(sym::Expr residual, bool active) {
    int e = equations_++;
    if (!active) return;
    for (sym::Expr s : ctx_.freeSymbols(residual))
      if (s->symbolId < of_.size() && of_[s->symbolId] >= 0) edges_.push_back({e, of_[s->symbolId]});
  }
  void addStart(int variable, bool active) {
    int e = equations_++;
    if (active) edges_.push_back({e, variable});
  }
  structural::BipartiteGraph graph() const { return {equations_, unknowns_, edges_}; }

 private:
  const Dae& dae_;
  const sym::Context& ctx_;
  std::vector<int> of_;            // symbol id -> unknown id
  std::vector<int> derivativeOf_;  // unknown id - n -> variable
  int unknowns_ = 0, equations_ = 0;
  std::vector<structural::Edge> edges_;
};

}  // namespace

std::optional<std::vector<char>> planInitialization(const Dae& dae, const std::vector<Equation>& initialRows,
                                                    const std::vector<StartUse>& starts, const sym::Context& ctx,
                                                    DiagnosticEngine& diags) {
  const int n = static_cast<int>(dae.variables.size());
  // Equation ids: DAE rows, initial rows, then one start equation per variable (in that order).
  auto build = [&](bool withDefaults) {
    InitialGraph g(dae, ctx);
    for (const Equation& e : dae.equations) g.addEquation(e.residual, true);
    for (const Equation& e : initialRows) g.addEquation(e.residual, true);
    for (int j = 0; j < n; ++j)
      g.addStart(j, starts[j] == StartUse::Required || (withDefaults && starts[j] == StartUse::Default));
    return g;
  };
  InitialGraph required = build(false), all = build(true);
  structural::BipartiteGraph g1 = required.graph(), g2 = all.graph();
  structural::Matching m1 = structural::maximumMatching(g1);
  const int rows = static_cast<int>(dae.equations.size()), firstStart = rows + static_cast<int>(initialRows.size());
  auto equationIsActive = [&](int e) { return e < firstStart || starts[e - firstStart] == StartUse::Required; };

  std::vector<int> overDetermined;
  for (int e = 0; e < g1.numEquations(); ++e)
    if (equationIsActive(e) && m1.matchOfEquation[e] == structural::kUnmatched) overDetermined.push_back(e);
  if (!overDetermined.empty()) {
    structural::DulmageMendelsohn dm = structural::dulmageMendelsohn(g1, m1);
    SourceRange at = dae.range;  // at an initial equation of the over-determined part, if there is one
    for (int e : dm.overEquations)
      if (e >= rows && e < firstStart && initialRows[e - rows].origin.range.valid()) {
        at = initialRows[e - rows].origin.range;
        break;
      }
    auto& d = diags.error(at, DiagCode::E0606,
                          "the initial conditions over-determine the start: " + std::to_string(overDetermined.size()) +
                              " condition(s) more than the unknowns they involve",
                          "remove a redundant initial equation, or declare a start value a guess (fixed = false)");
    for (int e : dm.overEquations) {
      if (d.notes.size() >= 12 || !equationIsActive(e)) continue;
      if (e >= firstStart) d.notes.push_back({dae.variables[e - firstStart].declaration.declRange,
                                              "the fixed start value of '" + dae.variables[e - firstStart].name + "'"});
      else if (e >= rows) d.notes.push_back({initialRows[e - rows].origin.range, "this initial equation"});
      else d.notes.push_back({dae.equations[e].origin.range, "this equation, which holds at the start"});
    }
    return std::nullopt;
  }
  structural::Matching m2 = structural::maximumMatching(g2, m1);
  std::vector<int> undetermined;
  for (int u = 0; u < all.unknowns(); ++u)
    if (m2.matchOfVariable[u] == structural::kUnmatched) undetermined.push_back(u);
  if (!undetermined.empty()) {
    std::string names;
    for (size_t k = 0; k < undetermined.size() && k < 8; ++k) names += (k ? ", " : "") + all.unknownName(undetermined[k]);
    auto& d = diags.error(dae.range, DiagCode::E0605, "the initial conditions do not determine " + names,
                          "give a start value with fixed = true or an initial equation for each");
    for (int u : undetermined)
      if (d.notes.size() < 12) d.notes.push_back({all.unknownRange(u), "'" + all.unknownName(u) + "' is not determined at the start"});
    return std::nullopt;
  }
  std::vector<char> kept(n, 0);
  for (int j = 0; j < n; ++j) kept[j] = starts[j] != StartUse::Guess && m2.matchOfEquation[firstStart + j] != structural::kUnmatched;
  return kept;
}

}  // namespace qdot::dae
