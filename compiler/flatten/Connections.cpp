// Connections (spec §7): connect(a, b) puts connectors in connection sets (union–find); each set's
// potentials are one variable and its flows sum to zero (an inside connector's flow counts +, an
// outside one's −; an unconnected inside connector's flow is zero). Potentials equal through
// connections and alias equations (`a.s = s`, `a.s = s0`) become one variable or one known
// expression (Variable::alias). A connector's flow is the generalized force on the coordinate its
// potential is in its component (itself, if the component's energies use it): the component's
// Euler–Lagrange expression for that coordinate equals the sum of those flows.
#include <algorithm>
#include <numeric>

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

}  // namespace

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

// An equation between two variables, or between a connector potential and an expression of
// parameters and time, may define an alias; the connections decide (connectAll).
void Flattener::recordAlias(size_t index) {
  const Equation& e = out_.equations[index];
  int x = out_.variableOf(e.lhs), y = out_.variableOf(e.rhs);
  if (x >= 0 && y >= 0 && isUnknownOrCoordinate(out_.variables[x]) && isUnknownOrCoordinate(out_.variables[y])) {
    cur_->aliasPairs.push_back({x, y});
    if (connectorPotential_[x] || connectorPotential_[y]) aliasCandidates_.push_back(index);
    return;
  }
  int p = x >= 0 && connectorPotential_[x] ? x : y >= 0 && connectorPotential_[y] ? y : -1;
  if (p < 0 || out_.variables[p].role != VarRole::Unknown) return;
  Expr other = p == x ? e.rhs : e.lhs;
  for (Expr s : ctx_.freeSymbols(other)) {
    int v = out_.variableOf(s);
    if (v < 0 || (out_.variables[v].role != VarRole::Parameter && out_.variables[v].role != VarRole::Time)) return;
  }
  aliasCandidates_.push_back(index);
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

// Potentials equal through a connection set or an alias equation are one variable: a declared
// coordinate if there is one, else a coordinate a component's energy made, else the first; or, if
// one of them is given by parameters and time (`a.s = s0`), that expression.
void Flattener::eliminateAliases(const std::vector<std::vector<ConnectorEnd>>& sets, const std::vector<SourceRange>& ranges) {
  UnionFind uf;
  uf.grow(out_.variables.size());
  std::unordered_map<int, SourceRange> connectedAt;  // a connected potential → its set's connect
  for (size_t s = 0; s < sets.size(); ++s) {
    const sema::CheckedClass& cls = *sets[s].front().connector->cls;
    for (const Declaration* d : cls.declarations) {
      if (d->isFlow || cls.symbols.at(d->name).kind == sema::SymbolKind::Component) continue;
      std::vector<Value> values;
      for (const ConnectorEnd& e : sets[s]) values.push_back(valueOf(*e.connector, *e.connector->cls->find(d->name), ranges[s]));
      for (size_t k = 1; k < values.size(); ++k)
        for (size_t j = 0; j < values[k].size(); ++j) {
          uf.unite(out_.variableOf(values[0].elems[j]), out_.variableOf(values[k].elems[j]));
          connectedAt[out_.variableOf(values[k].elems[j])] = ranges[s];
          connectedAt[out_.variableOf(values[0].elems[j])] = ranges[s];
        }
    }
  }
  std::unordered_map<int, std::pair<Expr, SourceRange>> bound;  // set root → its known value
  std::vector<char> removed(out_.equations.size(), 0);
  for (size_t index : aliasCandidates_) {
    const Equation& e = out_.equations[index];
    int x = out_.variableOf(e.lhs), y = out_.variableOf(e.rhs);
    bool twoVariables = x >= 0 && y >= 0 && isUnknownOrCoordinate(out_.variables[x]) && isUnknownOrCoordinate(out_.variables[y]);
    int p = twoVariables ? x : (x >= 0 && connectorPotential_[x]) ? x : y;
    int root = uf.find(p);
    auto known = bound.find(root);
    if (twoVariables) {
      int other = uf.find(y);
      auto otherKnown = bound.find(other);
      if (root == other || (known != bound.end() && otherKnown != bound.end())) {
        auto& diag = diags_.error(e.origin.range, DiagCode::E0321,
                                  "'" + std::string(out_.variables[x].name) + "' and '" + std::string(out_.variables[y].name) +
                                      "' are already " + (root == other ? "equal" : "both given") + " through connections",
                                  "remove this equation, or one of the connections");
        if (known != bound.end()) diag.notes.push_back({known->second.second, "given here"});
        continue;
      }
      std::pair<Expr, SourceRange> value;
      bool hasValue = known != bound.end() || otherKnown != bound.end();
      if (hasValue) value = known != bound.end() ? known->second : otherKnown->second;
      bound.erase(root), bound.erase(other);
      uf.unite(root, other);
      if (hasValue) bound[uf.find(root)] = value;
    } else {
      if (known != bound.end()) {  // reported at the connection, where the user joined the two
        auto at = connectedAt.find(p);
        auto& diag = diags_.error(at != connectedAt.end() ? at->second : e.origin.range, DiagCode::E0321,
                                  "'" + std::string(out_.variables[p].name) + "' is given twice (connected to another fixed potential)",
                                  "remove one of the two, or the connection between them");
        diag.notes.push_back({e.origin.range, "given here"});
        diag.notes.push_back({known->second.second, "and here"});
        continue;
      }
      bound[root] = {p == x ? e.rhs : e.lhs, e.origin.range};
    }
    removed[index] = 1;
  }
  // Representatives: members in creation order.
  std::unordered_map<int, std::vector<int>> members;
  size_t count = uf.parent.size();
  for (size_t v = 0; v < count; ++v)
    if (uf.find(static_cast<int>(v)) != static_cast<int>(v) || bound.count(static_cast<int>(v)))
      members[uf.find(static_cast<int>(v))];
  for (size_t v = 0; v < count; ++v)
    if (auto it = members.find(uf.find(static_cast<int>(v))); it != members.end()) it->second.push_back(static_cast<int>(v));
  std::vector<int> roots;
  for (const auto& [r, list] : members) roots.push_back(r);
  std::sort(roots.begin(), roots.end());
  for (int r : roots) {
    const std::vector<int>& list = members[r];
    SourceRange where = out_.variables[list.front()].declRange;
    auto known = bound.find(r);
    auto declared = [&](int v) { return out_.variables[v].role == VarRole::Coordinate && !connectorPotential_[v]; };
    auto coordinate = [&](int v) { return out_.variables[v].role == VarRole::Coordinate; };
    int rep = -1;
    if (known == bound.end()) {
      auto it = std::find_if(list.begin(), list.end(), declared);
      if (it == list.end()) it = std::find_if(list.begin(), list.end(), coordinate);
      rep = it == list.end() ? list.front() : *it;
    }
    for (int v : list) {
      if (v == rep) continue;
      Expr value = known != bound.end() ? known->second.first : out_.variables[rep].symbol;
      keepStart(v, rep, value);
      setAlias(v, value, where);
      // A component's own variable made equal to another stays a result column.
      if (!connectorPotential_[v]) {
        out_.outputs.push_back({std::string(out_.variables[v].name), out_.variables[v].symbol, out_.variables[v].declRange});
        if (int d = out_.variables[v].derivative; d >= 0)
          out_.outputs.push_back({std::string(out_.variables[d].name), out_.variables[d].symbol, out_.variables[d].declRange});
      }
    }
  }
  size_t kept = 0;
  for (size_t i = 0; i < out_.equations.size(); ++i)
    if (i >= removed.size() || !removed[i]) out_.equations[kept++] = std::move(out_.equations[i]);
  out_.equations.resize(kept);
}

// A start value given to a variable that becomes another: moved to the representative if that has
// none (Mass m2(s(start = 0.2)) joined rigidly to m1), else a warning when the two differ.
void Flattener::keepStart(int var, int rep, Expr value) {
  Variable& v = out_.variables[var];
  if (!v.start) return;
  Expr other = rep >= 0 ? out_.variables[rep].start : value;
  if (rep >= 0 && !other) {
    out_.variables[rep].start = v.start;
    out_.variables[rep].fixed = v.fixed || out_.variables[rep].fixed;
    out_.variables[rep].fixedGiven = v.fixedGiven || out_.variables[rep].fixedGiven;
    return;
  }
  if (other == v.start) return;
  std::string with = rep >= 0 ? "'" + std::string(out_.variables[rep].name) + "', which starts at " + sym::toString(ctx_, other)
                              : sym::toString(ctx_, value);
  const Instance* owner = varOwner_[var];
  diags_.warning(owner && owner->decl ? owner->decl->nameRange : v.declRange, DiagCode::W0302,
                 "the start value " + sym::toString(ctx_, v.start) + " of '" + std::string(v.name) +
                     "' is not used: through connections it is " + with,
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
