// Components' energies summed over their connections (issue 15, docs/loops.md "Arrays of
// components"). Flattening keeps each component's energies in its own variables — a spring's
// `0.5*k*(b.s - a.s - s0)^2` in its flanges' potentials — and each connector's flow as a generalized
// force on its component's coordinate (spec §7): the Euler–Lagrange row of every potential a
// component's energy uses then determines that flow, and the DAE solves the flows with the states.
// When nothing but those rows reads a flow, the rows of one connection node sum to the row of the
// summed Lagrangian in the node's coordinate (the chain rule through the aliases `links[i].b.s =
// ms[i].s`), and the flows cancel in that sum (each connection's flows add to zero). This pass
// writes the model in that form: the aliases substituted into the energies, the flows, the aliased
// variables and the forces the connections made gone. What remains is a model of energies over
// coordinates, as if written with one Lagrangian — the form whose repeated structure the templates
// keep (rerollTerms) — with the same trajectories, to rounding.
#include <algorithm>
#include <optional>
#include <unordered_map>

#include "flatten/Flatten.h"

namespace qdot::flat {

using sym::Expr;

namespace {

class Summation {
 public:
  Summation(FlatModel& m, sym::Context& ctx) : m_(m), ctx_(ctx), isFlow_(m.variables.size(), 0) {}

  std::string run(std::span<const std::string> results) {
    if (std::string why = shapeOfModel(); !why.empty()) return why;
    if (std::string why = findFlows(); !why.empty()) return why;
    if (std::string why = solveBalances(); !why.empty()) return why;
    resolveAliases();
    if (std::string why = flowsReadOnlyByConnections(); !why.empty()) return why;
    std::vector<std::pair<int, Term>> forces;
    if (std::string why = forcesOnRepresentatives(forces); !why.empty()) return why;
    std::vector<Output> asked;
    if (std::string why = requestedResults(results, asked); !why.empty()) return why;
    rewrite(std::move(forces), std::move(asked));
    return "";
  }

 private:
  FlatModel& m_;
  sym::Context& ctx_;
  std::vector<char> isFlow_;     // by variable
  std::vector<Expr> aliasOf_;    // by symbol id: the resolved alias (null: none)
  std::vector<std::pair<Expr, Expr>> balances_;  // a flow a connection's balance gives: (flow, value)
  uint64_t aliasMask_ = 0;

  bool aliased(int v) const { return m_.variables[v].alias != nullptr; }
  Expr substituted(Expr e) const { return e && aliasMask_ ? ctx_.substitute(e, aliasOf_, aliasMask_) : e; }

  // Only energies, forces and outputs: no constraint (index reduction), no equation but the
  // connections' flow balances (a component's equations over its flows need the flows), no
  // template, and connections that do no work (spec §7: every flow acts on a coordinate or where
  // the potential is fixed).
  std::string shapeOfModel() const {
    if (!m_.constraints.empty()) return "it has a constraint";
    for (const Equation& e : m_.equations)
      if (e.origin.kind != OriginKind::Connection) return "it has equations besides its connections";
    if (!m_.initialEquations.empty()) return "it has initial equations";
    if (!m_.indexedSums.empty() || !m_.indexedForces.empty() || !m_.equationTemplates.empty() || !m_.equationSums.empty())
      return "it has templates of its own";
    if (!m_.connectionsConserveEnergy) return "a connector's flow acts on no coordinate of its component";
    return "";
  }

  // The flows: the values of the forces the connections made, and the unknowns joined to them by
  // aliases either way (a flow made the negative of another, the reaction of a fixed flange). Every
  // unknown that is not an alias must be one: anything else would need its own equation.
  std::string findFlows() {
    auto unknown = [&](Expr s) {
      int v = m_.variableOf(s);
      return v >= 0 && m_.variables[v].role == VarRole::Unknown ? v : -1;
    };
    std::vector<std::vector<int>> joined(m_.variables.size());  // by unknown: the unknowns an alias joins it to
    for (size_t v = 0; v < m_.variables.size(); ++v)
      if (m_.variables[v].role == VarRole::Unknown && m_.variables[v].alias)
        for (Expr s : ctx_.freeSymbols(m_.variables[v].alias))
          if (int w = unknown(s); w >= 0) joined[v].push_back(w), joined[w].push_back(static_cast<int>(v));
    std::vector<int> work;
    auto add = [&](int v) {
      if (!isFlow_[v]) isFlow_[v] = 1, work.push_back(v);
    };
    for (const Equation& e : m_.equations)  // a connection's balance: every symbol a flow
      for (Expr s : ctx_.freeSymbols(e.residual)) {
        if (unknown(s) < 0) return "a connection's balance reads '" + std::string(ctx_.symbolName(s)) + "', which is no flow";
        add(unknown(s));
      }
    for (const auto& [q, t] : m_.forces)
      if (t.connectionFlow) {
        int v = t.value->isSymbol() ? unknown(t.value) : -1;
        if (v < 0) return "a connection's force is not a flow variable";
        add(v);
      }
    while (!work.empty()) {
      int v = work.back();
      work.pop_back();
      for (int w : joined[v]) add(w);
    }
    for (size_t v = 0; v < m_.variables.size(); ++v) {
      const Variable& var = m_.variables[v];
      if (var.role == VarRole::Derivative) return "'" + std::string(var.name) + "' is the rate of an unknown";
      if (var.role == VarRole::Unknown && !var.alias && !isFlow_[v])
        return "'" + std::string(var.name) + "' is an unknown that is not a connector's flow";
    }
    return "";
  }

  // Each balance of three or more flows (c1 f1 + c2 f2 + … = 0) gives its last flow that is not an
  // alias as the others' combination, as the two-flow connections give theirs (f2 = -f1): the
  // forces on each node then cancel through these values alone.
  std::string solveBalances() {
    std::vector<char> given(m_.variables.size(), 0);
    for (const Equation& e : m_.equations) {
      Expr r = e.residual;
      if (r->kind != sym::Kind::Add || r->value != 0) return "a connection's balance is not a sum of flows";
      int pick = -1;
      for (int k = static_cast<int>(r->args.size()) - 1; k >= 0 && pick < 0; --k) {
        int v = r->args[k]->isSymbol() ? m_.variableOf(r->args[k]) : -1;
        if (v >= 0 && !aliased(v) && !given[v]) pick = k;
      }
      if (pick < 0) return "a connection's balance has no flow of its own";
      std::vector<Expr> others;
      std::vector<double> coefs;
      for (size_t k = 0; k < r->args.size(); ++k)
        if (static_cast<int>(k) != pick) others.push_back(r->args[k]), coefs.push_back(-r->coefs()[k] / r->coefs()[pick]);
      given[m_.variableOf(r->args[pick])] = 1;
      balances_.push_back({r->args[pick], ctx_.linearCombination(others, coefs)});
    }
    return "";
  }

  // Every alias to the end of its chain (an alias of an alias), by symbol id.
  void resolveAliases() {
    aliasOf_.assign(ctx_.symbolCount(), nullptr);
    std::vector<Expr> from;
    auto note = [&](Expr s, Expr value) {
      aliasOf_[s->symbolId] = value, aliasMask_ |= uint64_t{1} << (s->symbolId % 64), from.push_back(s);
    };
    for (const Variable& v : m_.variables)
      if (v.alias) note(v.symbol, v.alias);
    for (auto [flow, value] : balances_) note(flow, value);
    for (Expr s : from) {
      Expr& to = aliasOf_[s->symbolId];
      for (int depth = 0; depth < 64; ++depth) {  // chains are short; a cycle cannot come from the alias pass
        Expr next = ctx_.substitute(to, aliasOf_, aliasMask_);
        if (next == to) break;
        to = next;
      }
    }
  }

  bool readsFlow(Expr e) const {
    if (!e) return false;
    for (Expr s : ctx_.freeSymbols(e)) {
      int v = m_.variableOf(s);
      if (v >= 0 && isFlow_[v]) return true;
    }
    return false;
  }

  // A flow read by an energy, a force of the model's own, a start value or an output other than its
  // own column is a result the summed rows do not give.
  std::string flowsReadOnlyByConnections() const {
    for (const auto* terms : {&m_.kinetic, &m_.potential, &m_.dissipation})
      for (const Term& t : *terms)
        if (readsFlow(t.value)) return "an energy reads a connector's flow";
    for (const auto& [q, t] : m_.forces)
      if (!t.connectionFlow && readsFlow(t.value)) return "a force reads a connector's flow";
    for (size_t v = 0; v < m_.variables.size(); ++v)
      if (readsFlow(m_.variables[v].start) || (!isFlow_[v] && readsFlow(m_.variables[v].alias)))
        return "'" + std::string(m_.variables[v].name) + "' is given by a connector's flow";
    for (const Output& o : m_.outputs)
      if (!isFlowColumn(o) && readsFlow(o.value)) return "the output '" + o.name + "' reads a connector's flow";
    return "";
  }

  bool isFlowColumn(const Output& o) const {
    int v = m_.variableOf(o.value);
    return v >= 0 && isFlow_[v];
  }

  // The coordinate a force's target is (itself, or the one it is an alias of, with the alias'
  // sign); nullopt for a potential fixed by parameters (its force is a reaction: no row).
  struct Target {
    int coordinate = -1;
    int sign = 1;
  };
  std::optional<std::optional<Target>> targetOf(int q) const {
    if (!aliased(q)) return std::optional<Target>(Target{q, 1});
    Expr a = aliasOf_[m_.variables[q].symbol->symbolId];
    if (auto s = signedSymbol(a)) {
      int r = m_.variableOf(s->first);
      if (r >= 0 && m_.variables[r].role == VarRole::Coordinate && !aliased(r)) return std::optional<Target>(Target{r, s->second});
    }
    for (Expr s : ctx_.freeSymbols(a)) {
      int v = m_.variableOf(s);
      if (v < 0 || m_.variables[v].role != VarRole::Parameter) return std::nullopt;
    }
    return std::optional<Target>();  // fixed: a reaction
  }

  // The connections' forces on each node's coordinate must cancel (each connection's flows sum to
  // zero); the model's own forces move to the coordinate their target is.
  std::string forcesOnRepresentatives(std::vector<std::pair<int, Term>>& forces) const {
    std::unordered_map<int, std::vector<Expr>> onNode;
    for (const auto& [q, t] : m_.forces) {
      auto target = targetOf(q);
      if (!target) return "'" + std::string(m_.variables[q].name) + "' is an alias of an expression";
      if (!*target) {
        if (!t.connectionFlow) return "a force acts on '" + std::string(m_.variables[q].name) + "', which is fixed";
        continue;
      }
      Expr value = (*target)->sign > 0 ? t.value : ctx_.neg(t.value);
      if (t.connectionFlow) onNode[(*target)->coordinate].push_back(substituted(value));
      else forces.push_back({(*target)->coordinate, {substituted(value), t.range, false}});
    }
    for (const auto& [q, flows] : onNode)
      if (!ctx_.add(flows)->isZero())
        return "the flows at '" + std::string(m_.variables[q].name) + "' do not cancel through its connections";
    return "";
  }

  // Requested results the rewrite removes: a flow cannot be given (nothing computes it any more);
  // a potential or rate made another variable becomes an output of its value.
  std::string requestedResults(std::span<const std::string> results, std::vector<Output>& asked) const {
    for (const std::string& name : results) {
      Expr s = ctx_.findSymbol(name);
      int v = s ? m_.variableOf(s) : -1;
      if (v < 0) continue;
      if (isFlow_[v]) return "the flow '" + name + "' is among the results asked for";
      if (aliased(v)) asked.push_back({name, aliasOf_[s->symbolId], m_.variables[v].declRange});
    }
    return "";
  }

  void rewrite(std::vector<std::pair<int, Term>> forces, std::vector<Output> asked) {
    for (auto* terms : {&m_.kinetic, &m_.potential, &m_.dissipation})
      for (Term& t : *terms) t.value = substituted(t.value);
    std::erase_if(m_.outputs, [&](const Output& o) { return isFlowColumn(o); });
    for (Output& o : m_.outputs) o.value = substituted(o.value);
    m_.outputs.insert(m_.outputs.end(), asked.begin(), asked.end());
    for (Variable& v : m_.variables) v.start = substituted(v.start);
    std::vector<int> newIndex(m_.variables.size(), -1);
    int kept = 0;
    for (size_t v = 0; v < m_.variables.size(); ++v)
      if (!aliased(static_cast<int>(v)) && !isFlow_[v]) newIndex[v] = kept++;
    m_.forces = std::move(forces);  // (on coordinates, which stay)
    m_.equations.clear();           // the balances, which the summed rows fulfil
    renumberVariables(m_, newIndex);
  }
};

}  // namespace

std::string sumConnectedEnergies(FlatModel& model, sym::Context& ctx, std::span<const std::string> results) {
  return Summation(model, ctx).run(results);
}

}  // namespace qdot::flat
