// Alias elimination on plain variable ids, without the front end: each rule and conflict by hand,
// random problems against a BFS oracle over the accepted relations, and a 10^6-variable chain
// (correctness asserted, time printed).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <random>
#include <stdexcept>
#include <vector>

#include "structural/AliasElimination.h"

namespace qdot::structural {
namespace {

using Kind = RelationOutcome::Kind;

AliasProblem problem(int n, std::vector<AliasRelation> relations) {
  AliasProblem p;
  p.numVariables = n;
  p.relations = std::move(relations);
  return p;
}

TEST(AliasElimination, ChainOfEqualAndOppositeResolvesToTheLowestId) {
  // x1 = -x0, x2 = x1, x3 = -x2  =>  x1 = -x0, x2 = -x0, x3 = x0
  AliasResult r = eliminateAliases(problem(5, {AliasRelation::equal(1, 0, -1), AliasRelation::equal(2, 1),
                                               AliasRelation::equal(3, 2, -1)}));
  EXPECT_EQ(r.representative, (std::vector<int>{0, 0, 0, 0, 4}));
  EXPECT_EQ(r.sign, (std::vector<int8_t>{1, -1, -1, 1, 1}));
  for (const auto& c : r.constant) EXPECT_FALSE(c);
  for (const auto& o : r.outcome) EXPECT_EQ(o.kind, Kind::Joined);
  EXPECT_TRUE(r.conflicts.empty());
}

TEST(AliasElimination, HighestPriorityIsTheRepresentative) {
  AliasProblem p = problem(4, {AliasRelation::equal(0, 1), AliasRelation::equal(1, 2, -1), AliasRelation::equal(3, 0)});
  p.priority = {0, 1, 2, 2};  // 2 and 3 tie: the lower id wins
  AliasResult r = eliminateAliases(p);
  EXPECT_EQ(r.representative, (std::vector<int>{2, 2, 2, 2}));
  EXPECT_EQ(r.sign, (std::vector<int8_t>{-1, -1, 1, -1}));  // x0 = x1 = -x2, x3 = x0
}

TEST(AliasElimination, ConstantReachesTheWholeClassWithItsSign) {
  AliasResult r = eliminateAliases(
      problem(4, {AliasRelation::equal(0, 1, -1), AliasRelation::fixedTo(1, 2.5), AliasRelation::equal(2, 0)}));
  ASSERT_TRUE(r.constant[0] && r.constant[1] && r.constant[2]);
  EXPECT_EQ(*r.constant[0], -2.5);
  EXPECT_EQ(*r.constant[1], 2.5);
  EXPECT_EQ(*r.constant[2], -2.5);
  EXPECT_FALSE(r.constant[3]);
  EXPECT_TRUE(r.conflicts.empty());
}

TEST(AliasElimination, ZeroThroughANegativeSignIsPlusZero) {
  AliasResult r = eliminateAliases(problem(2, {AliasRelation::fixedTo(0, 0.0), AliasRelation::equal(1, 0, -1)}));
  ASSERT_TRUE(r.constant[1]);
  EXPECT_FALSE(std::signbit(*r.constant[1]));
}

TEST(AliasElimination, EqualAndOppositeIsASignCycleNotApplied) {
  AliasResult r = eliminateAliases(
      problem(3, {AliasRelation::equal(0, 1), AliasRelation::equal(1, 2), AliasRelation::equal(2, 0, -1)}));
  EXPECT_EQ(r.outcome[2].kind, Kind::SignCycle);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].kind, AliasConflict::SignCycle);
  EXPECT_EQ(r.conflicts[0].variables, (std::vector<int>{2, 0}));
  EXPECT_EQ(r.conflicts[0].relation, 2);
  EXPECT_EQ(r.sign, (std::vector<int8_t>{1, 1, 1}));  // the first two relations stand
}

TEST(AliasElimination, RepeatedRelationIsImplied) {
  AliasResult r = eliminateAliases(
      problem(3, {AliasRelation::equal(0, 1, -1), AliasRelation::equal(1, 2), AliasRelation::equal(2, 0, -1)}));
  EXPECT_EQ(r.outcome[2].kind, Kind::Implied);
  EXPECT_EQ(r.outcome[2].earlier, -1);
  EXPECT_TRUE(r.conflicts.empty());
}

TEST(AliasElimination, TwoDifferentConstantsConflictAndNameTheEarlierOne) {
  // x0 = 1, x1 = 1 (x0 and x1 both given), x2 = -x0, x2 = -1 (implied), x2 = 3 (a second value).
  AliasResult r = eliminateAliases(problem(3, {AliasRelation::fixedTo(0, 1), AliasRelation::fixedTo(1, 2),
                                               AliasRelation::equal(0, 1), AliasRelation::equal(2, 0, -1),
                                               AliasRelation::fixedTo(2, -1), AliasRelation::fixedTo(2, 3)}));
  EXPECT_EQ(r.outcome[2].kind, Kind::TwoConstants);
  EXPECT_EQ(r.outcome[2].earlier, 0);
  EXPECT_EQ(r.outcome[3].kind, Kind::Joined);
  EXPECT_EQ(r.outcome[4].kind, Kind::Implied);
  EXPECT_EQ(r.outcome[4].earlier, 0);
  EXPECT_EQ(r.outcome[5].kind, Kind::TwoConstants);
  ASSERT_EQ(r.conflicts.size(), 2u);
  EXPECT_EQ(r.conflicts[0].variables, (std::vector<int>{0, 1}));
  EXPECT_EQ(r.conflicts[1].variables, (std::vector<int>{2}));
  EXPECT_EQ(r.conflicts[1].relation, 5);
  EXPECT_EQ(*r.constant[2], -1);
  EXPECT_EQ(*r.constant[1], 2);
}

TEST(AliasElimination, JoiningTwoClassesWithTheSameConstantIsImplied) {
  AliasResult r = eliminateAliases(
      problem(2, {AliasRelation::fixedTo(0, 4), AliasRelation::fixedTo(1, -4), AliasRelation::equal(1, 0, -1)}));
  EXPECT_EQ(r.outcome[2].kind, Kind::Implied);
  EXPECT_EQ(r.outcome[2].earlier, 1);  // a's class (x1) got its value from relation 1
}

TEST(AliasElimination, MemberStartMovesToTheRepresentativeThroughTheSign) {
  AliasProblem p = problem(3, {AliasRelation::equal(1, 0, -1), AliasRelation::equal(2, 0)});
  p.start = {std::nullopt, StartValue{0.3, false}, std::nullopt};
  AliasResult r = eliminateAliases(p);
  ASSERT_TRUE(r.start[0]);
  EXPECT_EQ(r.start[0]->value, -0.3);
  EXPECT_EQ(r.start[1]->value, 0.3);
  EXPECT_EQ(r.start[2]->value, -0.3);
  EXPECT_EQ(r.startFrom, (std::vector<int>{1, 1, 1}));
  EXPECT_TRUE(r.conflicts.empty());
}

TEST(AliasElimination, RepresentativesOwnStartWinsAndTheOtherIsReported) {
  AliasProblem p = problem(3, {AliasRelation::equal(0, 1), AliasRelation::equal(0, 2, -1)});
  p.priority = {0, 1, 0};
  p.start = {StartValue{0.2, false}, StartValue{0.1, false}, StartValue{-0.1, false}};  // x2 agrees
  AliasResult r = eliminateAliases(p);
  EXPECT_EQ(r.startFrom[0], 1);
  EXPECT_EQ(r.start[0]->value, 0.1);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].kind, AliasConflict::StartValues);
  EXPECT_EQ(r.conflicts[0].variables, (std::vector<int>{0, 1}));
}

TEST(AliasElimination, FixedStartWinsAndTwoFixedThatDisagreeAreReported) {
  AliasProblem p = problem(4, {AliasRelation::equal(0, 1), AliasRelation::equal(0, 2), AliasRelation::equal(0, 3)});
  p.start = {StartValue{1, false}, std::nullopt, StartValue{2, true}, StartValue{3, true}};
  AliasResult r = eliminateAliases(p);
  EXPECT_EQ(r.startFrom[0], 2);
  EXPECT_EQ(r.start[1], (StartValue{2, true}));
  ASSERT_EQ(r.conflicts.size(), 2u);
  EXPECT_EQ(r.conflicts[0].kind, AliasConflict::StartValues);  // x0's own 1, not fixed
  EXPECT_EQ(r.conflicts[0].variables, (std::vector<int>{0, 2}));
  EXPECT_EQ(r.conflicts[1].kind, AliasConflict::FixedStartValues);
  EXPECT_EQ(r.conflicts[1].variables, (std::vector<int>{3, 2}));
}

TEST(AliasElimination, StartThatDiffersFromTheConstantIsReported) {
  AliasProblem p = problem(3, {AliasRelation::fixedTo(0, 1), AliasRelation::equal(1, 0, -1), AliasRelation::equal(2, 0)});
  p.start = {std::nullopt, StartValue{-1, false}, StartValue{5, true}};
  AliasResult r = eliminateAliases(p);
  EXPECT_FALSE(r.start[0]);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].kind, AliasConflict::StartValues);
  EXPECT_EQ(r.conflicts[0].variables, (std::vector<int>{2}));
}

TEST(AliasElimination, BadInputThrows) {
  EXPECT_THROW(eliminateAliases(problem(2, {AliasRelation::equal(0, 2)})), std::invalid_argument);
  EXPECT_THROW(eliminateAliases(problem(2, {AliasRelation::equal(0, 1, 2)})), std::invalid_argument);
  AliasProblem p = problem(2, {});
  p.priority = {1};
  EXPECT_THROW(eliminateAliases(p), std::invalid_argument);
}

// ---------------------------------------------------------------------------------- the oracle

// Relations applied one at a time; each is checked by a BFS over the relations accepted so far
// (signs along the path, the one constant relation a component can hold).
struct Oracle {
  const AliasProblem& p;
  std::vector<AliasRelation> accepted;
  std::vector<int> acceptedIndex;

  // u -> s with u = s * from, for every u joined to `from`.
  std::map<int, int> component(int from) const {
    std::map<int, int> sign{{from, 1}};
    std::vector<int> queue{from};
    for (size_t i = 0; i < queue.size(); ++i)
      for (const AliasRelation& r : accepted) {
        if (r.b < 0) continue;
        int u = queue[i];
        int other = r.a == u ? r.b : r.b == u ? r.a : -1;
        if (other < 0 || sign.count(other)) continue;
        sign[other] = r.sign * sign[u];
        queue.push_back(other);
      }
    return sign;
  }
  // from's value and the relation that gave it, if its component has one.
  std::optional<std::pair<double, int>> constantOf(int from) const {
    for (auto [u, s] : component(from))
      for (size_t k = 0; k < accepted.size(); ++k)
        if (accepted[k].b < 0 && accepted[k].a == u) return std::pair{s * accepted[k].constant, acceptedIndex[k]};
    return std::nullopt;
  }
  RelationOutcome apply(const AliasRelation& r, int index) {
    auto ca = constantOf(r.a);
    RelationOutcome o{Kind::Joined, -1};
    if (r.b < 0) {
      if (ca) o = {ca->first == r.constant ? Kind::Implied : Kind::TwoConstants, ca->second};
    } else if (auto comp = component(r.a); comp.count(r.b)) {
      o = {comp[r.b] == r.sign ? Kind::Implied : Kind::SignCycle, -1};
    } else if (auto cb = constantOf(r.b); ca && cb) {
      o = {ca->first == r.sign * cb->first ? Kind::Implied : Kind::TwoConstants, ca->second};
    }
    if (o.kind == Kind::Joined) {
      accepted.push_back(r);
      acceptedIndex.push_back(index);
    }
    return o;
  }
};

// Per class: a fixed start if any member has one, else the representative's own, else the lowest
// member's; every member's start is the chosen one through its sign; each member whose own start
// differs is reported once.
void expectStartsChosenByTheRule(const AliasProblem& p, const AliasResult& r) {
  std::map<int, std::vector<int>> classes;
  for (int v = 0; v < p.numVariables; ++v) classes[r.representative[v]].push_back(v);
  size_t reported = 0;
  for (const auto& [rep, members] : classes) {
    auto asRep = [&](int v) { return p.start[v] ? std::optional<double>(r.sign[v] * p.start[v]->value) : std::nullopt; };
    std::vector<int> given;
    for (int v : members)
      if (p.start[v]) given.push_back(v);
    if (r.constant[rep]) {
      for (int v : given) reported += p.start[v]->value != *r.constant[v];
      continue;
    }
    if (given.empty()) {
      ASSERT_EQ(r.startFrom[rep], -1);
      continue;
    }
    int from = r.startFrom[rep];
    ASSERT_TRUE(std::find(given.begin(), given.end(), from) != given.end());
    bool anyFixed = std::any_of(given.begin(), given.end(), [&](int v) { return p.start[v]->fixed; });
    ASSERT_EQ(p.start[from]->fixed, anyFixed);
    int expected = -1;
    for (int v : given)
      if (p.start[v]->fixed == anyFixed && (expected < 0 || v == rep)) expected = v;
    if (p.start[rep] && p.start[rep]->fixed == anyFixed) expected = rep;
    ASSERT_EQ(from, expected);
    for (int v : members) {
      ASSERT_EQ(r.startFrom[v], from);
      ASSERT_EQ(r.start[v]->value, r.sign[v] * *asRep(from) + 0.0);
      if (p.start[v] && *asRep(v) != *asRep(from)) ++reported;
    }
  }
  size_t conflicts = std::count_if(r.conflicts.begin(), r.conflicts.end(), [](const AliasConflict& c) {
    return c.kind == AliasConflict::StartValues || c.kind == AliasConflict::FixedStartValues;
  });
  ASSERT_EQ(conflicts, reported);
}

TEST(AliasElimination, RandomProblemsAgreeWithTheBfsOracle) {
  std::mt19937 rng(20261124);
  for (int round = 0; round < 400; ++round) {
    int n = 1 + static_cast<int>(rng() % 20);
    int m = static_cast<int>(rng() % (2 * n + 1));
    AliasProblem p = problem(n, {});
    for (int i = 0; i < m; ++i) {
      int a = static_cast<int>(rng() % n);
      if (rng() % 5 == 0) p.relations.push_back(AliasRelation::fixedTo(a, static_cast<double>(rng() % 5) - 2));
      else p.relations.push_back(AliasRelation::equal(a, static_cast<int>(rng() % n), rng() % 2 ? 1 : -1));
    }
    for (int v = 0; v < n; ++v) p.priority.push_back(static_cast<int>(rng() % 3));
    for (int v = 0; v < n; ++v)
      p.start.push_back(rng() % 3 ? std::nullopt
                                  : std::optional<StartValue>(StartValue{static_cast<double>(rng() % 3) - 1, rng() % 2 == 0}));
    AliasResult r = eliminateAliases(p);
    Oracle oracle{p, {}, {}};
    for (int i = 0; i < m; ++i) {
      RelationOutcome o = oracle.apply(p.relations[i], i);
      ASSERT_EQ(r.outcome[i].kind, o.kind) << "round " << round << " relation " << i;
      ASSERT_EQ(r.outcome[i].earlier, o.earlier) << "round " << round << " relation " << i;
    }
    for (int v = 0; v < n; ++v) {
      auto comp = oracle.component(v);
      int best = v;
      for (auto [u, s] : comp)
        if (p.priority[u] > p.priority[best] || (p.priority[u] == p.priority[best] && u < best)) best = u;
      ASSERT_EQ(r.representative[v], best) << "round " << round << " variable " << v;
      ASSERT_EQ(r.sign[v], comp[best]) << "round " << round << " variable " << v;  // best = s v, so v = s best
      auto c = oracle.constantOf(v);
      ASSERT_EQ(r.constant[v].has_value(), c.has_value());
      if (c) {
        ASSERT_EQ(*r.constant[v], c->first);
      }
    }
    expectStartsChosenByTheRule(p, r);
  }
}

// ---------------------------------------------------------------------------------------- scale

TEST(AliasElimination, MillionVariableChainIsNearLinear) {
  constexpr int kN = 1'000'000;
  AliasProblem p = problem(kN, {});
  p.relations.reserve(kN);
  for (int v = kN - 1; v > 0; --v) p.relations.push_back(AliasRelation::equal(v, v - 1, -1));  // x_v = -x_{v-1}
  p.relations.push_back(AliasRelation::fixedTo(kN - 1, 2.0));
  auto start = std::chrono::steady_clock::now();
  AliasResult r = eliminateAliases(p);
  auto ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::printf("[   TIME   ] %-48s %8.1f ms\n", "alias chain of 10^6 variables", ms);
  double lastSign = (kN - 1) % 2 ? -1 : 1;  // x_{N-1} = (-1)^(N-1) x_0 = 2
  for (int v = 0; v < kN; ++v) {
    ASSERT_EQ(r.representative[v], 0);
    ASSERT_EQ(r.sign[v], v % 2 ? -1 : 1);
    ASSERT_EQ(*r.constant[v], (v % 2 ? -1 : 1) * lastSign * 2.0);
  }
  EXPECT_TRUE(r.conflicts.empty());
}

}  // namespace
}  // namespace qdot::structural
