// Iterative Tarjan over the equation dependency graph induced by a perfect matching. Edges
// point from an equation to the equations it needs, so Tarjan's emission order (a component is
// closed only after everything it reaches) is already the solve order.
#include "structural/BlockTriangular.h"

#include <algorithm>
#include <stdexcept>

namespace qdot::structural {
namespace {

constexpr int kUnvisited = -1;

class Tarjan {
 public:
  Tarjan(const BipartiteGraph& g, const Matching& m)
      : g_(g), m_(m), index_(g.numEquations(), kUnvisited), lowLink_(g.numEquations()),
        cursor_(g.numEquations(), 0), onStack_(g.numEquations(), false) {}

  BlockTriangularOrder run() {
    for (int e = 0; e < g_.numEquations(); ++e)
      if (index_[e] == kUnvisited) visitFrom(e);
    return std::move(order_);
  }

 private:
  void discover(int e) {
    index_[e] = lowLink_[e] = nextIndex_++;
    components_.push_back(e);
    onStack_[e] = true;
    calls_.push_back(e);
  }

  // Depth-first search from `root`, with `calls_` as the explicit call stack and `cursor_[e]` as
  // the position in e's variable list where its frame resumes.
  void visitFrom(int root) {
    discover(root);
    while (!calls_.empty()) {
      int e = calls_.back();
      std::span<const int> vars = g_.variablesOf(e);
      if (cursor_[e] < vars.size()) {
        int dependency = m_.matchOfVariable[vars[cursor_[e]++]];
        if (dependency == e) continue;
        if (index_[dependency] == kUnvisited)
          discover(dependency);
        else if (onStack_[dependency])
          lowLink_[e] = std::min(lowLink_[e], index_[dependency]);
        continue;
      }
      calls_.pop_back();
      if (lowLink_[e] == index_[e]) emitComponent(e);
      if (!calls_.empty()) lowLink_[calls_.back()] = std::min(lowLink_[calls_.back()], lowLink_[e]);
    }
  }

  // Pops the component whose root is `root` off the Tarjan stack as the next block.
  void emitComponent(int root) {
    std::vector<int> block;
    int e;
    do {
      e = components_.back();
      components_.pop_back();
      onStack_[e] = false;
      block.push_back(e);
    } while (e != root);
    std::sort(block.begin(), block.end());
    order_.blocks.push_back(std::move(block));
  }

  const BipartiteGraph& g_;
  const Matching& m_;
  std::vector<int> index_;
  std::vector<int> lowLink_;
  std::vector<std::size_t> cursor_;
  std::vector<bool> onStack_;
  std::vector<int> calls_;
  std::vector<int> components_;
  int nextIndex_ = 0;
  BlockTriangularOrder order_;
};

}  // namespace

BlockTriangularOrder blockTriangularOrder(const BipartiteGraph& g, const Matching& m) {
  if (!isValidMatching(g, m) || !m.isPerfect())
    throw std::invalid_argument("blockTriangularOrder: needs a valid perfect matching");
  return Tarjan(g, m).run();
}

std::vector<int> variablesOfBlock(const std::vector<int>& block, const Matching& m) {
  std::vector<int> vars;
  vars.reserve(block.size());
  for (int e : block) vars.push_back(m.matchOfEquation[e]);
  return vars;
}

}  // namespace qdot::structural
