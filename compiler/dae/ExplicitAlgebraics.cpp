// Explicit algebraic unknowns solved out of the DAE (see ExplicitAlgebraics.h).
#include "dae/ExplicitAlgebraics.h"

#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "dae/Balance.h"
#include "structural/Matching.h"

namespace qdot::dae {
namespace {

// A value larger than this (DAG nodes) is not substituted: a chain z_k = z_{k-1} + x_k would
// otherwise make values of every length up to the chain's, quadratic in all.
constexpr size_t kMaxValueNodes = 256;

// Which rows (and values of unknowns already solved out) may contain each candidate unknown, kept
// up to date as values are substituted; an entry is a row r ≥ 0 or the value of variable v as ~v.
class Eliminator {
 public:
  Eliminator(Dae& dae, sym::Context& ctx) : dae_(dae), ctx_(ctx) {
    size_t symbols = ctx.symbolCount();
    variableOf_.assign(symbols, -1);
    isRate_.assign(symbols, 0);
    for (int v = 0; v < static_cast<int>(dae.variables.size()); ++v) {
      const Variable& var = dae.variables[v];
      variableOf_[var.y->symbolId] = v;
      if (var.yp) isRate_[var.yp->symbolId] = 1;
    }
    candidate_.assign(dae.variables.size(), 0);
    for (size_t v = 0; v < dae.variables.size(); ++v) candidate_[v] = isCandidate(dae.variables[v]);
    users_.resize(dae.variables.size());
    values_.assign(dae.variables.size(), nullptr);
    definingRow_.assign(dae.variables.size(), -1);
    rowUsed_.assign(dae.equations.size(), 0);
    for (int r = 0; r < static_cast<int>(dae.equations.size()); ++r) noteUses(dae.equations[r].residual, r);
  }

  size_t run() {
    size_t count = 0;
    for (int z = 0; z < static_cast<int>(dae_.variables.size()); ++z) count += candidate_[z] && eliminate(z);
    return count;
  }

  const std::vector<sym::Expr>& values() const { return values_; }
  const std::vector<char>& rowsUsed() const { return rowUsed_; }
  /// Per unknown solved out: the row it came from (else -1).
  const std::vector<int>& definingRows() const { return definingRow_; }

 private:
  static bool isCandidate(const Variable& v) {
    return v.kind == VarKind::Algebraic && v.role == UnknownRole::Algebraic && !v.declaration.fixed;
  }

  int unknownOf(sym::Expr s) const {
    return s->symbolId < variableOf_.size() ? variableOf_[s->symbolId] : -1;
  }

  // Entry `user` (a row, or ~v for the value of v) contains e's candidates from now on.
  void noteUses(sym::Expr e, int user) {
    for (sym::Expr s : ctx_.freeSymbols(e))
      if (int w = unknownOf(s); w >= 0 && candidate_[w] && !values_[w]) users_[w].push_back(user);
  }

  bool hasRate(sym::Expr e) const {
    for (sym::Expr s : ctx_.freeSymbols(e))
      if (s->symbolId < isRate_.size() && isRate_[s->symbolId]) return true;
    return false;
  }

  // The row that defines z best: z with a constant non-zero coefficient, no y' if possible, small.
  int definingRow(int z, double& coefficient) {
    sym::Expr zs = dae_.variables[z].y;
    int best = -1;
    bool bestHasRate = true;
    size_t bestSize = 0;
    std::unordered_set<int> seen;
    for (int user : users_[z]) {
      if (user < 0 || rowUsed_[user] || !seen.insert(user).second) continue;
      sym::Expr r = dae_.equations[user].residual;
      if (!ctx_.dependsOn(r, zs)) continue;
      double c = coefficientOf(r, zs);
      if (c == 0 || !std::isfinite(c)) continue;
      bool rate = hasRate(r);
      size_t size = ctx_.dagSize({&r, 1});
      if (best < 0 || (bestHasRate && !rate) || (rate == bestHasRate && size < bestSize))
        best = user, bestHasRate = rate, bestSize = size, coefficient = c;
    }
    return best;
  }

  // The position of z among the terms of the sum e when it is one of them and no other term
  // contains it (a flow in its row, the common case), else -1.
  int directTerm(sym::Expr e, sym::Expr zs) const {
    if (e->kind != sym::Kind::Add) return -1;
    int at = -1;
    for (size_t i = 0; i < e->args.size(); ++i)
      if (e->args[i] == zs) at = static_cast<int>(i);
      else if (ctx_.dependsOn(e->args[i], zs)) return -1;
    return at;
  }

  // ∂r/∂z if it is a number (r is then affine in z), else 0.
  double coefficientOf(sym::Expr r, sym::Expr zs) {
    if (int at = directTerm(r, zs); at >= 0) return r->coefs()[at];
    sym::Expr d = ctx_.diff(r, zs);
    return d->isConstant() ? d->value : 0;
  }

  // e with z replaced by its value: the term a·z of a sum becomes a·value, summed in place.
  sym::Expr replaced(sym::Expr e, sym::Expr zs, sym::Expr value) {
    int at = directTerm(e, zs);
    if (at < 0) return ctx_.substitute(e, {{zs, value}});
    return combination(e, at, 1.0, value, e->coefs()[at]);
  }

  bool eliminate(int z) {
    double c = 0;
    int row = definingRow(z, c);
    if (row < 0) return false;
    sym::Expr zs = dae_.variables[z].y;
    sym::Expr value = solvedFor(dae_.equations[row], zs, c);
    if (ctx_.dagSize({&value, 1}) > kMaxValueNodes) return false;
    rowUsed_[row] = 1;
    definingRow_[z] = row;
    values_[z] = value;
    std::vector<int> users = std::move(users_[z]);
    std::unordered_set<int> done;
    for (int user : users) {
      if (!done.insert(user).second || (user >= 0 && rowUsed_[user])) continue;
      if (user >= 0) substituteInRow(dae_.equations[user], user, zs, value);
      else if (sym::Expr& v = values_[~user]; ctx_.dependsOn(v, zs)) v = replaced(v, zs, value), noteUses(value, user);
    }
    noteUses(value, ~z);
    return true;
  }

  // z from its row, where its coefficient is c: the other side as written (`E = expr`), else
  // −g/c for the row c·z + g (affine in z: its derivative is the number c), g being the row at z = 0.
  sym::Expr solvedFor(const Equation& eq, sym::Expr zs, double c) {
    if (eq.lhs == zs && eq.rhs && !ctx_.dependsOn(eq.rhs, zs)) return eq.rhs;
    if (eq.rhs == zs && eq.lhs && !ctx_.dependsOn(eq.lhs, zs)) return eq.lhs;
    return scaledSum(-1.0 / c, replaced(eq.residual, zs, ctx_.zero()));
  }

  // k·e, a sum scaled term by term (k·(a + b) would stay a product: the canonical form does not
  // distribute, and the value is printed as a result's formula).
  sym::Expr scaledSum(double k, sym::Expr e) {
    if (e->kind != sym::Kind::Add || k == 1.0) return ctx_.scale(k, e);
    return combination(e, -1, k, nullptr);
  }

  // Σ over the terms of the sum e but the one at `skip`, each scaled by k, plus k·e's constant and
  // c·value: one sum built at once.
  sym::Expr combination(sym::Expr e, int skip, double k, sym::Expr value, double c = 0) {
    std::vector<sym::Expr> terms{ctx_.one()};
    std::vector<double> coefs{k * e->value};
    for (size_t i = 0; i < e->args.size(); ++i)
      if (static_cast<int>(i) != skip) terms.push_back(e->args[i]), coefs.push_back(k * e->coefs()[i]);
    if (value) terms.push_back(value), coefs.push_back(c);
    return ctx_.linearCombination(terms, coefs);
  }

  void substituteInRow(Equation& eq, int row, sym::Expr zs, sym::Expr value) {
    if (!ctx_.dependsOn(eq.residual, zs)) return;
    eq.residual = replaced(eq.residual, zs, value);
    if (eq.lhs) eq.lhs = replaced(eq.lhs, zs, value);  // the sides as written, for the printers
    if (eq.rhs) eq.rhs = replaced(eq.rhs, zs, value);
    noteUses(value, row);
  }

  Dae& dae_;
  sym::Context& ctx_;
  std::vector<int> variableOf_;  ///< by symbol id: the unknown whose y it is
  std::vector<char> isRate_;     ///< by symbol id: some unknown's y'
  std::vector<char> candidate_;
  std::vector<std::vector<int>> users_;
  std::vector<sym::Expr> values_;  ///< per unknown: its value once solved out
  std::vector<int> definingRow_;
  std::vector<char> rowUsed_;
};

// The DAE without the solved unknowns and their rows; they become outputs, first in the list.
void removeSolved(Dae& dae, sym::Context& ctx, const std::vector<sym::Expr>& values, const std::vector<char>& rowUsed,
                  const std::vector<int>& definingRow) {
  std::unordered_map<sym::Expr, sym::Expr> map;
  std::vector<flat::Output> outputs;
  std::vector<int> newIndex(dae.variables.size(), -1);
  std::vector<Variable> variables;
  for (size_t v = 0; v < dae.variables.size(); ++v) {
    Variable& var = dae.variables[v];
    if (values[v]) {
      map.emplace(var.y, values[v]);
      // located at its equation: where a failure to compute it (sqrt of a negative number) points
      outputs.push_back({var.name, values[v], dae.equations[definingRow[v]].origin.range, flat::OutputKind::Plain});
      continue;
    }
    newIndex[v] = static_cast<int>(variables.size());
    variables.push_back(std::move(var));
  }
  std::vector<int> newRow(dae.equations.size(), -1);
  std::vector<Equation> equations;
  std::vector<std::string> rowCoordinates;
  for (size_t r = 0; r < dae.equations.size(); ++r) {
    if (rowUsed[r]) continue;
    newRow[r] = static_cast<int>(equations.size());
    if (r < dae.rowCoordinates.size()) rowCoordinates.push_back(std::move(dae.rowCoordinates[r]));
    equations.push_back(std::move(dae.equations[r]));
  }
  for (DerivativeLink& l : dae.links) l = {newRow[l.row], newIndex[l.variable], newIndex[l.derivative]};
  for (int& c : dae.coordinates) c = newIndex[c];
  std::erase(dae.coordinates, -1);
  dae.variables = std::move(variables);
  dae.equations = std::move(equations);
  dae.rowCoordinates = std::move(rowCoordinates);

  uint64_t mask = sym::Context::keyMaskOf(map);
  for (Equation& eq : dae.initialEquations) eq.residual = ctx.substitute(eq.residual, map, mask);
  for (flat::Output& o : dae.outputs) o.value = ctx.substitute(o.value, map, mask);
  for (Invariant& inv : dae.invariants) inv.value = ctx.substitute(inv.value, map, mask);
  outputs.insert(outputs.end(), std::make_move_iterator(dae.outputs.begin()), std::make_move_iterator(dae.outputs.end()));
  dae.outputs = std::move(outputs);
}

}  // namespace

EliminationReport eliminateExplicitAlgebraics(Dae& dae, sym::Context& ctx) {
  // Only a DAE of index ≤ 1 as built: index reduction differentiates rows along derivative chains
  // and the run time picks dummy derivatives among them, which this leaves to the whole system.
  if (dae.templated() || !dae.differentiatedRows.empty()) return {};
  for (const Variable& v : dae.variables)
    if (v.role == UnknownRole::Multiplier || v.role == UnknownRole::Derivative) return {};
  if (!structural::maximumMatching(incidence(dae, ctx)).isPerfect()) return {};
  Eliminator eliminator(dae, ctx);
  size_t count = eliminator.run();
  if (count) removeSolved(dae, ctx, eliminator.values(), eliminator.rowsUsed(), eliminator.definingRows());
  return {count};
}

}  // namespace qdot::dae
