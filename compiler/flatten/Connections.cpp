// Connections (spec §7): connect(a, b) puts connectors in connection sets (union–find); each set's
// potentials are one variable and its flows sum to zero (an inside connector's flow counts +, an
// outside one's −; an unconnected inside connector's flow is zero). Potentials equal through
// connections and alias equations (`a.s = s`, `a.s = s0`), and plain unknowns made ± one another or
// given by parameters (`x = -y`, `x = 2*p`), become one variable or one known expression
// (Variable::alias; the classes are the structural alias pass's). A connector's flow is the generalized force on the coordinate its
// potential is in its component (itself, if the component's energies use it): the component's
// Euler–Lagrange expression for that coordinate equals the sum of those flows.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <tuple>

#include "flatten/Flattener.h"
#include "support/Assert.h"

namespace qdot::flat {

using namespace qdot::ast;
using sym::Expr;

namespace {

struct UnionFind {
  std::vector<int> parent;
  int find(int x) {
    while (parent[x] != x) x = parent[x] = parent[parent[x]];
    return x;
  }
  void grow(size_t n) {
    size_t old = parent.size();
    if (n <= old) return;
    parent.resize(n);
    std::iota(parent.begin() + static_cast<long>(old), parent.end(), static_cast<int>(old));
  }
  /// False if they were already one set.
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[std::max(a, b)] = std::min(a, b);  // the earlier one stays the root
    return true;
  }
};

bool isUnknownOrCoordinate(const Variable& v) { return v.role == VarRole::Unknown || v.role == VarRole::Coordinate; }

/// A residual c*x + d*y with |c| = |d| (`x = y`, `x = -y`, `x + y = 0`): (x, y, sign) with x = sign*y.
std::optional<std::tuple<Expr, Expr, int>> symbolPair(Expr r) {
  if (r->kind != sym::Kind::Add || r->value != 0 || r->args.size() != 2 || !r->args[0]->isSymbol() ||
      !r->args[1]->isSymbol() || std::abs(r->coefs()[0]) != std::abs(r->coefs()[1]))
    return std::nullopt;
  return std::tuple{r->args[0], r->args[1], r->coefs()[0] == r->coefs()[1] ? -1 : 1};
}

}  // namespace

std::optional<std::pair<Expr, int>> signedSymbol(Expr e) {
  if (e->isSymbol()) return std::pair{e, 1};
  if (e->kind == sym::Kind::Mul && (e->value == 1 || e->value == -1) && e->args.size() == 1 && e->args[0]->isSymbol() &&
      e->exps()[0]->isOne())
    return std::pair{e->args[0], e->value > 0 ? 1 : -1};
  return std::nullopt;
}

/// Known values (start values, what a class of variables is given) as numbers for the alias pass,
/// which only compares them and negates them: each expression up to its sign gets a key k >= 1,
/// its negative -k, and zero 0.
class ValueKeys {
 public:
  explicit ValueKeys(sym::Context& ctx) : ctx_(ctx) {}
  double key(Expr e) {
    if (e->isZero()) return 0;
    if (auto it = keys_.find(e); it != keys_.end()) return it->second;
    exprs_.push_back(e);
    double k = static_cast<double>(exprs_.size());
    keys_[e] = k;
    if (Expr n = ctx_.neg(e); n != e) keys_[n] = -k;
    return k;
  }
  Expr expr(double key) const {
    if (key == 0) return ctx_.zero();
    Expr e = exprs_[static_cast<size_t>(std::abs(key)) - 1];
    return key > 0 ? e : ctx_.neg(e);
  }

 private:
  sym::Context& ctx_;
  std::unordered_map<Expr, double> keys_;
  std::vector<Expr> exprs_;
};

void Flattener::lowerConnect(const ast::Equation& eq) {
  Instance& a = instanceOf(*eq.lhs);
  Instance& b = instanceOf(*eq.rhs);
  if (!a.cls->isConnector() || !b.cls->isConnector())
    fail(eq.range, DiagCode::E0222, "connect needs two connectors");
  ConnectorEnd ea{&a, a.parent == cur_}, eb{&b, b.parent == cur_};
  if (&a == &b)
    fail(eq.range, DiagCode::E0320, "this connects '" + a.path + "' to itself", "connect it to another component's connector");
  if (a.parent == b.parent && !ea.outside && !eb.outside)
    fail(eq.range, DiagCode::E0320,
         "this connects two connectors of the same component '" + a.parent->path + "' to each other",
         "a component's own connectors are joined through its equations; connect them to other components");
  connections_.push_back({ea, eb, eq.range});
}

// An equation between two variables may let a potential stand for a coordinate (aliasPairs,
// coordinateOfPotential). One that looks like an alias (`x = ±y`, `x + y = 0`, `x = known`) is a
// candidate: whether it is one is decided once every variable is known (eliminateAliases).
void Flattener::recordAlias(size_t index) {
  const Equation& e = out_.equations[index];
  int x = out_.variableOf(e.lhs), y = out_.variableOf(e.rhs);
  if (x >= 0 && y >= 0 && isUnknownOrCoordinate(out_.variables[x]) && isUnknownOrCoordinate(out_.variables[y]))
    cur_->aliasPairs.push_back({x, y});
  if (signedSymbol(e.lhs) || signedSymbol(e.rhs) || symbolPair(e.residual)) aliasCandidates_.push_back(index);
}

void Flattener::connectAll() {
  std::vector<ConnectorEnd> ends;
  std::unordered_map<int, int> idOf;  // instance index * 2 + outside → end
  auto id = [&](ConnectorEnd e) {
    auto [it, inserted] = idOf.try_emplace(e.connector->index * 2 + e.outside, static_cast<int>(ends.size()));
    if (inserted) ends.push_back(e);
    return it->second;
  };
  std::vector<std::pair<int, int>> pairs;
  std::vector<SourceRange> pairRanges;
  for (const Connection& c : connections_) {
    pairs.push_back({id(c.a), id(c.b)});
    pairRanges.push_back(c.range);
  }
  // A component's connector is an inside end of its enclosing model's sets, connected or not; the
  // model's own connectors are inside ends of the level above, where nothing joins them (flow 0).
  for (Instance& inst : instances_)
    if (inst.cls->isConnector() && inst.parent) id({&inst, false});
  UnionFind sets;
  sets.grow(ends.size());
  std::vector<SourceRange> firstRange(ends.size());
  for (size_t i = 0; i < pairs.size(); ++i) {
    int ra = sets.find(pairs[i].first), rb = sets.find(pairs[i].second);
    SourceRange r = firstRange[ra].valid() ? firstRange[ra] : firstRange[rb].valid() ? firstRange[rb] : pairRanges[i];
    sets.unite(ra, rb);
    firstRange[sets.find(ra)] = r;
  }
  std::vector<std::vector<ConnectorEnd>> grouped;
  std::vector<SourceRange> ranges;
  std::unordered_map<int, size_t> groupOf;
  for (size_t i = 0; i < ends.size(); ++i) {
    int root = sets.find(static_cast<int>(i));
    auto [it, inserted] = groupOf.try_emplace(root, grouped.size());
    if (inserted) {
      grouped.emplace_back();
      const Instance& owner = *ends[i].connector->parent;
      ranges.push_back(firstRange[root].valid() ? firstRange[root] : owner.decl ? owner.decl->nameRange : out_.range);
    }
    grouped[it->second].push_back(ends[i]);
  }
  addFlowBalances(grouped, ranges);
  eliminateAliases(grouped, ranges);
  attachFlows();
}

void Flattener::addFlowBalances(const std::vector<std::vector<ConnectorEnd>>& sets, const std::vector<SourceRange>& ranges) {
  for (size_t s = 0; s < sets.size(); ++s) {
    const sema::CheckedClass& cls = *sets[s].front().connector->cls;
    std::string names;
    for (const ConnectorEnd& e : sets[s]) names += (names.empty() ? "" : ", ") + e.connector->path;
    if (sets[s].size() == 1) {
      names += " (unconnected)";
      out_.unconnected.push_back({sets[s].front().connector->path, ranges[s]});
    }
    for (const Declaration* d : cls.declarations) {
      if (!d->isFlow) continue;
      std::vector<Value> flows;
      for (const ConnectorEnd& e : sets[s]) flows.push_back(valueOf(*e.connector, *e.connector->cls->find(d->name), ranges[s]));
      for (size_t j = 0; j < flows.front().size(); ++j) {
        std::vector<Expr> terms;
        for (size_t k = 0; k < flows.size(); ++k)
          terms.push_back(sets[s][k].outside ? ctx_.neg(flows[k].elems[j]) : flows[k].elems[j]);
        // f = 0 or f2 = -f1: an alias, not an unknown with an equation; of a flow not already one
        // (a composite's port is in a set inside it and in one outside).
        if (terms.size() <= 2) {
          int pick = -1;
          for (int k = static_cast<int>(terms.size()) - 1; k >= 0 && pick < 0; --k)
            if (!out_.variables[out_.variableOf(flows[k].elems[j])].alias) pick = k;
          if (pick >= 0) {
            Expr others = terms.size() == 1 ? ctx_.zero() : terms[1 - pick];
            eliminateFlow(out_.variableOf(flows[pick].elems[j]), sets[s][pick].outside ? others : ctx_.neg(others), ranges[s]);
            continue;
          }
        }
        Expr sum = ctx_.add(terms);
        out_.equations.push_back({sum, {OriginKind::Connection, ranges[s], -1, names, 0}, sum, ctx_.zero()});
      }
    }
  }
}

// A flow fixed by its connection alone (zero when unconnected, the other's negative between two
// connectors) is not an unknown; it stays a result column (the reaction of a wall, the force in a
// spring).
void Flattener::eliminateFlow(int var, Expr value, SourceRange where) {
  setAlias(var, value, where);
  out_.outputs.push_back({std::string(out_.variables[var].name), out_.variables[var].symbol, out_.variables[var].declRange});
}

// Which equations are aliases (spec §7 and the plain ones):
//  * two variables, unknowns or coordinates, one of them a connector's potential: `a.s = s`;
//  * a connector's potential given by parameters and time: `a.s = s0`, a prescribed motion;
//  * `x = ±y` (also `x + y = 0`) between two plain unknowns: not a connector's potential, not a
//    state (no der(x)), not already an alias (a flow its connection set gives);
//  * `±x = value` for a plain unknown x and a value of parameters only.
// Anything else stays an equation: a coordinate's or a state's dynamics is never an alias.
std::optional<AliasEquation> Flattener::aliasEquation(const Equation& e) {
  int x = out_.variableOf(e.lhs), y = out_.variableOf(e.rhs);
  if (x >= 0 && y >= 0 && isUnknownOrCoordinate(out_.variables[x]) && isUnknownOrCoordinate(out_.variables[y]) &&
      (connectorPotential_[x] || connectorPotential_[y]))
    return AliasEquation{x, y, 1, nullptr, true};
  int p = x >= 0 && connectorPotential_[x] ? x : y >= 0 && connectorPotential_[y] ? y : -1;
  if (p >= 0) {
    if (out_.variables[p].role != VarRole::Unknown || !overParameters(p == x ? e.rhs : e.lhs, true)) return std::nullopt;
    return AliasEquation{p, -1, 1, p == x ? e.rhs : e.lhs, true};
  }
  if (auto pair = symbolPair(e.residual)) {
    auto [a, b, sign] = *pair;
    int va = out_.variableOf(a), vb = out_.variableOf(b);
    if (plainUnknown(va) && plainUnknown(vb)) return AliasEquation{va, vb, sign, nullptr, false};
  }
  for (bool left : {true, false}) {
    auto s = signedSymbol(left ? e.lhs : e.rhs);
    Expr other = left ? e.rhs : e.lhs;
    if (!s || !plainUnknown(out_.variableOf(s->first)) || !overParameters(other, false)) continue;
    return AliasEquation{out_.variableOf(s->first), -1, 1, s->second > 0 ? other : ctx_.neg(other), false};
  }
  return std::nullopt;
}

bool Flattener::plainUnknown(int var) const {
  if (var < 0) return false;
  const Variable& v = out_.variables[var];
  return v.role == VarRole::Unknown && !connectorPotential_[var] && v.derivative < 0 && !v.alias;
}

bool Flattener::overParameters(Expr e, bool timeToo) {
  for (Expr s : ctx_.freeSymbols(e)) {
    int v = out_.variableOf(s);
    if (v < 0 || (out_.variables[v].role != VarRole::Parameter && !(timeToo && out_.variables[v].role == VarRole::Time)))
      return false;
  }
  return true;
}

// Variables equal (or opposite) through connection sets and alias equations are one variable: a
// declared coordinate if there is one, else a coordinate a component's energy made, else the
// first; or, if the class is given a known value (`a.s = s0`), that expression. The classes are
// the structural alias pass's (structural/AliasElimination.h): variables are its ids, known values
// its constants (ValueKeys). An equation it rejects is reported (E0321) and stays an equation.
void Flattener::eliminateAliases(const std::vector<std::vector<ConnectorEnd>>& sets, const std::vector<SourceRange>& ranges) {
  using structural::AliasRelation;
  if (sets.empty() && aliasCandidates_.empty()) return;  // nothing to join (the cost is per variable)
  structural::AliasProblem problem;
  problem.numVariables = static_cast<int>(out_.variables.size());
  std::vector<char> touched(out_.variables.size(), 0);
  auto relate = [&](AliasRelation r) {
    touched[r.a] = 1;
    if (r.b >= 0) touched[r.b] = 1;
    problem.relations.push_back(r);
  };
  std::unordered_map<int, SourceRange> connectedAt;  // a connected potential → its set's connect
  for (size_t s = 0; s < sets.size(); ++s) {
    const sema::CheckedClass& cls = *sets[s].front().connector->cls;
    for (const Declaration* d : cls.declarations) {
      if (d->isFlow || cls.symbols.at(d->name).kind == sema::SymbolKind::Component) continue;
      std::vector<Value> values;
      for (const ConnectorEnd& e : sets[s]) values.push_back(valueOf(*e.connector, *e.connector->cls->find(d->name), ranges[s]));
      for (size_t k = 1; k < values.size(); ++k)
        for (size_t j = 0; j < values[k].size(); ++j) {
          relate(AliasRelation::equal(out_.variableOf(values[0].elems[j]), out_.variableOf(values[k].elems[j])));
          connectedAt[out_.variableOf(values[k].elems[j])] = ranges[s];
          connectedAt[out_.variableOf(values[0].elems[j])] = ranges[s];
        }
    }
  }
  ValueKeys keys(ctx_);
  size_t firstEquation = problem.relations.size();
  std::vector<std::pair<size_t, AliasEquation>> aliasEquations;  // (equation index, what it says)
  for (size_t index : aliasCandidates_) {
    std::optional<AliasEquation> a = aliasEquation(out_.equations[index]);
    if (!a) continue;
    relate(a->y >= 0 ? AliasRelation::equal(a->x, a->y, a->sign) : AliasRelation::fixedTo(a->x, keys.key(a->value)));
    aliasEquations.push_back({index, *a});
  }
  problem.priority.resize(out_.variables.size());
  problem.start.resize(out_.variables.size());
  for (size_t v = 0; v < out_.variables.size(); ++v) {
    if (!touched[v]) continue;
    const Variable& var = out_.variables[v];
    problem.priority[v] = var.role != VarRole::Coordinate ? 0 : connectorPotential_[v] ? 1 : 2;
    if (var.start) problem.start[v] = structural::StartValue{keys.key(var.start), var.fixed};
  }
  structural::AliasResult result = structural::eliminateAliases(problem);

  std::vector<char> removed(out_.equations.size(), 0);
  for (size_t k = 0; k < aliasEquations.size(); ++k) {
    const auto& [index, a] = aliasEquations[k];
    const structural::RelationOutcome& o = result.outcome[firstEquation + k];
    if (o.kind == structural::RelationOutcome::Joined) {
      removed[index] = 1;
      continue;
    }
    // Only alias equations give a class its value: an earlier relation is one of them.
    SourceRange earlier = o.earlier >= 0 ? out_.equations[aliasEquations[o.earlier - firstEquation].first].origin.range
                                         : SourceRange{};
    reportRejectedAlias(a, out_.equations[index], o, earlier, connectedAt);
  }
  applyAliases(result, keys);
  for (const structural::AliasConflict& c : result.conflicts)
    if (c.kind == structural::AliasConflict::StartValues || c.kind == structural::AliasConflict::FixedStartValues)
      reportUnusedStart(c, result);
  size_t kept = 0;
  for (size_t i = 0; i < out_.equations.size(); ++i)
    if (i >= removed.size() || !removed[i]) out_.equations[kept++] = std::move(out_.equations[i]);
  out_.equations.resize(kept);
}

// Each class of more than one variable, or with a known value, in the order of its first member:
// every member but the representative becomes ±it (or the value); the representative takes the
// class's start value. A component's own variable made another stays a result column.
void Flattener::applyAliases(const structural::AliasResult& r, const ValueKeys& keys) {
  int n = static_cast<int>(r.representative.size());
  std::vector<int> size(n, 0), classOf(n, -1);  // by representative
  for (int v = 0; v < n; ++v) ++size[r.representative[v]];
  std::vector<std::vector<int>> classes;
  for (int v = 0; v < n; ++v) {
    int rep = r.representative[v];
    if (size[rep] == 1 && !r.constant[rep]) continue;
    if (classOf[rep] < 0) {
      classOf[rep] = static_cast<int>(classes.size());
      classes.emplace_back();
    }
    classes[classOf[rep]].push_back(v);
  }
  for (const std::vector<int>& members : classes) {
    int rep = r.representative[members.front()];
    bool known = r.constant[rep].has_value();
    SourceRange where = out_.variables[members.front()].declRange;
    if (!known && r.startFrom[rep] >= 0 && r.startFrom[rep] != rep) {
      out_.variables[rep].start = keys.expr(r.start[rep]->value);
      out_.variables[rep].fixed = out_.variables[rep].fixed || r.start[rep]->fixed;
      out_.variables[rep].fixedGiven = out_.variables[rep].fixedGiven || out_.variables[r.startFrom[rep]].fixedGiven;
    }
    for (int v : members) {
      if (v == rep && !known) continue;
      Expr repSymbol = out_.variables[rep].symbol;
      setAlias(v, known ? keys.expr(*r.constant[v]) : r.sign[v] > 0 ? repSymbol : ctx_.neg(repSymbol), where);
      if (!connectorPotential_[v]) {
        out_.outputs.push_back({std::string(out_.variables[v].name), out_.variables[v].symbol, out_.variables[v].declRange});
        if (int d = out_.variables[v].derivative; d >= 0)
          out_.outputs.push_back({std::string(out_.variables[d].name), out_.variables[d].symbol, out_.variables[d].declRange});
      }
    }
  }
}

// An alias equation that repeats or contradicts what the connections and the earlier alias
// equations say.
void Flattener::reportRejectedAlias(const AliasEquation& a, const Equation& e, const structural::RelationOutcome& o,
                                    SourceRange earlier, const std::unordered_map<int, SourceRange>& connectedAt) {
  using Kind = structural::RelationOutcome::Kind;
  auto quoted = [&](int v) { return std::string("'").append(out_.variables[v].name).append("'"); };
  std::string x = quoted(a.x);
  std::string through = a.ofPotential ? "through connections" : "through other equations";
  if (o.kind == Kind::SignCycle) {
    std::string y = quoted(a.y);
    diags_.error(e.origin.range, DiagCode::E0321,
                 x + " and " + y + " are made both equal and opposite " + through + ", which forces both to 0",
                 "remove this equation or the one it contradicts; write " + std::string(out_.variables[a.x].name) +
                     " = 0 if that is meant");
    return;
  }
  if (a.y >= 0) {
    bool given = o.earlier >= 0;
    auto& diag = diags_.error(e.origin.range, DiagCode::E0321,
                              x + " and " + quoted(a.y) + " are already " +
                                  (given ? "both given" : a.sign > 0 ? "equal" : "opposite") + " " + through,
                              a.ofPotential ? "remove this equation, or one of the connections" : "remove this equation");
    if (given) diag.notes.push_back({earlier, "given here"});
    return;
  }
  // Reported at the connection, where the user joined the two.
  auto at = a.ofPotential ? connectedAt.find(a.x) : connectedAt.end();
  auto& diag = diags_.error(at != connectedAt.end() ? at->second : e.origin.range, DiagCode::E0321,
                            x + " is given twice " +
                                (a.ofPotential ? std::string("(connected to another fixed potential)") : through),
                            a.ofPotential ? "remove one of the two, or the connection between them"
                                          : "remove one of the two equations");
  if (a.ofPotential) diag.notes.push_back({e.origin.range, "given here"});
  diag.notes.push_back({earlier, a.ofPotential ? "and here" : "given here"});
}

// A start value given to a variable that becomes another, when its class starts elsewhere (Mass
// m2(s(start = 0.2)) joined rigidly to m1 with its own).
void Flattener::reportUnusedStart(const structural::AliasConflict& c, const structural::AliasResult& r) {
  int var = c.variables.front();
  const Variable& v = out_.variables[var];
  auto plain = [&](int u) { return out_.variables[u].role == VarRole::Unknown && !connectorPotential_[u]; };
  std::string with;
  bool byEquations = plain(var);  // a plain unknown is joined by alias equations (or to a potential)
  if (c.variables.size() == 1) {
    with = sym::toString(ctx_, v.alias);
  } else {
    int rep = r.representative[var];
    int named = var == rep ? c.variables[1] : rep;
    bool negated = var != rep && r.sign[var] < 0;
    byEquations = byEquations && plain(named);
    with = std::string(negated ? "the negative of " : "") + "'" + std::string(out_.variables[named].name) +
           "', which starts at " + sym::toString(ctx_, out_.variables[named].start);
  }
  const Instance* owner = varOwner_[var];
  diags_.warning(owner && owner->decl ? owner->decl->nameRange : v.declRange, DiagCode::W0302,
                 "the start value " + sym::toString(ctx_, v.start) + " of '" + std::string(v.name) + "' is not used: " +
                     (byEquations ? "through alias equations" : "through connections") + " it is " + with,
                 "give the start value to one of the joined variables only");
}

void Flattener::setAlias(int var, Expr value, SourceRange where) {
  out_.variables[var].alias = value;
  int d = out_.variables[var].derivative;
  if (d < 0) return;
  int rv = out_.variableOf(value);
  bool unknown = rv >= 0 && out_.variables[rv].role != VarRole::Parameter && out_.variables[rv].role != VarRole::Time;
  Expr rate = unknown ? out_.variables[derivativeVariable(rv, where)].symbol : timeDerivative(value, where);
  setAlias(d, rate, where);
}

// Each connector's flow is a generalized force on the coordinate its potential is, in its own
// component: the potential itself when the component's energies use it, else the component's
// coordinate it equals through the component's equations (Mass: a.s = s).
void Flattener::attachFlows() {
  for (Instance& inst : instances_) {
    for (const Declaration* d : inst.cls->declarations) {
      auto child = inst.children.find(d);
      if (child == inst.children.end()) continue;
      for (Instance* c : child->second.elems) {
        if (!c->cls->isConnector()) continue;
        std::vector<const Declaration*> potentials, flows;
        for (const Declaration* f : c->cls->declarations) (f->isFlow ? flows : potentials).push_back(f);
        for (size_t k = 0; k < potentials.size() && k < flows.size(); ++k) {
          const Value& p = valueOf(*c, c->cls->symbols.at(potentials[k]->name), d->nameRange);
          const Value& f = valueOf(*c, c->cls->symbols.at(flows[k]->name), d->nameRange);
          for (size_t j = 0; j < p.size() && j < f.size(); ++j) {
            int potential = out_.variableOf(p.elems[j]);
            int target = coordinateOfPotential(inst, potential);
            if (target >= 0) out_.forces.push_back({target, {f.elems[j], d->nameRange, true}});
            else if (!fixedPotential(potential)) out_.connectionsConserveEnergy = false;
          }
        }
      }
    }
  }
}

// A potential made one with an expression of parameters only (a Fixed flange): its flow does no work.
bool Flattener::fixedPotential(int var) {
  if (var < 0 || !out_.variables[var].alias) return false;
  for (Expr s : ctx_.freeSymbols(out_.variables[var].alias)) {
    int v = out_.variableOf(s);
    if (v < 0 || out_.variables[v].role != VarRole::Parameter) return false;
  }
  return true;
}

// The coordinate of `inst` (its own, or one its energies made of a connector potential) that the
// potential `x` is through the instance's equations `x = y`; -1 if none.
int Flattener::coordinateOfPotential(const Instance& inst, int x) {
  if (x < 0) return -1;
  auto ownCoordinate = [&](int v) {
    return out_.variables[v].role == VarRole::Coordinate && (varOwner_[v] == &inst || varOwner_[v]->parent == &inst);
  };
  if (ownCoordinate(x)) return x;
  std::vector<int> seen{x};
  for (size_t i = 0; i < seen.size(); ++i)
    for (const auto& [a, b] : inst.aliasPairs) {
      int next = a == seen[i] ? b : b == seen[i] ? a : -1;
      if (next < 0 || std::find(seen.begin(), seen.end(), next) != seen.end()) continue;
      if (ownCoordinate(next)) return next;
      seen.push_back(next);
    }
  return -1;
}

}  // namespace qdot::flat
