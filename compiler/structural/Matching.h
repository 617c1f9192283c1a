// Maximum equation–variable matching (Hopcroft–Karp) and the Dulmage–Mendelsohn coarse
// decomposition that explains a matching which is not perfect: which equations are over-determined
// and which variables are under-determined. Everything is iterative and near-linear.
#pragma once

#include <vector>

#include "structural/BipartiteGraph.h"

namespace qdot::structural {

/// Marks an equation or variable without a partner.
inline constexpr int kUnmatched = -1;

/// A matching of a BipartiteGraph: equation e is paired with variable matchOfEquation[e] and
/// variable v with equation matchOfVariable[v]; kUnmatched where there is no partner.
struct Matching {
  std::vector<int> matchOfEquation;  ///< size E
  std::vector<int> matchOfVariable;  ///< size V

  /// The matching with no pairs for a graph of the given size.
  static Matching empty(int numEquations, int numVariables);
  /// Number of matched pairs; O(E).
  int size() const;
  /// True iff every equation and every variable is matched (which implies E == V).
  bool isPerfect() const;
};

/// True iff `m` is sized for `g`, its two arrays agree, and every pair is an edge of `g`.
bool isValidMatching(const BipartiteGraph& g, const Matching& m);

/// A maximum-cardinality matching of `g`: a linear-time Karp–Sipser start (usually within a few
/// pairs of maximum), then Hopcroft–Karp phases of one BFS and iterative DFSs. O(|edges| *
/// sqrt(E + V)) worst case, O(E + V) extra memory, deterministic.
Matching maximumMatching(const BipartiteGraph& g);

/// Extends `initial` to a maximum matching. Every equation and variable matched in `initial`
/// stays matched (its partner may change). Throws std::invalid_argument if `initial` is not a
/// valid matching of `g`.
Matching maximumMatching(const BipartiteGraph& g, Matching initial);

/// Dulmage–Mendelsohn coarse decomposition. The three parts partition the equations and the
/// variables; they do not depend on which maximum matching was used. All lists are ascending.
struct DulmageMendelsohn {
  /// Over-determined part: the unmatched equations and everything reachable from them by
  /// alternating paths (equation -any edge-> variable -matched edge-> equation). Its equations
  /// mention only its variables, and it has exactly (number of unmatched equations) more
  /// equations than variables. Empty iff every equation can be matched.
  std::vector<int> overEquations;
  std::vector<int> overVariables;  ///< all matched, each to an equation of overEquations

  /// Under-determined part: the unmatched variables and everything reachable from them by
  /// alternating paths (variable -any edge-> equation -matched edge-> variable). Its variables
  /// occur only in its equations, and it has exactly (number of unmatched variables) more
  /// variables than equations. Empty iff every variable can be matched.
  std::vector<int> underVariables;
  std::vector<int> underEquations;  ///< all matched, each to a variable of underVariables

  /// Well-determined part: the rest, perfectly matched among itself. Its equations may also
  /// mention over-determined variables (they are known once that part is solved).
  std::vector<int> wellEquations;
  std::vector<int> wellVariables;

  /// True iff the graph has a perfect matching (both rectangular parts are empty).
  bool isWellDetermined() const { return overEquations.empty() && underVariables.empty(); }
};

/// Decomposes `g` with respect to the maximum matching `m` in O(E + V + |edges|). Throws
/// std::invalid_argument if `m` is not a valid matching of `g` or is not maximum.
DulmageMendelsohn dulmageMendelsohn(const BipartiteGraph& g, const Matching& m);

}  // namespace qdot::structural
