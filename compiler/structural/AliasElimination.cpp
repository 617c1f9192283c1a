// Weighted union–find whose edges carry a sign: parent[v] = p with v = sign[v] * p. A root holds
// its class's size, best member (by priority) and constant (the root's value) with the relation
// that gave it.
#include "structural/AliasElimination.h"

#include <stdexcept>
#include <string>

namespace qdot::structural {
namespace {

class SignedUnionFind {
 public:
  explicit SignedUnionFind(const AliasProblem& p)
      : priority_(p.priority),
        parent_(p.numVariables),
        sign_(p.numVariables, 1),
        size_(p.numVariables, 1),
        best_(p.numVariables),
        constant_(p.numVariables),
        constantFrom_(p.numVariables, -1) {
    for (int v = 0; v < p.numVariables; ++v) parent_[v] = best_[v] = v;
  }

  /// The root of v's class and the sign s with v = s * root; compresses the path.
  std::pair<int, int> find(int v) {
    path_.clear();
    int root = v;
    while (parent_[root] != root) {
      path_.push_back(root);
      root = parent_[root];
    }
    // From the root's side down: each node's sign to the root is its sign to its parent times the
    // parent's (already resolved) sign to the root.
    for (size_t i = path_.size(); i-- > 0;) {
      int node = path_[i];
      if (parent_[node] != root) sign_[node] = static_cast<int8_t>(sign_[node] * sign_[parent_[node]]);
      parent_[node] = root;
    }
    return {root, v == root ? 1 : sign_[v]};
  }

  RelationOutcome relate(const AliasRelation& r, int index) {
    auto [ra, sa] = find(r.a);
    if (r.b == AliasRelation::kNoVariable) return fix(ra, sa * r.constant, index);
    auto [rb, sb] = find(r.b);
    int k = sa * r.sign * sb;  // ra = k * rb
    if (ra == rb) return {k == 1 ? RelationOutcome::Implied : RelationOutcome::SignCycle, -1};
    if (constant_[ra] && constant_[rb]) {
      bool same = *constant_[ra] == k * *constant_[rb];
      return {same ? RelationOutcome::Implied : RelationOutcome::TwoConstants, constantFrom_[ra]};
    }
    if (size_[ra] > size_[rb]) std::swap(ra, rb);  // ra = k * rb holds both ways round
    parent_[ra] = rb;
    sign_[ra] = static_cast<int8_t>(k);
    size_[rb] += size_[ra];
    if (better(best_[ra], best_[rb])) best_[rb] = best_[ra];
    if (constant_[ra]) {
      constant_[rb] = normalized(k * *constant_[ra]);
      constantFrom_[rb] = constantFrom_[ra];
    }
    return {RelationOutcome::Joined, -1};
  }

  int best(int root) const { return best_[root]; }
  const std::optional<double>& constant(int root) const { return constant_[root]; }

  static double normalized(double c) { return c == 0 ? 0.0 : c; }  // no -0 from a sign

 private:
  const std::vector<int>& priority_;
  std::vector<int> parent_;
  std::vector<int8_t> sign_;
  std::vector<int> size_;
  std::vector<int> best_;
  std::vector<std::optional<double>> constant_;
  std::vector<int> constantFrom_;
  std::vector<int> path_;

  int priorityOf(int v) const { return priority_.empty() ? 0 : priority_[v]; }
  bool better(int x, int y) const {
    return priorityOf(x) != priorityOf(y) ? priorityOf(x) > priorityOf(y) : x < y;
  }

  RelationOutcome fix(int root, double value, int index) {
    if (constant_[root])
      return {*constant_[root] == value ? RelationOutcome::Implied : RelationOutcome::TwoConstants, constantFrom_[root]};
    constant_[root] = normalized(value);
    constantFrom_[root] = index;
    return {RelationOutcome::Joined, -1};
  }
};

void validate(const AliasProblem& p) {
  auto bad = [](const std::string& what) { throw std::invalid_argument("eliminateAliases: " + what); };
  if (p.numVariables < 0) bad("negative number of variables");
  if (!p.priority.empty() && p.priority.size() != static_cast<size_t>(p.numVariables)) bad("priority list size");
  if (!p.start.empty() && p.start.size() != static_cast<size_t>(p.numVariables)) bad("start list size");
  for (const AliasRelation& r : p.relations) {
    if (r.a < 0 || r.a >= p.numVariables) bad("variable id " + std::to_string(r.a) + " out of range");
    if (r.b == AliasRelation::kNoVariable) continue;
    if (r.b < 0 || r.b >= p.numVariables) bad("variable id " + std::to_string(r.b) + " out of range");
    if (r.sign != 1 && r.sign != -1) bad("sign " + std::to_string(r.sign));
  }
}

/// The members of each class, classes in the order of their lowest member, members ascending
/// (a counting sort by root): the order start values are chosen and reported in.
std::vector<std::vector<int>> classesInOrder(const std::vector<int>& rootOf) {
  std::vector<int> slot(rootOf.size(), -1);
  std::vector<std::vector<int>> classes;
  for (size_t v = 0; v < rootOf.size(); ++v) {
    int& s = slot[rootOf[v]];
    if (s < 0) {
      s = static_cast<int>(classes.size());
      classes.emplace_back();
    }
    classes[s].push_back(static_cast<int>(v));
  }
  return classes;
}

std::optional<StartValue> converted(std::optional<StartValue> s, int sign) {
  if (s) s->value = SignedUnionFind::normalized(sign * s->value);
  return s;
}

// A fixed start first, then the representative's, then the lowest member's. Members whose start
// (as a value of the representative) differs from the chosen one are reported.
void chooseStart(const std::vector<int>& members, const AliasProblem& p, AliasResult& out) {
  auto startOf = [&](int v) {  // as a start of the representative
    return p.start.empty() ? std::optional<StartValue>() : converted(p.start[v], out.sign[v]);
  };
  int rep = out.representative[members.front()];
  if (out.constant[rep]) {
    for (int v : members)
      if (!p.start.empty() && p.start[v] && p.start[v]->value != *out.constant[v])
        out.conflicts.push_back({AliasConflict::StartValues, {v}, -1});
    return;
  }
  int from = -1;
  auto consider = [&](int v) {
    if (startOf(v) && (from < 0 || (startOf(v)->fixed && !startOf(from)->fixed))) from = v;
  };
  consider(rep);
  for (int v : members) consider(v);
  if (from < 0) return;
  StartValue chosen = *startOf(from);
  for (int v : members) {
    out.start[v] = converted(chosen, out.sign[v]);
    out.startFrom[v] = from;
    std::optional<StartValue> own = startOf(v);
    if (v == from || !own || own->value == chosen.value) continue;
    bool bothFixed = own->fixed && chosen.fixed;
    out.conflicts.push_back({bothFixed ? AliasConflict::FixedStartValues : AliasConflict::StartValues, {v, from}, -1});
  }
}

}  // namespace

AliasResult eliminateAliases(const AliasProblem& p) {
  validate(p);
  SignedUnionFind sets(p);
  AliasResult out;
  out.outcome.reserve(p.relations.size());
  for (size_t i = 0; i < p.relations.size(); ++i) {
    const AliasRelation& r = p.relations[i];
    RelationOutcome o = sets.relate(r, static_cast<int>(i));
    out.outcome.push_back(o);
    if (o.kind == RelationOutcome::SignCycle)
      out.conflicts.push_back({AliasConflict::SignCycle, {r.a, r.b}, static_cast<int>(i)});
    else if (o.kind == RelationOutcome::TwoConstants)
      out.conflicts.push_back({AliasConflict::TwoConstants,
                               r.b == AliasRelation::kNoVariable ? std::vector<int>{r.a} : std::vector<int>{r.a, r.b},
                               static_cast<int>(i)});
  }
  size_t n = static_cast<size_t>(p.numVariables);
  std::vector<int> rootOf(n);
  out.representative.resize(n);
  out.sign.resize(n);
  out.constant.resize(n);
  out.start.resize(n);
  out.startFrom.assign(n, -1);
  for (int v = 0; v < p.numVariables; ++v) {
    auto [root, s] = sets.find(v);
    int rep = sets.best(root);
    auto [repRoot, repSign] = sets.find(rep);
    rootOf[v] = root;
    out.representative[v] = rep;
    out.sign[v] = static_cast<int8_t>(s * repSign);  // v = s root, rep = repSign root
    if (sets.constant(root)) out.constant[v] = SignedUnionFind::normalized(s * *sets.constant(root));
  }
  for (const std::vector<int>& members : classesInOrder(rootOf)) chooseStart(members, p, out);
  return out;
}

}  // namespace qdot::structural
