// BipartiteGraph construction: two counting-sort passes give equation rows sorted by variable,
// duplicates are squeezed out in place, and a third pass transposes into variable rows sorted by
// equation. Linear in E + V + |edges|, no comparison sort.
#include "structural/BipartiteGraph.h"

#include <stdexcept>
#include <string>

namespace qdot::structural {
namespace {

// Turns per-row counts (size n+1, counts in [1..n]) into CSR offsets in place.
void countsToOffsets(std::vector<std::size_t>& offsets) {
  for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
}

void checkInputs(int numEquations, int numVariables, std::span<const Edge> edges) {
  if (numEquations < 0 || numVariables < 0)
    throw std::invalid_argument("BipartiteGraph: negative equation or variable count");
  for (const Edge& edge : edges) {
    if (edge.equation < 0 || edge.equation >= numEquations || edge.variable < 0 ||
        edge.variable >= numVariables)
      throw std::invalid_argument("BipartiteGraph: edge (" + std::to_string(edge.equation) + ", " +
                                  std::to_string(edge.variable) + ") out of range");
  }
}

// Removes repeated entries from each (sorted) row, compacting the adjacency array in place.
void removeDuplicates(std::vector<std::size_t>& offsets, std::vector<int>& adjacency) {
  std::size_t write = 0;
  for (std::size_t r = 0; r + 1 < offsets.size(); ++r) {
    std::size_t begin = offsets[r], end = offsets[r + 1], rowStart = write;
    for (std::size_t i = begin; i < end; ++i)
      if (write == rowStart || adjacency[write - 1] != adjacency[i]) adjacency[write++] = adjacency[i];
    offsets[r] = rowStart;
  }
  offsets.back() = write;
  adjacency.resize(write);
}

// Transposes CSR `offsets`/`adjacency` (rows = sources) into rows over `numTargets`. Because
// sources are visited in ascending order, every transposed row comes out sorted.
void transpose(const std::vector<std::size_t>& offsets, const std::vector<int>& adjacency, int numTargets,
               std::vector<std::size_t>& outOffsets, std::vector<int>& outAdjacency) {
  outOffsets.assign(static_cast<std::size_t>(numTargets) + 1, 0);
  for (int target : adjacency) ++outOffsets[target + 1];
  countsToOffsets(outOffsets);
  outAdjacency.resize(adjacency.size());
  std::vector<std::size_t> cursor(outOffsets.begin(), outOffsets.end() - 1);
  for (std::size_t source = 0; source + 1 < offsets.size(); ++source)
    for (std::size_t i = offsets[source]; i < offsets[source + 1]; ++i)
      outAdjacency[cursor[adjacency[i]]++] = static_cast<int>(source);
}

}  // namespace

BipartiteGraph::BipartiteGraph(int numEquations, int numVariables, std::span<const Edge> edges)
    : numEquations_(numEquations), numVariables_(numVariables) {
  checkInputs(numEquations, numVariables, edges);
  // Pass 1: bucket the edges by variable (equations of each variable in input order).
  std::vector<std::size_t> byVariable(static_cast<std::size_t>(numVariables) + 1, 0);
  for (const Edge& edge : edges) ++byVariable[edge.variable + 1];
  countsToOffsets(byVariable);
  std::vector<int> equationsByVariable(edges.size());
  std::vector<std::size_t> cursor(byVariable.begin(), byVariable.end() - 1);
  for (const Edge& edge : edges) equationsByVariable[cursor[edge.variable]++] = edge.equation;
  // Pass 2: transposing gives equation rows sorted by variable (still with duplicates).
  transpose(byVariable, equationsByVariable, numEquations, equationOffsets_, equationAdjacency_);
  removeDuplicates(equationOffsets_, equationAdjacency_);
  // Pass 3: the variable direction, from the clean equation rows.
  transpose(equationOffsets_, equationAdjacency_, numVariables, variableOffsets_, variableAdjacency_);
}

BipartiteGraph BipartiteGraph::fromAdjacency(int numVariables,
                                             const std::vector<std::vector<int>>& variablesOfEquation) {
  std::vector<Edge> edges;
  for (std::size_t e = 0; e < variablesOfEquation.size(); ++e)
    for (int v : variablesOfEquation[e]) edges.push_back({static_cast<int>(e), v});
  return BipartiteGraph(static_cast<int>(variablesOfEquation.size()), numVariables, edges);
}

}  // namespace qdot::structural
