// Maximum matching (Karp–Sipser start, then Hopcroft–Karp) and the Dulmage–Mendelsohn coarse
// decomposition. Each Hopcroft–Karp phase layers the equations by a BFS from the free ones, then
// augments along shortest paths found by DFSs with an explicit stack and per-equation edge
// cursors, so a phase costs O(|edges|) and nothing recurses.
#include "structural/Matching.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace qdot::structural {
namespace {

constexpr int kInfinity = std::numeric_limits<int>::max();

// Karp–Sipser initial matching. While some free vertex has exactly one free neighbour, match that
// pair (this never costs maximality); otherwise match the lowest free equation to its first free
// variable. Linear time: degrees only decrease, so every vertex is queued at most once.
class KarpSipser {
 public:
  KarpSipser(const BipartiteGraph& g, Matching& m)
      : g_(g), m_(m), equationDegree_(g.numEquations(), 0), variableDegree_(g.numVariables(), 0) {}

  void run() {
    countFreeNeighbours();
    for (int next = 0;; ++next) {
      matchDegreeOneVertices();
      while (next < g_.numEquations() && !isFreeWithFreeNeighbour(next)) ++next;
      if (next == g_.numEquations()) return;
      match(next, firstFreeVariableOf(next));
    }
  }

 private:
  // Pending vertices are encoded as e (equation) or ~v (variable).
  void countFreeNeighbours() {
    for (int e = 0; e < g_.numEquations(); ++e) {
      if (m_.matchOfEquation[e] != kUnmatched) continue;
      for (int v : g_.variablesOf(e))
        if (m_.matchOfVariable[v] == kUnmatched) ++equationDegree_[e], ++variableDegree_[v];
    }
    for (int e = 0; e < g_.numEquations(); ++e)
      if (equationDegree_[e] == 1) pending_.push_back(e);
    for (int v = 0; v < g_.numVariables(); ++v)
      if (variableDegree_[v] == 1) pending_.push_back(~v);
  }

  void matchDegreeOneVertices() {
    while (!pending_.empty()) {
      int x = pending_.back();
      pending_.pop_back();
      if (x >= 0 && m_.matchOfEquation[x] == kUnmatched && equationDegree_[x] == 1)
        match(x, firstFreeVariableOf(x));
      else if (x < 0 && m_.matchOfVariable[~x] == kUnmatched && variableDegree_[~x] == 1)
        match(firstFreeEquationOf(~x), ~x);
    }
  }

  bool isFreeWithFreeNeighbour(int e) const {
    return m_.matchOfEquation[e] == kUnmatched && equationDegree_[e] > 0;
  }
  int firstFreeVariableOf(int e) const {
    for (int v : g_.variablesOf(e))
      if (m_.matchOfVariable[v] == kUnmatched) return v;
    return kUnmatched;  // unreachable: callers check the degree
  }
  int firstFreeEquationOf(int v) const {
    for (int e : g_.equationsOf(v))
      if (m_.matchOfEquation[e] == kUnmatched) return e;
    return kUnmatched;
  }

  // Pairs e with v and removes both from the free graph, updating their free neighbours' degrees.
  void match(int e, int v) {
    m_.matchOfEquation[e] = v;
    m_.matchOfVariable[v] = e;
    for (int u : g_.variablesOf(e))
      if (m_.matchOfVariable[u] == kUnmatched && --variableDegree_[u] == 1) pending_.push_back(~u);
    for (int f : g_.equationsOf(v))
      if (m_.matchOfEquation[f] == kUnmatched && --equationDegree_[f] == 1) pending_.push_back(f);
  }

  const BipartiteGraph& g_;
  Matching& m_;
  std::vector<int> equationDegree_;  // free variables of each free equation
  std::vector<int> variableDegree_;  // free equations of each free variable
  std::vector<int> pending_;         // vertices whose free degree dropped to 1
};

class HopcroftKarp {
 public:
  HopcroftKarp(const BipartiteGraph& g, Matching& m)
      : g_(g), m_(m), layer_(g.numEquations()), cursor_(g.numEquations()) {}

  void run() {
    while (buildLayers()) augmentAlongLayers();
  }

 private:
  // BFS from all free equations; layer_[e] = alternating distance (in equations) from a free
  // equation. Sets pathLayers_ to the number of equation layers on a shortest augmenting path
  // and returns false if there is none.
  bool buildLayers() {
    queue_.clear();
    for (int e = 0; e < g_.numEquations(); ++e) {
      bool isFree = m_.matchOfEquation[e] == kUnmatched;
      layer_[e] = isFree ? 0 : kInfinity;
      if (isFree) queue_.push_back(e);
    }
    pathLayers_ = kInfinity;
    for (std::size_t head = 0; head < queue_.size(); ++head) {
      int e = queue_[head];
      if (layer_[e] >= pathLayers_) break;  // queue is sorted by layer
      for (int v : g_.variablesOf(e)) {
        int next = m_.matchOfVariable[v];
        if (next == kUnmatched) {
          pathLayers_ = layer_[e] + 1;
        } else if (layer_[next] == kInfinity) {
          layer_[next] = layer_[e] + 1;
          queue_.push_back(next);
        }
      }
    }
    return pathLayers_ != kInfinity;
  }

  void augmentAlongLayers() {
    std::fill(cursor_.begin(), cursor_.end(), 0);
    for (int e = 0; e < g_.numEquations(); ++e)
      if (m_.matchOfEquation[e] == kUnmatched && layer_[e] == 0) augmentFrom(e);
  }

  // Iterative DFS along the layers from the free equation `root`. The stack holds the equations
  // of the current path; the variable leading out of stack entry e is the one just before
  // cursor_[e]. Exhausted equations are removed from the layering for the rest of the phase.
  bool augmentFrom(int root) {
    stack_.assign(1, root);
    while (!stack_.empty()) {
      int e = stack_.back();
      std::span<const int> vars = g_.variablesOf(e);
      if (cursor_[e] == vars.size()) {
        layer_[e] = kInfinity;
        stack_.pop_back();
        continue;
      }
      int v = vars[cursor_[e]++];
      int next = m_.matchOfVariable[v];
      if (next == kUnmatched) {
        if (layer_[e] + 1 != pathLayers_) continue;
        flipStackPath();
        return true;
      }
      if (layer_[next] == layer_[e] + 1 && layer_[next] < pathLayers_) stack_.push_back(next);
    }
    return false;
  }

  void flipStackPath() {
    for (int e : stack_) {
      int v = g_.variablesOf(e)[cursor_[e] - 1];
      m_.matchOfEquation[e] = v;
      m_.matchOfVariable[v] = e;
    }
  }

  const BipartiteGraph& g_;
  Matching& m_;
  std::vector<int> layer_;
  std::vector<std::size_t> cursor_;
  std::vector<int> queue_;
  std::vector<int> stack_;
  int pathLayers_ = kInfinity;
};

enum class Part : unsigned char { Well, Over, Under };

// Marks the over-determined part: BFS over alternating paths from the free equations. Reaching a
// free variable would be an augmenting path, i.e. `m` is not maximum.
void markOverDetermined(const BipartiteGraph& g, const Matching& m, std::vector<Part>& eqPart,
                        std::vector<Part>& varPart) {
  std::vector<int> queue;
  for (int e = 0; e < g.numEquations(); ++e)
    if (m.matchOfEquation[e] == kUnmatched) eqPart[e] = Part::Over, queue.push_back(e);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    for (int v : g.variablesOf(queue[head])) {
      if (varPart[v] == Part::Over) continue;
      int partner = m.matchOfVariable[v];
      if (partner == kUnmatched) throw std::invalid_argument("dulmageMendelsohn: matching is not maximum");
      varPart[v] = Part::Over;
      eqPart[partner] = Part::Over;
      queue.push_back(partner);
    }
  }
}

// Marks the under-determined part: BFS over alternating paths from the free variables. For a
// maximum matching it is disjoint from the over-determined part.
void markUnderDetermined(const BipartiteGraph& g, const Matching& m, std::vector<Part>& eqPart,
                         std::vector<Part>& varPart) {
  std::vector<int> queue;
  for (int v = 0; v < g.numVariables(); ++v)
    if (m.matchOfVariable[v] == kUnmatched) varPart[v] = Part::Under, queue.push_back(v);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    for (int e : g.equationsOf(queue[head])) {
      if (eqPart[e] == Part::Under) continue;
      int partner = m.matchOfEquation[e];  // matched: an unmatched e would end an augmenting path
      eqPart[e] = Part::Under;
      varPart[partner] = Part::Under;
      queue.push_back(partner);
    }
  }
}

void collect(const std::vector<Part>& parts, std::vector<int>& over, std::vector<int>& under,
             std::vector<int>& well) {
  for (std::size_t i = 0; i < parts.size(); ++i) {
    int id = static_cast<int>(i);
    switch (parts[i]) {
      case Part::Over: over.push_back(id); break;
      case Part::Under: under.push_back(id); break;
      case Part::Well: well.push_back(id); break;
    }
  }
}

}  // namespace

Matching Matching::empty(int numEquations, int numVariables) {
  return Matching{std::vector<int>(numEquations, kUnmatched), std::vector<int>(numVariables, kUnmatched)};
}

int Matching::size() const {
  int count = 0;
  for (int v : matchOfEquation) count += v != kUnmatched;
  return count;
}

bool Matching::isPerfect() const {
  return matchOfEquation.size() == matchOfVariable.size() &&
         size() == static_cast<int>(matchOfEquation.size());
}

bool isValidMatching(const BipartiteGraph& g, const Matching& m) {
  if (m.matchOfEquation.size() != static_cast<std::size_t>(g.numEquations()) ||
      m.matchOfVariable.size() != static_cast<std::size_t>(g.numVariables()))
    return false;
  int pairs = 0;
  for (int e = 0; e < g.numEquations(); ++e) {
    int v = m.matchOfEquation[e];
    if (v == kUnmatched) continue;
    if (v < 0 || v >= g.numVariables() || m.matchOfVariable[v] != e) return false;
    std::span<const int> vars = g.variablesOf(e);
    if (!std::binary_search(vars.begin(), vars.end(), v)) return false;
    ++pairs;
  }
  int matchedVariables = 0;
  for (int e : m.matchOfVariable) {
    if (e == kUnmatched) continue;
    if (e < 0 || e >= g.numEquations()) return false;
    ++matchedVariables;
  }
  return matchedVariables == pairs;
}

Matching maximumMatching(const BipartiteGraph& g) {
  return maximumMatching(g, Matching::empty(g.numEquations(), g.numVariables()));
}

Matching maximumMatching(const BipartiteGraph& g, Matching initial) {
  if (!isValidMatching(g, initial)) throw std::invalid_argument("maximumMatching: invalid initial matching");
  KarpSipser(g, initial).run();
  HopcroftKarp(g, initial).run();
  return initial;
}

DulmageMendelsohn dulmageMendelsohn(const BipartiteGraph& g, const Matching& m) {
  if (!isValidMatching(g, m)) throw std::invalid_argument("dulmageMendelsohn: invalid matching");
  std::vector<Part> eqPart(g.numEquations(), Part::Well);
  std::vector<Part> varPart(g.numVariables(), Part::Well);
  markOverDetermined(g, m, eqPart, varPart);
  markUnderDetermined(g, m, eqPart, varPart);
  DulmageMendelsohn dm;
  collect(eqPart, dm.overEquations, dm.underEquations, dm.wellEquations);
  collect(varPart, dm.overVariables, dm.underVariables, dm.wellVariables);
  return dm;
}

}  // namespace qdot::structural
