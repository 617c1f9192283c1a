// Alias elimination on a plain graph: variables 0..n-1 and relations `a = ±b`, `a = constant`.
// Every class of variables joined by the relations becomes one representative (or one constant);
// its members are ±the representative. The class keeps one start value. Relations that contradict
// the earlier ones (a = b and a = -b, two constants) are reported, not applied. Iterative weighted
// union–find with path compression: O((n + relations) α(n)).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace qdot::structural {

/// `a = sign * b` (b >= 0, sign ±1), or `a = constant` (b == kNoVariable).
struct AliasRelation {
  static constexpr int kNoVariable = -1;
  int a = 0;
  int b = kNoVariable;
  int sign = 1;
  double constant = 0;

  static AliasRelation equal(int a, int b, int sign = 1) { return {a, b, sign, 0}; }
  static AliasRelation fixedTo(int a, double constant) { return {a, kNoVariable, 1, constant}; }
};

struct StartValue {
  double value = 0;
  bool fixed = false;
  bool operator==(const StartValue&) const = default;
};

struct AliasProblem {
  int numVariables = 0;
  std::vector<AliasRelation> relations;  ///< applied in order: a later one that contradicts is not
  /// By variable (empty: all 0): the highest of a class is its representative; ties → lower id.
  std::vector<int> priority;
  /// By variable (empty: none).
  std::vector<std::optional<StartValue>> start;
};

/// What became of one relation.
struct RelationOutcome {
  enum Kind : uint8_t {
    Joined,        ///< joined two classes, or gave a class its constant
    Implied,       ///< already follows from the earlier relations (nothing changes)
    SignCycle,     ///< a = b and a = -b together: forces the class to 0 (not applied)
    TwoConstants,  ///< a different constant than the class already has (not applied)
  } kind = Joined;
  /// Implied or TwoConstants: the relation that gave a's class its constant (b's if a's has
  /// none); -1 for a relation between two variables already in one class.
  int earlier = -1;
};

struct AliasConflict {
  enum Kind : uint8_t {
    SignCycle,         ///< variables: a, b of the relation
    TwoConstants,      ///< variables: a (and b) of the relation
    /// variables: the member whose start is not used, then the one whose start is used (none in
    /// a class with a constant: the start differs from the constant)
    StartValues,
    FixedStartValues,  ///< the same, both starts fixed
  } kind = SignCycle;
  std::vector<int> variables;
  int relation = -1;  ///< SignCycle, TwoConstants: which relation
};

struct AliasResult {
  /// By variable: v = sign[v] * representative[v] (representative[r] == r, sign +1). A class
  /// with a constant has a representative too; constant[v] then holds v's value.
  std::vector<int> representative;
  std::vector<int8_t> sign;
  std::vector<std::optional<double>> constant;
  /// By variable: the start value of its class, converted to v through its sign; none for a class
  /// with a constant. A fixed start wins over one not fixed, then the representative's own, then
  /// the lowest member's. startFrom[v] is the member it was given to (-1 if none).
  std::vector<std::optional<StartValue>> start;
  std::vector<int> startFrom;
  std::vector<RelationOutcome> outcome;  ///< by relation
  /// Contradicting relations in relation order, then start values not used: class by class (in
  /// the order of their lowest member), members ascending. Constants are compared exactly.
  std::vector<AliasConflict> conflicts;
};

/// Throws std::invalid_argument for an id out of range, a sign other than ±1, or a priority or
/// start list of the wrong size.
AliasResult eliminateAliases(const AliasProblem& problem);

}  // namespace qdot::structural
