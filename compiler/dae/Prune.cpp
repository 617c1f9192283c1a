// Pruning to the requested results (see Prune.h).
#include "dae/Prune.h"

#include <algorithm>
#include <unordered_map>

#include "dae/Balance.h"
#include "structural/Matching.h"

namespace qdot::dae {
namespace {

// Which DAE variable each symbol is (its y, and for a state its y'), by symbol id.
std::vector<int> variableOfSymbol(const Dae& dae, const sym::Context& ctx) {
  std::vector<int> of(ctx.symbolCount(), -1);
  for (int i = 0; i < static_cast<int>(dae.variables.size()); ++i) {
    of[dae.variables[i].y->symbolId] = i;
    if (dae.variables[i].yp) of[dae.variables[i].yp->symbolId] = i;
  }
  return of;
}

// Each equation's variables (their y or y'): what computing it needs.
std::vector<std::vector<int>> variablesOfEquations(const Dae& dae, const sym::Context& ctx, const std::vector<int>& of) {
  std::vector<std::vector<int>> variables(dae.equations.size());
  for (size_t e = 0; e < dae.equations.size(); ++e)
    for (sym::Expr s : ctx.freeSymbols(dae.equations[e].residual))
      if (s->symbolId < of.size() && of[s->symbolId] >= 0) variables[e].push_back(of[s->symbolId]);
  return variables;
}

}  // namespace

PruneReport pruneToResults(Dae& dae, const std::vector<std::string>& names, sym::Context& ctx) {
  PruneReport report;
  report.variablesBefore = report.variablesKept = dae.variables.size();
  report.equationsBefore = report.equationsKept = dae.equations.size();
  std::vector<int> of = variableOfSymbol(dae, ctx);
  std::unordered_map<std::string, int> byName;
  for (int i = 0; i < static_cast<int>(dae.variables.size()); ++i) byName.emplace(dae.variables[i].name, i);

  // The seeds: named variables, and the variables of named outputs and invariants.
  std::vector<int> seeds;
  std::vector<char> keepOutput(dae.outputs.size(), 0), keepInvariant(dae.invariants.size(), 0);
  auto seedExpr = [&](sym::Expr e) {
    for (sym::Expr s : ctx.freeSymbols(e))
      if (s->symbolId < of.size() && of[s->symbolId] >= 0) seeds.push_back(of[s->symbolId]);
  };
  for (const std::string& name : names) {
    bool found = false;
    if (auto it = byName.find(name); it != byName.end()) seeds.push_back(it->second), found = true;
    for (size_t o = 0; o < dae.outputs.size(); ++o)
      if (dae.outputs[o].name == name) keepOutput[o] = 1, seedExpr(dae.outputs[o].value), found = true;
    for (size_t k = 0; k < dae.invariants.size(); ++k)
      if (dae.invariants[k].name == name) keepInvariant[k] = 1, seedExpr(dae.invariants[k].value), found = true;
    if (!found) report.unknownNames.push_back(name);
  }
  if (!report.unknownNames.empty() || names.empty()) return report;

  structural::Matching matching = structural::maximumMatching(incidence(dae, ctx));
  if (!matching.isPerfect()) return report;  // not balanced: keep it whole, the checks have spoken

  // Closure: a needed variable needs its equation, which needs every variable it contains.
  std::vector<std::vector<int>> variablesOf = variablesOfEquations(dae, ctx, of);
  std::vector<char> neededVar(dae.variables.size(), 0), neededEq(dae.equations.size(), 0);
  std::vector<int> work;
  auto need = [&](int v) {
    if (!neededVar[v]) neededVar[v] = 1, work.push_back(v);
  };
  for (int v : seeds) need(v);
  // An initial equation ties its variables' start values: one needed variable needs them all.
  std::vector<std::vector<int>> initialVariables;
  for (const auto& eq : dae.initialEquations) {
    initialVariables.emplace_back();
    for (sym::Expr s : ctx.freeSymbols(eq.residual))
      if (s->symbolId < of.size() && of[s->symbolId] >= 0) initialVariables.back().push_back(of[s->symbolId]);
  }
  std::vector<char> initialUsed(initialVariables.size(), 0);
  for (bool grew = true; grew;) {
    while (!work.empty()) {
      int v = work.back();
      work.pop_back();
      int e = matching.matchOfVariable[v];
      if (e < 0 || neededEq[e]) continue;
      neededEq[e] = 1;
      for (int w : variablesOf[e]) need(w);
    }
    grew = false;
    for (size_t k = 0; k < initialVariables.size(); ++k) {
      if (initialUsed[k] || std::none_of(initialVariables[k].begin(), initialVariables[k].end(),
                                         [&](int v) { return neededVar[v] != 0; }))
        continue;
      initialUsed[k] = 1;
      for (int w : initialVariables[k]) need(w);
      grew |= !work.empty();
    }
  }

  // Keep in order; remap the variable indices the DAE holds.
  std::vector<int> newIndex(dae.variables.size(), -1);
  std::vector<Variable> variables;
  for (size_t i = 0; i < dae.variables.size(); ++i)
    if (neededVar[i]) newIndex[i] = static_cast<int>(variables.size()), variables.push_back(std::move(dae.variables[i]));
  std::vector<Equation> equations;
  std::vector<std::string> rows;
  std::vector<int> newRow(dae.equations.size(), -1);
  for (size_t e = 0; e < dae.equations.size(); ++e) {
    if (!neededEq[e]) continue;
    newRow[e] = static_cast<int>(equations.size());
    if (e < dae.rowCoordinates.size()) rows.push_back(dae.rowCoordinates[e]);
    equations.push_back(std::move(dae.equations[e]));
  }
  std::vector<int> coordinates;
  for (int c : dae.coordinates)
    if (newIndex[c] >= 0) coordinates.push_back(newIndex[c]);
  std::vector<DerivativeLink> links;
  for (const DerivativeLink& l : dae.links)
    if (newRow[l.row] >= 0 && newIndex[l.variable] >= 0 && newIndex[l.derivative] >= 0)
      links.push_back({newRow[l.row], newIndex[l.variable], newIndex[l.derivative]});
  dae.links = std::move(links);
  dae.variables = std::move(variables);
  dae.equations = std::move(equations);
  dae.rowCoordinates = std::move(rows);
  dae.coordinates = std::move(coordinates);

  // Initial equations of dropped variables only, outputs and invariants not named: dropped.
  std::vector<Equation> initial;
  for (size_t k = 0; k < dae.initialEquations.size(); ++k)
    if (initialUsed[k]) initial.push_back(std::move(dae.initialEquations[k]));
  dae.initialEquations = std::move(initial);
  std::vector<flat::Output> outputs;
  for (size_t o = 0; o < dae.outputs.size(); ++o)
    if (keepOutput[o]) outputs.push_back(std::move(dae.outputs[o]));
  dae.outputs = std::move(outputs);
  std::vector<Invariant> invariants;
  for (size_t k = 0; k < dae.invariants.size(); ++k)
    if (keepInvariant[k]) invariants.push_back(std::move(dae.invariants[k]));
  dae.invariants = std::move(invariants);
  report.variablesKept = dae.variables.size();
  report.equationsKept = dae.equations.size();
  return report;
}

}  // namespace qdot::dae
