// Euler–Lagrange rows and first integrals over an index from symbols to energy terms.
#include "mechanics/EulerLagrange.h"

#include <algorithm>
#include <array>
#include <map>
#include <span>
#include <unordered_map>

#include "flatten/Flatten.h"
#include <utility>

namespace qdot::mech {
namespace {

using flat::VarRole;
using sym::Expr;

/// The summands of an energy (T with +1, V with −1), each with the variables it contains. The
/// index from variables to terms is one flat array (CSR) built once all terms are in: a hash map of
/// small vectors cost a heap block per variable.
class TermIndex {
 public:
  std::vector<Expr> terms;
  bool dependsOnTime = false;

  /// Records that term `term` contains variable `var` (terms in increasing order).
  void addOccurrence(int var, int term) { occurrences_.push_back({var, term}); }

  /// Builds the index over `variableCount` variables; each variable's terms stay in increasing order.
  void finish(size_t variableCount) {
    offsets_.assign(variableCount + 1, 0);
    for (const auto& [var, term] : occurrences_) ++offsets_[var + 1];
    for (size_t v = 0; v < variableCount; ++v) offsets_[v + 1] += offsets_[v];
    termIds_.resize(occurrences_.size());
    std::vector<int> next(offsets_.begin(), offsets_.end() - 1);
    for (const auto& [var, term] : occurrences_) termIds_[next[var]++] = term;
    occurrences_ = {};
  }

  std::span<const int> termsOf(int var) const {
    return {termIds_.data() + offsets_[var], termIds_.data() + offsets_[var + 1]};
  }

 private:
  std::vector<std::pair<int, int>> occurrences_;  ///< (variable, term) while terms are added
  std::vector<int> offsets_;                      ///< size variables + 1
  std::vector<int> termIds_;
};

// The points of `box` outside every box of `covered` (f(point) for each, row-major): a box of one
// dimension has the covered intervals cut out, so a contribution over 10⁶ elements visits its few
// peeled ones rather than all of them; in more dimensions each point is tested against the boxes.
template <class F>
void forEachPointOutside(const flat::Box& box, const std::vector<const flat::Box*>& covered, F&& f) {
  if (box.size() != 1) {
    flat::forEachPoint(box, [&](std::span<const long> point, size_t) {
      for (const flat::Box* c : covered) {
        bool inside = true;
        for (size_t d = 0; d < point.size() && inside; ++d) inside = point[d] >= (*c)[d].first && point[d] <= (*c)[d].second;
        if (inside) return;
      }
      f(point);
    });
    return;
  }
  std::vector<std::pair<long, long>> cuts;
  for (const flat::Box* c : covered)
    if ((*c)[0].first <= (*c)[0].second) cuts.push_back((*c)[0]);
  std::sort(cuts.begin(), cuts.end());
  auto visit = [&](long first, long last) {
    for (long i = first; i <= last; ++i) f(std::span<const long>(&i, 1));
  };
  long next = box[0].first, last = box[0].second;
  for (auto [lo, hi] : cuts) {
    if (lo > last) break;
    if (lo > next) visit(next, lo - 1);
    next = std::max(next, hi + 1);
  }
  visit(next, last);
}

class Deriver {
 public:
  Deriver(const flat::FlatModel& m, sym::Context& ctx, DiagnosticEngine& diags, sym::SimplifyLevel level)
      : m_(m), ctx_(ctx), diags_(diags), level_(level), simplifier_(ctx, level) {}

  std::optional<EquationsOfMotion> run() {
    size_t errorsBefore = diags_.errorCount();
    std::vector<flat::Term> kinetic = m_.kinetic, potential = m_.potential, dissipation = m_.dissipation;
    bool templates = !m_.indexedSums.empty() || !m_.indexedForces.empty();
    if (templates) expandScalarTemplates(kinetic, potential, dissipation);
    index(lagrangian_, kinetic, 1.0);
    index(lagrangian_, potential, -1.0);
    index(dissipation_, dissipation, 1.0);
    lagrangian_.finish(m_.variables.size());
    dissipation_.finish(m_.variables.size());
    makeMultipliers();
    coordinates_ = m_.variablesWithRole(VarRole::Coordinate);  // one pass: a large model has 3 variables per element
    if (templates) deriveTemplates();
    for (int q : coordinates_) derive(q);
    if (diags_.errorCount() > errorsBefore) return std::nullopt;
    findFirstIntegrals();
    out_.kinetic = simplified(total(m_.kinetic));
    out_.potential = simplified(total(m_.potential));
    out_.dissipation = simplified(total(m_.dissipation));
    return std::move(out_);
  }

 private:
  const flat::FlatModel& m_;
  sym::Context& ctx_;
  DiagnosticEngine& diags_;
  sym::SimplifyLevel level_;
  sym::Simplifier simplifier_;
  bool energiesSimplified_ = true;  ///< no energy ran out of the simplifier's budget
  TermIndex lagrangian_, dissipation_;
  /// The generalized forces on each coordinate that has any (by flat variable: few of a large
  /// model's variables have one, so not a vector over all of them).
  std::unordered_map<int, std::vector<Expr>> forces_;
  EquationsOfMotion out_;
  std::optional<sym::DirectionalDerivative> timeDerivative_;  ///< d/dt, set up on first use

  Expr total(const std::vector<flat::Term>& terms) {
    std::vector<Expr> v;
    for (const auto& t : terms) v.push_back(t.value);
    return ctx_.add(v);
  }

  // Splits every statement into its top-level summands and records which variables each contains.
  // The summands hold exactly the statement's symbols, so the energy check looks at those; only a
  // statement that fails it is walked again, to report its symbols in order of appearance.
  // Statements worth simplifying are simplified together (the terms of x, y and z of one mass cancel
  // across statements too); their variables are checked statement by statement first.
  void index(TermIndex& idx, const std::vector<flat::Term>& terms, double sign) {
    std::vector<Expr> together;
    for (const auto& t : terms) {
      if (sym::worthSimplifying(t.value, level_)) {
        if (!energyVariablesAllowed(t.value)) checkEnergyVariables(t);
        together.push_back(t.value);
      } else if (!addSummands(idx, t.value, sign)) {
        checkEnergyVariables(t);
      }
    }
    if (together.empty()) return;
    addSummands(idx, simplifier_(ctx_.add(together)), sign);
    energiesSimplified_ &= !simplifier_.gaveUp();
  }

  bool addSummands(TermIndex& idx, Expr e, double sign) {
    bool allowed = true;
    if (e->kind == sym::Kind::Add) {
      for (size_t i = 0; i < e->args.size(); ++i) allowed &= addSummands(idx, ctx_.scale(sign * e->coefs()[i], e->args[i]), 1.0);
    } else if (Expr sum = distributedSum(e)) {
      Expr rest = ctx_.div(e, sum);  // the other factors and the coefficient
      for (size_t i = 0; i < sum->args.size(); ++i)
        allowed &= addSummands(idx, ctx_.mul(rest, ctx_.scale(sign * sum->coefs()[i], sum->args[i])), 1.0);
      if (sum->value != 0) allowed &= addSummands(idx, ctx_.scale(sign * sum->value, rest), 1.0);
    } else if (!e->isConstant()) {
      allowed = addTerm(idx, ctx_.scale(sign, e));
    }
    return allowed;
  }

  // A product with a long sum among its factors (`0.5*m*(v1^2 + … + vn^2)`, a factor written
  // outside a `sum(…)`): that sum, whose terms become terms of their own — one term containing
  // every variable would be differentiated whole for each of them (n rows × n terms).
  static Expr distributedSum(Expr e) {
    constexpr size_t kLong = 8;
    if (e->kind != sym::Kind::Mul) return nullptr;
    for (size_t i = 0; i < e->args.size(); ++i)
      if (e->args[i]->kind == sym::Kind::Add && e->args[i]->args.size() >= kLong && e->exps()[i]->isOne()) return e->args[i];
    return nullptr;
  }

  bool energyVariablesAllowed(Expr e) {
    for (Expr s : ctx_.freeSymbols(e))
      if (int var = m_.variableOf(s); var >= 0 && !mayAppearInEnergy(m_.variables[var].role)) return false;
    return true;
  }

  // Rows, momenta and integrals are simplified only when the energies were: derived from energies
  // too large for the budget, they would exceed it too, and trying would only cost time.
  Expr simplified(Expr e) { return energiesSimplified_ && sym::worthSimplifying(e, level_) ? simplifier_(e) : e; }

  // Returns false if the term contains a variable an energy may not depend on.
  bool addTerm(TermIndex& idx, Expr term) {
    int id = static_cast<int>(idx.terms.size());
    idx.terms.push_back(term);
    bool allowed = true;
    for (Expr s : ctx_.freeSymbols(term)) {
      int var = m_.variableOf(s);
      if (var < 0) continue;
      allowed &= mayAppearInEnergy(m_.variables[var].role);
      if (m_.variables[var].role == VarRole::Time) idx.dependsOnTime = true;
      idx.addOccurrence(var, id);
    }
    return allowed;
  }

  static bool mayAppearInEnergy(VarRole r) {
    return r == VarRole::Coordinate || r == VarRole::Velocity || r == VarRole::Parameter || r == VarRole::Time;
  }

  // Energies may depend on coordinates, their velocities, parameters and time only.
  void checkEnergyVariables(const flat::Term& t) {
    for (Expr s : ctx_.freeSymbols(t.value)) {
      int var = m_.variableOf(s);
      if (var < 0) continue;
      VarRole r = m_.variables[var].role;
      if (mayAppearInEnergy(r)) continue;
      // The declaration to change: der(y[2]) is y's rate, y[2] an element of y.
      const flat::Variable& shown = r == VarRole::Derivative && m_.variables[var].derivativeOf >= 0
                                        ? m_.variables[m_.variables[var].derivativeOf]
                                        : m_.variables[var];
      std::string declared(shown.name.substr(0, shown.name.find('[')));
      diags_.error(t.range, DiagCode::E0402,
                   "this energy depends on '" + std::string(m_.variables[var].name) +
                       "', which is not a coordinate or its velocity",
                   r == VarRole::Acceleration
                       ? "energies cannot depend on accelerations"
                       : "declare '" + declared + "' as 'coordinate Real " + declared +
                             "', or express it through the coordinates with a definition");
    }
  }

  void makeMultipliers() {
    for (size_t k = 0; k < m_.constraints.size(); ++k) {
      std::string name = "lambda[" + std::to_string(k + 1) + "]";
      out_.multipliers.push_back({name, ctx_.symbol(name), static_cast<int>(k)});
    }
    for (const auto& [q, term] : m_.forces) forces_[q].push_back(term.value);
    for (const auto& [q, value] : scalarForces_) forces_[q].push_back(value);
  }

  std::span<const Expr> forcesOn(int q) const {
    auto it = forces_.find(q);
    return it == forces_.end() ? std::span<const Expr>() : std::span<const Expr>(it->second);
  }

  Expr partial(const TermIndex& idx, int var) {
    std::vector<Expr> parts;
    Expr s = m_.variables[var].symbol;
    for (int t : idx.termsOf(var)) parts.push_back(ctx_.diff(idx.terms[t], s));
    return ctx_.add(parts);
  }

  // d/dt of an expression in coordinates, velocities, parameters and time: along q → v, v → a and
  // time → 1 (everything else is constant). One derivative object for all rows, so subexpressions
  // the momenta share (the velocities of every mass) are differentiated once. The rates of e's
  // symbols are given before e is differentiated (a derivative depends only on the rates of the
  // symbols it contains), so a templated model's few scalar rows do not pay per element.
  Expr timeDerivative(Expr e) {
    if (!timeDerivative_) timeDerivative_.emplace(ctx_), rateGiven_.assign(ctx_.symbolCount(), 0);
    for (Expr s : ctx_.freeSymbols(e)) {
      if (s->symbolId >= rateGiven_.size()) rateGiven_.resize(s->symbolId + 1, 0);
      if (rateGiven_[s->symbolId]) continue;
      rateGiven_[s->symbolId] = 1;
      int var = m_.variableOf(s);
      if (var < 0) continue;
      const flat::Variable& v = m_.variables[var];
      if (v.role == VarRole::Time) timeDerivative_->setRate(v.symbol, ctx_.one());
      else if ((v.role == VarRole::Coordinate || v.role == VarRole::Velocity) && v.derivative >= 0)
        timeDerivative_->setRate(v.symbol, m_.variables[v.derivative].symbol);
    }
    return (*timeDerivative_)(e);
  }
  std::vector<char> rateGiven_;  ///< by symbolId: its rate has been given to timeDerivative_

  // --- templates (issue 15, TemplateRows.h) ---
  std::vector<int> templateOf_;  ///< by flat variable: the template row of its element, or -1
  /// The templates' contributions to a peeled element's row, instantiated (by flat variable).
  struct PeeledExtras {
    Expr momentum = nullptr, position = nullptr, dissipation = nullptr, force = nullptr;
  };
  std::unordered_map<int, PeeledExtras> extras_;
  bool templated_ = false;

  // Sums and forces that cannot give template rows become the scalar terms and forces flattening
  // would have made.
  void expandScalarTemplates(std::vector<flat::Term>& kinetic, std::vector<flat::Term>& potential,
                             std::vector<flat::Term>& dissipation) {
    TemplateDerivation t = templatesWithoutRows(m_, ctx_);
    for (int f : t.scalarForces) {
      const flat::IndexedForce& force = m_.indexedForces[f];
      flat::forEachPoint(force.box, [&](std::span<const long> point, size_t) {
        int q = m_.variableOf(flat::instantiate(m_, ctx_, force.target, point));
        scalarForces_.push_back({q, flat::instantiate(m_, ctx_, force.body, point)});
      });
    }
    for (int s : t.scalarSums) {
      const flat::IndexedSum& sum = m_.indexedSums[s];
      auto& terms = sum.energy == flat::IndexedSum::Energy::Kinetic     ? kinetic
                    : sum.energy == flat::IndexedSum::Energy::Potential ? potential
                                                                        : dissipation;
      std::vector<Expr> parts;
      flat::forEachPoint(sum.box, [&](std::span<const long> point, size_t) { parts.push_back(flat::instantiate(m_, ctx_, sum.body, point)); });
      terms[sum.term].value = ctx_.add(terms[sum.term].value, ctx_.add(parts));
      scalarSums_.push_back(s);
    }
  }
  std::vector<int> scalarSums_;
  std::vector<int> coordinates_;  ///< the flat variables of role Coordinate, in order
  std::vector<std::pair<int, Expr>> scalarForces_;  ///< force templates made scalar: (coordinate, force)

  // Coordinates that occur in scalar terms, forces or constraints keep scalar rows (peeled).
  std::vector<char> peeledCoordinates() const {
    std::vector<char> peeled(m_.variables.size(), 0);
    for (int q : coordinates_) {
      int v = m_.variables[q].derivative;
      peeled[q] = !lagrangian_.termsOf(q).empty() || !lagrangian_.termsOf(v).empty() || !dissipation_.termsOf(v).empty() ||
                  !forcesOn(q).empty() || !m_.constraints.empty() || m_.variables[q].alias;
    }
    return peeled;
  }

  void deriveTemplates() {
    TemplateDerivation t = deriveTemplateRows(m_, ctx_, peeledCoordinates(), level_);
    templated_ = true;
    templateOf_.assign(m_.variables.size(), -1);
    const auto& arrays = m_.patterns->arrays;
    for (int r = 0; r < static_cast<int>(t.rows.size()); ++r) {
      const auto& a = arrays[t.rows[r].array];
      flat::forEachPoint(t.rows[r].region, [&](std::span<const long> point, size_t) {
        templateOf_[m_.variableOf(a.elements[flat::linearIndex(a.shape, point)])] = r;
      });
    }
    // Peeled elements and regions of one element: their contributions, instantiated.
    std::map<int, std::array<std::vector<Expr>, 4>> parts;  // by flat variable: momentum, position, dissipation, force
    for (const Contribution& c : t.contributions) {
      const auto& a = arrays[c.array];
      // A point inside a template row's region of the same array is that row's element (skipped
      // below in any case): only the others are looked at.
      std::vector<const flat::Box*> covered;
      for (const TemplateRow& row : t.rows)
        if (row.array == c.array) covered.push_back(&row.region);
      forEachPointOutside(c.box, covered, [&](std::span<const long> point) {
        int q = m_.variableOf(a.elements[flat::linearIndex(a.shape, point)]);
        if (templateOf_[q] >= 0) return;
        int part = c.part == Contribution::Part::Momentum   ? 0
                   : c.part == Contribution::Part::Position ? 1
                   : c.part == Contribution::Part::Force    ? 3
                                                            : 2;
        parts[q][part].push_back(flat::instantiate(m_, ctx_, c.value, point));
      });
    }
    auto sum = [&](const std::vector<Expr>& terms) { return terms.empty() ? nullptr : ctx_.add(terms); };
    for (const auto& [q, p] : parts) extras_[q] = {sum(p[0]), sum(p[1]), sum(p[2]), sum(p[3])};
    out_.templateRows = std::move(t.rows);
  }

  Expr plus(Expr a, Expr extra) { return extra ? ctx_.add(a, extra) : a; }

  void derive(int q) {
    const flat::Variable& coord = m_.variables[q];
    int v = coord.derivative;
    if (templated_ && templateOf_[q] >= 0) {
      out_.rows.push_back({q, nullptr, nullptr, true, templateOf_[q]});
      return;
    }
    auto found = extras_.find(q);
    PeeledExtras none, &extras = found == extras_.end() ? none : found->second;
    bool extra = extras.momentum || extras.position || extras.dissipation || extras.force;
    Expr p = plus(partial(lagrangian_, v), extras.momentum);
    std::vector<Expr> parts{timeDerivative(p), ctx_.neg(plus(partial(lagrangian_, q), extras.position)),
                            plus(partial(dissipation_, v), extras.dissipation)};
    for (Expr f : forcesOn(q)) parts.push_back(ctx_.neg(f));
    if (extras.force) parts.push_back(ctx_.neg(extras.force));
    bool constrained = false;
    for (const auto& mult : out_.multipliers) {
      Expr dg = ctx_.diff(m_.constraints[mult.constraint].residual, coord.symbol);
      constrained |= !dg->isZero();
      parts.push_back(ctx_.neg(ctx_.mul(mult.symbol, dg)));
    }
    Expr residual = ctx_.add(parts);
    if (lagrangian_.termsOf(q).empty() && lagrangian_.termsOf(v).empty() && forcesOn(q).empty() && !constrained && !extra) {
      diags_.error(coord.declRange, DiagCode::E0401,
                   "coordinate '" + std::string(coord.name) + "' appears in no energy, force or constraint",
                   "add its kinetic energy in the mechanics section, or declare it as a plain 'Real'");
      return;
    }
    bool inertial = !lagrangian_.termsOf(v).empty() || extras.momentum;
    out_.rows.push_back({q, simplified(residual), simplified(p), inertial});
  }

  void findFirstIntegrals() {
    // Connector flows are forces between components: with connectionsConserveEnergy their power
    // cancels node by node, so only `force(q)` statements make the system non-conservative.
    bool statedForces = !m_.indexedForces.empty() ||
                        std::any_of(m_.forces.begin(), m_.forces.end(), [](const auto& f) { return !f.second.connectionFlow; });
    bool conservative = m_.dissipation.empty() && !statedForces && m_.connectionsConserveEnergy &&
                        !lagrangian_.dependsOnTime;
    for (const auto& c : m_.constraints) conservative &= !ctx_.dependsOn(c.residual, m_.time());
    std::vector<Expr> jacobi;  // Σ v ∂L/∂v, only built when the Jacobi integral exists
    for (const auto& row : out_.rows) {
      if (row.templateRow >= 0) continue;
      const flat::Variable& coord = m_.variables[row.coordinate];
      int v = coord.derivative;
      // A templated model's scalar terms only: a peeled element's momentum has the sums' part too,
      // which their own loops count (jacobiSums).
      if (conservative)
        jacobi.push_back(ctx_.mul(m_.variables[v].symbol, templated_ ? partial(lagrangian_, v) : row.momentum));
      // A peeled element of a templated array is in the templates' sums too (the last mass of a
      // chain: in no scalar term, but in the springs' sum).
      auto found = extras_.find(row.coordinate);
      bool inTemplates = found != extras_.end() && (found->second.position || found->second.dissipation || found->second.force);
      bool cyclic = !m_.variables[row.coordinate].alias && lagrangian_.termsOf(row.coordinate).empty() &&
                    forcesOn(row.coordinate).empty() && !inTemplates &&
                    dissipation_.termsOf(v).empty() && !row.momentum->isZero();
      for (const auto& c : m_.constraints) cyclic &= !ctx_.dependsOn(c.residual, coord.symbol);
      if (cyclic)
        out_.integrals.push_back(
            {FirstIntegral::Kind::CyclicMomentum, row.coordinate, "p(" + std::string(coord.name) + ")", row.momentum});
    }
    // Without coordinates there is no Lagrangian whose energy could be conserved (a model of
    // equations or rigid bodies only): a Jacobi integral would be the constant 0.
    if (!conservative || out_.rows.empty()) return;
    jacobi.push_back(ctx_.neg(ctx_.add(lagrangian_.terms)));
    std::vector<flat::IndexedTerm> sums;
    if (templated_) sums = jacobiSums(jacobi);
    out_.integrals.push_back({FirstIntegral::Kind::Jacobi, -1, "jacobi", simplified(ctx_.add(jacobi)), std::move(sums)});
  }

  // The energy sums kept as templates in the Jacobi integral h = Σ v ∂L/∂v − L, which is linear
  // in L's terms: per sum of T (sign +1) or V (−1) with body b, Σ over its box of
  // ±(Σ_r r ∂b/∂r − b), r every velocity in b (its own elements' and scalar ones). A body without
  // relative symbols is the same at every point: its total joins the scalar terms (so do the
  // points of one that reads arrays of parameters only).
  std::vector<flat::IndexedTerm> jacobiSums(std::vector<Expr>& scalar) {
    std::vector<flat::IndexedTerm> sums;
    for (int s = 0; s < static_cast<int>(m_.indexedSums.size()); ++s) {
      const flat::IndexedSum& sum = m_.indexedSums[s];
      if (sum.energy == flat::IndexedSum::Energy::Dissipation ||
          std::find(scalarSums_.begin(), scalarSums_.end(), s) != scalarSums_.end())
        continue;
      std::vector<Expr> parts{ctx_.neg(sum.body)};
      std::vector<int> shape;
      bool relative = false;
      for (Expr r : ctx_.freeSymbols(sum.body)) {
        VarRole role = VarRole::Parameter;
        relative |= m_.patterns->iteratorOf(r) >= 0;  // the body changes from point to point
        if (const flat::RelativeElement* rel = m_.relativeElement(r)) {
          relative = true;
          const flat::ArrayVariable& a = m_.patterns->arrays[rel->array];
          int var = m_.variableOf(a.elements[0]);
          if (var >= 0) role = m_.variables[var].role;
          if (role == VarRole::Coordinate || role == VarRole::Velocity) shape = a.shape;
        } else if (int var = m_.variableOf(r); var >= 0) {
          role = m_.variables[var].role;
        }
        if (role == VarRole::Velocity) parts.push_back(ctx_.mul(r, ctx_.diff(sum.body, r)));
      }
      Expr body = ctx_.scale(sum.energy == flat::IndexedSum::Energy::Kinetic ? 1.0 : -1.0, ctx_.add(parts));
      if (!shape.empty()) {
        sums.push_back({sum.box, std::move(shape), simplified(body)});
      } else if (!relative) {
        scalar.push_back(ctx_.scale(static_cast<double>(flat::pointCount(sum.box)), body));
      } else {  // arrays of parameters only: no loop reads them without coordinates (Pipeline.cpp)
        flat::forEachPoint(sum.box, [&](std::span<const long> p, size_t) { scalar.push_back(flat::instantiate(m_, ctx_, body, p)); });
      }
    }
    return sums;
  }
};

}  // namespace

std::optional<EquationsOfMotion> deriveEquationsOfMotion(const flat::FlatModel& model, sym::Context& ctx,
                                                         DiagnosticEngine& diags, sym::SimplifyLevel simplify) {
  return Deriver(model, ctx, diags, simplify).run();
}

}  // namespace qdot::mech
