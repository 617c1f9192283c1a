// Index reduction (see IndexReduction.h). The plan comes from structural::pantelides on the chain
// structure; here the DAE is extended: chains the differentiated equations touch get every order up
// to the one needed as an unknown (a chain's top is algebraic), and each differentiated equation is
// differentiated along the chains (d/dt x = der(x), d/dt time = 1) with sym::DirectionalDerivative.
#include "dae/IndexReduction.h"

#include <algorithm>

#include "dae/Balance.h"
#include "structural/Matching.h"

namespace qdot::dae {
namespace {

using sym::Expr;

class Reducer {
 public:
  Reducer(Dae& dae, sym::Context& ctx) : dae_(dae), ctx_(ctx), derivative_(ctx) {}

  void run(const ChainStructure& cs, const structural::DifferentiationPlan& plan) {
    chains_ = cs.chains;
    std::vector<char> involved(chains_.size(), 0);
    for (size_t k = 0; k < cs.equations.size(); ++k)
      if (plan.differentiations[k] > 0)
        for (structural::Occurrence o : cs.structure.occurrences[k]) involved[o.chain] = 1;
    for (size_t c = 0; c < chains_.size(); ++c)
      if (involved[c]) extendChain(chains_[c], plan.highestOrder[c]);
    // d/dt along the chains: x -> der(x) -> …; a state at the top of its chain -> its y'. An
    // algebraic top has no rate (a differentiated equation never reaches one: Pantelides).
    derivative_.setRate(dae_.time, ctx_.one());
    for (const auto& chain : chains_)
      for (size_t j = 0; j < chain.size(); ++j) {
        const Variable& v = dae_.variables[chain[j]];
        if (j + 1 < chain.size()) derivative_.setRate(v.y, dae_.variables[chain[j + 1]].y);
        else if (v.kind == VarKind::State) derivative_.setRate(v.y, v.yp);
        else unrated_.resize(std::max<size_t>(unrated_.size(), v.y->symbolId + 1)), unrated_[v.y->symbolId] = 1;
      }
    for (size_t k = 0; k < cs.equations.size(); ++k)
      if (plan.differentiations[k] > 0) differentiate(cs.equations[k], plan.differentiations[k]);
  }

  /// de/dt, or null if e contains an algebraic unknown whose derivative is not in the system.
  Expr timeDerivative(Expr e) {
    for (Expr s : ctx_.freeSymbols(e))
      if (s->symbolId < unrated_.size() && unrated_[s->symbolId]) return nullptr;
    return derivative_(e);
  }

 private:
  // Gives the chain an unknown for every order up to `order`, the last one algebraic.
  void extendChain(std::vector<int>& chain, int order) {
    while (true) {
      int top = chain.back();
      bool state = dae_.variables[top].kind == VarKind::State;
      if (!state && static_cast<int>(chain.size()) - 1 >= order) return;
      chain.push_back(addDerivativeOf(top));
    }
  }

  // The unknown der(v) with its link row der(v) = that unknown. If v is a state, its derivative
  // symbol (the one the equations contain) becomes the new unknown's and v gets a fresh one.
  int addDerivativeOf(int index) {
    Variable& v = dae_.variables[index];
    std::string name = "der(" + v.name + ")";
    Expr value = v.kind == VarKind::State ? v.yp : ctx_.symbol(name);
    v.kind = VarKind::State;
    v.yp = ctx_.symbol("$der(" + v.name + ")");
    Variable d{.name = name, .kind = VarKind::Algebraic, .role = UnknownRole::Derivative, .y = value};
    d.declaration = v.declaration;
    d.declaration.start = nullptr;  // a guess of 0; initialization computes it
    d.declaration.fixed = false;
    d.declaration.nominal = nullptr;
    flat::Origin origin{.kind = flat::OriginKind::Kinematic, .range = v.declaration.declRange, .variable = v.flatVar};
    Expr link = ctx_.sub(v.yp, value);
    int row = static_cast<int>(dae_.equations.size());
    int derivative = static_cast<int>(dae_.variables.size());
    dae_.equations.push_back({link, origin, v.yp, value});
    dae_.links.push_back({row, index, derivative});
    dae_.variables.push_back(std::move(d));
    return derivative;
  }

  void differentiate(int row, int times) {
    std::vector<int> rows{row};
    Equation eq = dae_.equations[row];
    for (int i = 1; i <= times; ++i) {
      eq.residual = derivative_(eq.residual);
      if (eq.lhs && eq.rhs) eq.lhs = derivative_(eq.lhs), eq.rhs = derivative_(eq.rhs);
      eq.origin.differentiated = i;
      rows.push_back(static_cast<int>(dae_.equations.size()));
      dae_.equations.push_back(eq);
    }
    dae_.differentiatedRows.push_back(std::move(rows));
  }

  Dae& dae_;
  sym::Context& ctx_;
  sym::DirectionalDerivative derivative_;
  std::vector<std::vector<int>> chains_;
  std::vector<char> unrated_;  ///< by symbol id: an algebraic chain top (no rate)
};

// g and dg/dt of every constraint as invariants, to watch their drift.
void addConstraintInvariants(Dae& dae, Reducer& reducer) {
  for (const Equation& eq : dae.equations) {
    if (eq.origin.kind != flat::OriginKind::Constraint || eq.origin.differentiated != 0) continue;
    std::string name = "constraint[" + std::to_string(eq.origin.variable + 1) + "]";
    dae.invariants.push_back({name, "constraint residual", eq.residual});
    if (Expr rate = reducer.timeDerivative(eq.residual))
      dae.invariants.push_back({"der(" + name + ")", "constraint residual", rate});
  }
}

}  // namespace

ChainStructure chainStructure(const Dae& dae, const sym::Context& ctx) {
  ChainStructure cs;
  const int n = static_cast<int>(dae.variables.size());
  std::vector<int> next(n, -1), prev(n, -1);
  std::vector<char> isLink(dae.equations.size(), 0);
  for (const DerivativeLink& l : dae.links) next[l.variable] = l.derivative, prev[l.derivative] = l.variable, isLink[l.row] = 1;
  cs.chainOf.assign(n, -1);
  cs.orderOf.assign(n, 0);
  for (int v = 0; v < n; ++v) {
    if (prev[v] >= 0) continue;
    int c = static_cast<int>(cs.chains.size());
    cs.chains.emplace_back();
    for (int u = v, order = 0; u >= 0; u = next[u], ++order) {
      cs.chainOf[u] = c, cs.orderOf[u] = order;
      cs.chains[c].push_back(u);
    }
    int top = cs.chains[c].back();
    cs.structure.highestOrder.push_back(cs.orderOf[top] + (dae.variables[top].kind == VarKind::State ? 1 : 0));
  }
  // symbol id -> (chain, order) of the variable it is (y) or of its derivative (y')
  std::vector<structural::Occurrence> of(ctx.symbolCount(), {-1, 0});
  for (int v = 0; v < n; ++v) {
    of[dae.variables[v].y->symbolId] = {cs.chainOf[v], cs.orderOf[v]};
    if (dae.variables[v].yp) of[dae.variables[v].yp->symbolId] = {cs.chainOf[v], cs.orderOf[v] + 1};
  }
  for (int row = 0; row < static_cast<int>(dae.equations.size()); ++row) {
    if (isLink[row]) continue;
    cs.equations.push_back(row);
    auto& list = cs.structure.occurrences.emplace_back();
    for (Expr s : ctx.freeSymbols(dae.equations[row].residual))
      if (s->symbolId < of.size() && of[s->symbolId].chain >= 0) list.push_back(of[s->symbolId]);
  }
  return cs;
}

bool reduceIndex(Dae& dae, sym::Context& ctx, DiagnosticEngine& diags) {
  bool constrained = false;
  for (const Equation& eq : dae.equations) constrained |= eq.origin.kind == flat::OriginKind::Constraint;
  bool indexAtMostOne = structural::maximumMatching(incidence(dae, ctx)).isPerfect();
  if (indexAtMostOne && !constrained) return true;
  ChainStructure cs = chainStructure(dae, ctx);
  if (!structural::chainsDetermined(cs.structure)) {
    diags.error(dae.range, DiagCode::E0503, "structurally singular system: the equations cannot be solved for the unknowns",
                "check that every unknown occurs in some equation and no equation repeats another");
    return false;
  }
  structural::DifferentiationPlan plan =
      indexAtMostOne ? structural::DifferentiationPlan{std::vector<int>(cs.equations.size(), 0), cs.structure.highestOrder, {}}
                     : structural::pantelides(cs.structure);
  Reducer reducer(dae, ctx);
  reducer.run(cs, plan);
  addConstraintInvariants(dae, reducer);
  return true;
}

}  // namespace qdot::dae
