// Assembles the DAE from the flat model and its equations of motion: classifies every unknown,
// adds the kinematic rows q' = der(q), and checks the balance of equations and unknowns.
#include "dae/Dae.h"
#include "dae/Balance.h"
#include "dae/TemplateOde.h"
#include "flatten/Flatten.h"
#include "support/Assert.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>

namespace qdot::dae {
namespace {

using sym::Expr;

class Builder {
 public:
  Builder(const flat::FlatModel& m, const mech::EquationsOfMotion& eom, sym::Context& ctx, DiagnosticEngine& diags)
      : m_(m), eom_(eom), ctx_(ctx), diags_(diags) {}

  std::optional<Dae> run() {
    QDOT_ASSERT(m_.equationSums.empty(), "buildDae: an equation with sums the pipeline neither expanded nor made an output");
    size_t errorsBefore = diags_.errorCount();
    dae_.name = m_.name;
    dae_.description = m_.description;
    dae_.range = m_.range;
    dae_.time = m_.time();
    dae_.experiment = m_.experiment;
    dae_.structuralParameters = m_.structuralParameters;
    dae_.unconnected = m_.unconnected;
    dae_.outputs = m_.outputs;
    sortVariablesByRole();
    if (!m_.equationTemplates.empty()) {  // an explicit ODE (isTemplatedOde): balanced by construction
      addParameters();
      addTemplatedOde(m_, ctx_, dae_);
      expandOutputSums();
      return std::move(dae_);
    }
    collectAliases();
    addParameters();
    addEquations();
    dae_.variables.reserve(unknownCount());
    addMechanics();
    insertKinematicRows();
    addUnknowns();
    for (const auto& fi : eom_.integrals)
      dae_.invariants.push_back({fi.name, fi.kind == mech::FirstIntegral::Kind::Jacobi ? "Jacobi integral" : "cyclic momentum",
                                 substituted(fi.value), fi.sums});
    if (!aliases_.empty()) substituteRest();
    if (!eom_.templateRows.empty()) addTemplateBlocks(), addScalarKinematicResiduals();
    if (!dae_.templated()) expandInvariantSums(), expandOutputSums();
    // Template rows are one Euler–Lagrange row per coordinate and its kinematic row by construction.
    if (diags_.errorCount() == errorsBefore && !dae_.templated()) checkBalance(dae_, ctx_, diags_);
    if (diags_.errorCount() > errorsBefore) return std::nullopt;
    return std::move(dae_);
  }

 private:
  // Without template rows (every element peeled) the structural passes see scalars: an
  // invariant's sums become its terms at every point.
  void expandInvariantSums() {
    for (Invariant& inv : dae_.invariants) {
      std::vector<Expr> terms{inv.value};
      for (const flat::IndexedTerm& sum : inv.sums)
        flat::forEachPoint(sum.box, [&](std::span<const long> p, size_t) { terms.push_back(flat::instantiate(m_, ctx_, sum.body, p)); });
      inv.value = ctx_.add(terms);
      inv.sums.clear();
    }
  }
  // An output's sums likewise (flat::withSumsExpanded: what the scalar lowering of its binding gives).
  void expandOutputSums() {
    for (flat::Output& o : dae_.outputs) {
      if (o.sums.empty()) continue;
      o.value = substituted(flat::withSumsExpanded(m_, ctx_, o.value, o.sums));
      o.sums.clear();
    }
  }

  const flat::FlatModel& m_;
  const mech::EquationsOfMotion& eom_;
  sym::Context& ctx_;
  DiagnosticEngine& diags_;
  Dae dae_;
  size_t firstKinematic_ = 0;  ///< where addMechanics appended the kinematic rows
  enum RowKind : char { Skip, Algebraic, NotInertial, Inertial };  ///< of a coordinate's row, in addMechanics
  std::vector<char> kinematicTaken_;  ///< per kinematic row (templated models): a template's
  std::vector<std::pair<int, int>> kinematicPairs_;  ///< per kinematic row: coordinate, velocity (index among velocities)
  std::unordered_map<Expr, Expr> aliases_;  ///< symbol of a variable that is not an unknown → its value
  std::vector<Expr> aliasTable_;            ///< the same by symbol id (null: no alias), for substituting
  uint64_t aliasMask_ = 0;
  std::vector<char> appears_;               ///< by symbol id: in some equation (after substitution)
  /// The flat variables the steps below visit, found in one pass: a large model has three per
  /// array element (x, der(x), der(der(x))), and a pass over them costs more than the steps' work.
  struct VariablesByRole {
    std::vector<int> aliased;     ///< with an alias, any role
    std::vector<int> parameters;  ///< in declaration order
    std::vector<int> unknowns;    ///< role Unknown and no alias, in declaration order
    size_t unknownRole = 0;       ///< role Unknown, aliased or not
  } byRole_;

  void sortVariablesByRole() {
    for (int i = 0; i < static_cast<int>(m_.variables.size()); ++i) {
      const flat::Variable& f = m_.variables[i];
      if (f.alias) byRole_.aliased.push_back(i);
      if (f.role == flat::VarRole::Parameter) byRole_.parameters.push_back(i);
      if (f.role != flat::VarRole::Unknown) continue;
      ++byRole_.unknownRole;
      if (!f.alias) byRole_.unknowns.push_back(i);
    }
  }

  // Connected potentials and their derivatives are one variable (FlatModel: Variable::alias).
  void collectAliases() {
    for (int i : byRole_.aliased) aliases_.emplace(m_.variables[i].symbol, m_.variables[i].alias);
    // An alias of an alias (a value that is itself eliminated) resolves to the end of the chain.
    aliasMask_ = sym::Context::keyMaskOf(aliases_);
    for (auto& [from, to] : aliases_)
      for (int guard = 0; guard < 8; ++guard) {
        Expr next = ctx_.substitute(to, aliases_, aliasMask_);
        if (next == to) break;
        to = next;
      }
    if (aliases_.empty()) return;
    aliasTable_.assign(ctx_.symbolCount(), nullptr);
    for (const auto& [from, to] : aliases_) aliasTable_[from->symbolId] = to;
  }

  Expr substituted(Expr e) { return aliases_.empty() || !e ? e : ctx_.substitute(e, aliasTable_, aliasMask_); }

  // Which symbols the equations contain: decides what kind of unknown each coordinate is.
  void markAppearances() {
    appears_.assign(ctx_.symbolCount(), 0);
    for (const auto& eq : dae_.equations)
      if (eq.residual)
        for (Expr s : ctx_.freeSymbols(eq.residual)) appears_[s->symbolId] = 1;
  }
  bool appears(Expr s) const { return s->symbolId < appears_.size() && appears_[s->symbolId]; }

  void substituteRest() {
    for (auto& o : dae_.outputs) {
      o.value = substituted(o.value);
      for (flat::IndexedTerm& sum : o.sums) sum.body = substituted(sum.body);
    }
    for (auto& v : dae_.variables) v.declaration.start = substituted(v.declaration.start);
  }

  // At most: a coordinate and its velocity per row, every other unknown, every multiplier.
  size_t unknownCount() const {
    return 2 * eom_.rows.size() + eom_.multipliers.size() + byRole_.unknownRole;
  }

  Variable fromFlat(int index, VarKind kind, UnknownRole role) {
    const flat::Variable& f = m_.variables[index];
    return Variable{.name = std::string(f.name), .kind = kind, .role = role, .flatVar = index, .y = f.symbol,
                    .declaration = Declaration::of(m_, index)};
  }

  void addParameters() {
    for (int i : byRole_.parameters) {
      const flat::Variable& f = m_.variables[i];
      dae_.parameters.push_back({std::string(f.name), f.symbol, f.value, std::string(m_.attributesOf(f).description),
                                 std::string(m_.attributesOf(f).unit), f.declRange, f.input});
    }
  }

  // Coordinates first, then velocities (spec §5). A coordinate whose row contains no velocity at
  // all is algebraic (massless node); one with velocity only through forces or dissipation keeps q
  // as a state and its velocity algebraic. Written in place (two passes over the rows): a large
  // model's unknowns and kinematic rows are not built in temporaries and then moved.
  void addMechanics() {
    markAppearances();
    std::vector<char> kindOf(eom_.rows.size(), Skip);
    for (size_t r = 0; r < eom_.rows.size(); ++r) {
      const auto& row = eom_.rows[r];
      const flat::Variable& q = m_.variables[row.coordinate];
      if (q.alias) continue;  // its row stays an equation; it is another variable
      const flat::Variable& v = m_.variables[q.derivative];
      // Inertia shows as the acceleration in some row (an aliased coordinate's row counts).
      bool inertial = row.templateRow >= 0 || appears(m_.variables[v.derivative].symbol);
      kindOf[r] = inertial ? Inertial : appears(v.symbol) ? NotInertial : Algebraic;
    }
    keepWhatTemplatesRead(kindOf);
    size_t states = std::count_if(kindOf.begin(), kindOf.end(), [](char k) { return k == Inertial || k == NotInertial; });
    firstKinematic_ = dae_.equations.size();  // appended in place (addEquations reserved room)
    kinematicPairs_.reserve(states);
    std::vector<Expr> rates = rateSymbols(kindOf, states);
    size_t state = 0;
    for (size_t r = 0; r < eom_.rows.size(); ++r) {
      if (kindOf[r] == Skip) continue;
      const flat::Variable& q = m_.variables[eom_.rows[r].coordinate];
      dae_.coordinates.push_back(static_cast<int>(dae_.variables.size()));
      if (kindOf[r] == Algebraic) {
        dae_.variables.push_back(fromFlat(eom_.rows[r].coordinate, VarKind::Algebraic, UnknownRole::Coordinate));
        continue;
      }
      Variable qv = fromFlat(eom_.rows[r].coordinate, VarKind::State, UnknownRole::Coordinate);
      qv.yp = rates[state++];
      // A templated model's kinematic rows are made when addTemplateBlocks has taken its arrays'.
      Expr residual = eom_.templateRows.empty() ? ctx_.sub(qv.yp, m_.variables[q.derivative].symbol) : nullptr;
      dae_.equations.push_back({residual, {flat::OriginKind::Kinematic, q.declRange, eom_.rows[r].coordinate, ""}});
      kinematicPairs_.push_back({static_cast<int>(dae_.variables.size()), static_cast<int>(kinematicPairs_.size())});
      dae_.variables.push_back(std::move(qv));
    }
    int firstVelocity = static_cast<int>(dae_.variables.size());
    for (size_t r = 0; r < eom_.rows.size(); ++r) {
      if (kindOf[r] != Inertial && kindOf[r] != NotInertial) continue;
      const flat::Variable& q = m_.variables[eom_.rows[r].coordinate];
      const flat::Variable& v = m_.variables[q.derivative];
      Variable vv = fromFlat(q.derivative, kindOf[r] == Inertial ? VarKind::State : VarKind::Algebraic, UnknownRole::Velocity);
      vv.declaration.start = v.start ? v.start : ctx_.zero();  // a velocity starts at 0 unless an initial equation says otherwise
      if (kindOf[r] == Inertial) vv.yp = m_.variables[v.derivative].symbol;
      dae_.variables.push_back(std::move(vv));
    }
    int row = static_cast<int>(eom_.rows.size());  // the kinematic rows follow the Euler–Lagrange rows
    for (auto [coordinate, velocity] : kinematicPairs_) dae_.links.push_back({row++, coordinate, firstVelocity + velocity});
  }

  // What a template row reads counts as appearing, as a scalar row's symbols do (appears() sees only
  // rows with a residual): a peeled element whose acceleration only a template reads (der(der(x))
  // [%1+1] at its region's last point) is inertial, one whose velocity only a template reads keeps
  // it among the unknowns. In a model such as the chain, the peeled rows have their own inertia and
  // nothing changes; a pipeline-fuzzer model whose kinetic energy is cubic in the velocities
  // (v[n] only as a factor of the last sum's term) crashed the kernel stage reading der(der(x[n])).
  void keepWhatTemplatesRead(std::vector<char>& kindOf) const {
    if (eom_.templateRows.empty()) return;
    std::vector<size_t> candidates;
    for (size_t r = 0; r < eom_.rows.size(); ++r)
      if (kindOf[r] != Inertial && kindOf[r] != Skip && eom_.rows[r].templateRow < 0) candidates.push_back(r);
    if (candidates.empty()) return;
    const auto& arrays = m_.patterns->arrays;
    std::unordered_map<Expr, std::pair<int, long>> element;  // coordinate → its array and linear index
    for (const mech::TemplateRow& t : eom_.templateRows)
      for (size_t k = 0; k < arrays[t.array].elements.size(); ++k) element.emplace(arrays[t.array].elements[k], std::pair{t.array, static_cast<long>(k)});
    for (size_t r : candidates) {
      auto it = element.find(m_.variables[eom_.rows[r].coordinate].symbol);
      if (it == element.end()) continue;
      auto [array, k] = it->second;
      int velocities = arrays[array].derivative, accelerations = velocities >= 0 ? arrays[velocities].derivative : -1;
      if (templatesRead(accelerations, arrays[array].shape, k)) kindOf[r] = Inertial;
      else if (kindOf[r] == Algebraic && templatesRead(velocities, arrays[array].shape, k)) kindOf[r] = NotInertial;
    }
  }

  // Whether a template row reads element k (linear) of array `a` (of `shape`) at a point of its region.
  bool templatesRead(int a, const std::vector<int>& shape, long k) const {
    if (a < 0) return false;
    std::vector<long> subscript(shape.size());
    for (size_t d = shape.size(); d-- > 0; k /= shape[d]) subscript[d] = k % shape[d] + 1;
    for (const mech::TemplateRow& t : eom_.templateRows)
      for (Expr s : ctx_.freeSymbols(t.residual)) {
        const flat::RelativeElement* rel = m_.relativeElement(s);
        if (!rel || rel->array != a) continue;
        bool reads = true;
        for (size_t d = 0; d < rel->dims.size() && reads; ++d) {
          const auto& dim = rel->dims[d];
          reads = dim.iterator < 0 ? subscript[d] == dim.offset
                                   : subscript[d] >= t.region[dim.iterator].first + dim.offset &&
                                         subscript[d] <= t.region[dim.iterator].second + dim.offset;
        }
        if (reads) return true;
      }
    return false;
  }

  // The symbols of the coordinates' rates `$der(q)`, of the states among them in row order: made
  // in batches (Context::symbols; a large array's names are not all written out at once), with the
  // ids one by one would give.
  // $der(q) of every state coordinate, in row order. Coordinates that are a whole array of symbols
  // in order (Context::symbolArray, as flatten makes a declared array's) get theirs as one such
  // array, $der(x[i]); the others by name, a batch at a time.
  std::vector<Expr> rateSymbols(const std::vector<char>& kindOf, size_t states) {
    constexpr size_t kBatch = 4096;
    std::vector<Expr> coordinates;
    coordinates.reserve(states);
    for (size_t r = 0; r < eom_.rows.size(); ++r)
      if (kindOf[r] == Inertial || kindOf[r] == NotInertial) coordinates.push_back(m_.variables[eom_.rows[r].coordinate].symbol);
    std::vector<Expr> rates;
    rates.reserve(states);
    std::string buffer;
    std::vector<size_t> ends;
    auto make = [&] {
      std::vector<std::string_view> names;
      for (size_t k = 0, begin = 0; k < ends.size(); begin = ends[k++]) names.emplace_back(buffer.data() + begin, ends[k] - begin);
      for (Expr s : ctx_.symbols(names)) rates.push_back(s);
      buffer.clear(), ends.clear();
    };
    for (size_t k = 0; k < coordinates.size();) {
      if (size_t count = ctx_.wholeSymbolArrayAt(std::span(coordinates).subspan(k))) {
        make();
        for (Expr s : ctx_.symbolArrayAround(coordinates[k], "$der(", ")")) rates.push_back(s);
        k += count;
        continue;
      }
      buffer.append("$der(").append(ctx_.symbolName(coordinates[k++])).append(")");
      ends.push_back(buffer.size());
      if (ends.size() == kBatch) make();
    }
    make();
    return rates;
  }

  // The kinematic rows q' - der(q) that no template took (templated models only).
  void addScalarKinematicResiduals() {
    for (size_t k = 0; k < dae_.links.size(); ++k) {
      const DerivativeLink& link = dae_.links[k];
      if (k < kinematicTaken_.size() && kinematicTaken_[k]) continue;
      dae_.equations[link.row].residual = ctx_.sub(dae_.variables[link.variable].yp, dae_.variables[link.derivative].y);
    }
  }

  void addUnknowns() {
    std::vector<Variable> algebraic;
    for (int i : byRole_.unknowns) {
      const flat::Variable& f = m_.variables[i];
      if (f.derivative >= 0) {
        Variable v = fromFlat(i, VarKind::State, UnknownRole::State);
        v.yp = m_.variables[f.derivative].symbol;
        dae_.variables.push_back(std::move(v));
      } else {
        algebraic.push_back(fromFlat(i, VarKind::Algebraic, UnknownRole::Algebraic));
      }
    }
    dae_.variables.insert(dae_.variables.end(), std::make_move_iterator(algebraic.begin()),
                          std::make_move_iterator(algebraic.end()));
    for (const auto& mult : eom_.multipliers) {
      const auto& c = m_.constraints[mult.constraint];
      dae_.variables.push_back({.name = mult.name, .kind = VarKind::Algebraic, .role = UnknownRole::Multiplier,
                                .y = mult.symbol, .declaration = {.declRange = c.origin.range}});
    }
  }

  void addEquations() {
    // At most one kinematic row per Euler–Lagrange row (inserted after them by insertKinematicRows).
    dae_.equations.reserve(2 * eom_.rows.size() + m_.equations.size() + m_.constraints.size());
    for (const auto& row : eom_.rows) {
      const flat::Variable& q = m_.variables[row.coordinate];
      dae_.equations.push_back({substituted(row.residual), {flat::OriginKind::EulerLagrange, q.declRange, row.coordinate, ""}});
      dae_.rowCoordinates.emplace_back(q.name);
    }
    for (const auto& eq : m_.equations)
      dae_.equations.push_back({substituted(eq.residual), eq.origin, substituted(eq.lhs), substituted(eq.rhs)});
    for (size_t k = 0; k < m_.constraints.size(); ++k) {
      const auto& c = m_.constraints[k];
      flat::Origin o = c.origin;
      o.variable = static_cast<int>(k);
      dae_.equations.push_back({substituted(c.residual), o, substituted(c.lhs), substituted(c.rhs)});
    }
    for (const auto& eq : m_.initialEquations)
      dae_.initialEquations.push_back({substituted(eq.residual), eq.origin, substituted(eq.lhs), substituted(eq.rhs)});
  }

  // --- templates (issue 15) ---
  // The Euler–Lagrange template rows, and per templated array one template for its kinematic rows
  // $der(x)[%…] − der(x)[%…] (rows of the same order as its elements').
  void addTemplateBlocks() {
    dae_.patterns = m_.patterns;
    kinematicTaken_.assign(dae_.links.size(), 0);
    flat::ElementPatterns& patterns = *m_.patterns;
    // By flat variable: the row of its Euler–Lagrange row and of its kinematic row (-1: none).
    std::vector<int> rowOfFlat(m_.variables.size(), -1), kinematicRowOfFlat(m_.variables.size(), -1);
    for (int r = 0; r < static_cast<int>(eom_.rows.size()); ++r)
      if (int& at = rowOfFlat[eom_.rows[r].coordinate]; at < 0) at = r;
    for (const auto& link : dae_.links)
      if (int& at = kinematicRowOfFlat[dae_.variables[link.variable].flatVar]; at < 0) at = link.row;
    auto rowOf = [&](const std::vector<int>& rows, Expr element) {
      int row = rows[m_.variableOf(element)];
      if (row < 0) QDOT_UNREACHABLE("a templated array element without its row");
      return row;
    };
    std::vector<int> arrays;
    for (const auto& t : eom_.templateRows) {
      const flat::ArrayVariable& a = patterns.arrays[t.array];
      int first = rowOf(rowOfFlat, a.elements[0]);
      const flat::Variable& q = m_.variables[m_.variableOf(a.elements[0])];
      dae_.templateBlocks.push_back({first, a.shape, t.region, t.residual, flat::OriginKind::EulerLagrange, q.declRange});
      if (std::find(arrays.begin(), arrays.end(), t.array) == arrays.end()) arrays.push_back(t.array);
    }
    // Rows in the elements' order is what lets a template address them (coordinates are declared
    // element by element, so they are).
    auto inOrder = [&](const std::vector<int>& rows, const flat::ArrayVariable& a) {
      int first = rows[m_.variableOf(a.elements[0])];
      for (size_t k = 0; first >= 0 && k < a.elements.size(); ++k)
        if (rows[m_.variableOf(a.elements[k])] != first + static_cast<int>(k)) return false;
      return first >= 0;
    };
    for (int x : arrays)
      if (!inOrder(rowOfFlat, patterns.arrays[x]))
        QDOT_UNREACHABLE("template rows of an array whose Euler-Lagrange rows are not in element order");
    for (int x : arrays) {
      if (!inOrder(kinematicRowOfFlat, patterns.arrays[x])) continue;  // an element without inertia: scalar kinematic rows
      // Read by index: adding the rates' array below may move the others.
      int first = rowOf(kinematicRowOfFlat, patterns.arrays[x].elements[0]);
      flat::ArrayVariable rates{"$der(" + patterns.arrays[x].name + ")", patterns.arrays[x].shape, {}};
      rates.elements.reserve(patterns.arrays[x].elements.size());
      for (Expr e : patterns.arrays[x].elements) {
        int row = rowOf(kinematicRowOfFlat, e);
        rates.elements.push_back(dae_.variables[dae_.links[row - eom_.rows.size()].variable].yp);
        dae_.equations[row].residual = nullptr;
        kinematicTaken_[row - eom_.rows.size()] = 1;
      }
      patterns.arrays.push_back(std::move(rates));
      const flat::ArrayVariable& a = patterns.arrays[x];
      flat::RelativeElement own{static_cast<int>(patterns.arrays.size()) - 1, {}};
      flat::Box all;
      for (size_t d = 0; d < a.shape.size(); ++d) own.dims.push_back({static_cast<int>(d), 0}), all.push_back({1, a.shape[d]});
      flat::RelativeElement velocity = own;
      velocity.array = a.derivative;
      Expr residual = ctx_.sub(patterns.symbol(ctx_, own), patterns.symbol(ctx_, velocity));
      dae_.templateBlocks.push_back({first, a.shape, all, residual, flat::OriginKind::Kinematic,
                                     m_.variables[m_.variableOf(a.elements[0])].declRange});
    }
  }

  // The kinematic rows go after the Euler–Lagrange rows (made by addMechanics, which needs to
  // know which symbols the other equations contain, and appends them): rotated past the other
  // equations, a few in most models, rather than copied from a temporary (a row per coordinate).
  void insertKinematicRows() {
    auto first = dae_.equations.begin();
    std::rotate(first + static_cast<long>(eom_.rows.size()), first + static_cast<long>(firstKinematic_),
                dae_.equations.end());
  }
};

}  // namespace

const char* roleName(UnknownRole r) {
  switch (r) {
    case UnknownRole::Coordinate: return "coordinate";
    case UnknownRole::Velocity: return "velocity";
    case UnknownRole::State: return "state";
    case UnknownRole::Algebraic: return "algebraic";
    case UnknownRole::Multiplier: return "multiplier";
    case UnknownRole::Derivative: return "derivative";
  }
  return "?";
}

std::optional<Dae> buildDae(const flat::FlatModel& model, const mech::EquationsOfMotion& eom, sym::Context& ctx,
                            DiagnosticEngine& diags) {
  return Builder(model, eom, ctx, diags).run();
}

}  // namespace qdot::dae
