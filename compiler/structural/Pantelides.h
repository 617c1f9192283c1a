// Pantelides' algorithm: which equations of a DAE must be differentiated, and how often, so that the
// highest derivatives of its variables can be solved for (structural index ≤ 1 after the dummy
// derivative method). Works on a plain structure: variables are derivative chains (x, x', x'', …)
// identified by dense ids, equations list the (chain, order) pairs they contain.
#pragma once

#include <vector>

namespace qdot::structural {

/// One occurrence of a variable in an equation: the order-th time derivative of chain `chain`.
struct Occurrence {
  int chain;
  int order;
};

/// The input. `highestOrder[c]` is the order of chain c's highest derivative in the system (the
/// unknown the equations solve for): 0 for an algebraic variable, 1 for a first-order state, 2 for
/// a coordinate whose acceleration appears. Orders in `occurrences` are ≤ the chain's highest.
struct DerivativeStructure {
  std::vector<int> highestOrder;                       ///< per chain
  std::vector<std::vector<Occurrence>> occurrences;    ///< per equation, any order, may repeat
};

/// The result.
struct DifferentiationPlan {
  /// Per equation: how many times it is differentiated (the system then contains e, e', …, e^(c)).
  std::vector<int> differentiations;
  /// Per chain: its highest derivative order after differentiation (≥ the input's).
  std::vector<int> highestOrder;
  /// Per equation: the chain whose highest derivative its highest differentiated form is matched to.
  std::vector<int> matchedChain;
  /// The largest number of differentiations of any equation (the structural index is this + 1
  /// when some variable is algebraic, and 0 when nothing is differentiated and all are states).
  int maxDifferentiations() const;
};

/// True iff there are as many equations as chains and each equation can be matched to a distinct
/// chain it contains (at any order): the condition under which Pantelides' algorithm terminates.
bool chainsDetermined(const DerivativeStructure& s);

/// Pantelides (1988): for each equation in turn, search an augmenting path over the highest
/// derivatives; if there is none, differentiate every equation visited and raise the order of
/// every chain visited, and search again from the differentiated equation. Augmenting-path search
/// is iterative; visit marks are generation counters, so a search costs only what it visits.
/// Precondition: chainsDetermined(s); throws
/// std::invalid_argument otherwise (a compiler bug: the caller reports the user error first).
DifferentiationPlan pantelides(const DerivativeStructure& s);

}  // namespace qdot::structural
