// BipartiteGraph: the plain equation–variable incidence structure the structural algorithms run on.
// Equations are 0..E-1 and variables 0..V-1; adjacency is stored in both directions in CSR form,
// every row sorted ascending and free of duplicates. It knows nothing of expressions: an adapter
// maps the DAE onto it.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

namespace qdot::structural {

/// One incidence: `variable` occurs in `equation`.
struct Edge {
  int equation;
  int variable;
};

/// Immutable bipartite graph between equations and variables with dense integer ids.
class BipartiteGraph {
 public:
  /// The empty graph: no equations, no variables.
  BipartiteGraph() = default;

  /// Builds both CSR directions from an edge list in O(E + V + |edges|); duplicate edges are merged.
  /// Throws std::invalid_argument if a count is negative or an id is out of range.
  BipartiteGraph(int numEquations, int numVariables, std::span<const Edge> edges);

  /// Convenience for small graphs: row e of `variablesOfEquation` lists the variables of equation e.
  static BipartiteGraph fromAdjacency(int numVariables,
                                      const std::vector<std::vector<int>>& variablesOfEquation);

  /// Number of equations E.
  int numEquations() const { return numEquations_; }
  /// Number of variables V.
  int numVariables() const { return numVariables_; }
  /// Number of distinct edges.
  std::size_t numEdges() const { return equationAdjacency_.size(); }

  /// Variables occurring in `equation`, ascending. Precondition: 0 <= equation < E.
  std::span<const int> variablesOf(int equation) const {
    return row(equationOffsets_, equationAdjacency_, equation);
  }
  /// Equations in which `variable` occurs, ascending. Precondition: 0 <= variable < V.
  std::span<const int> equationsOf(int variable) const {
    return row(variableOffsets_, variableAdjacency_, variable);
  }

 private:
  static std::span<const int> row(const std::vector<std::size_t>& offsets, const std::vector<int>& adjacency,
                                  int id) {
    return {adjacency.data() + offsets[id], offsets[id + 1] - offsets[id]};
  }

  int numEquations_ = 0;
  int numVariables_ = 0;
  std::vector<std::size_t> equationOffsets_{0};  // size E+1
  std::vector<int> equationAdjacency_;           // variables, row by row
  std::vector<std::size_t> variableOffsets_{0};  // size V+1
  std::vector<int> variableAdjacency_;           // equations, row by row
};

}  // namespace qdot::structural
