// Pantelides' algorithm on derivative chains. Only the highest derivative of each chain takes part
// in the matching, and only the latest differentiated form of each equation, so the state is one
// order per chain, one differentiation count per equation and one assignment per chain: equation e
// (differentiated c_e times) reaches chain c's highest derivative iff maxOrder(e, c) + c_e == K_c.
#include "structural/Pantelides.h"

#include <algorithm>
#include <stdexcept>

#include "structural/BipartiteGraph.h"
#include "structural/Matching.h"

namespace qdot::structural {
namespace {

constexpr int kNone = -1;

// Each equation's chains with the highest order at which it contains them (deduplicated).
std::vector<std::vector<Occurrence>> highestOccurrences(const DerivativeStructure& s) {
  std::vector<std::vector<Occurrence>> out(s.occurrences.size());
  for (size_t e = 0; e < s.occurrences.size(); ++e) {
    auto list = s.occurrences[e];
    std::sort(list.begin(), list.end(), [](Occurrence a, Occurrence b) {
      return a.chain != b.chain ? a.chain < b.chain : a.order > b.order;
    });
    for (Occurrence o : list)
      if (out[e].empty() || out[e].back().chain != o.chain) out[e].push_back(o);
  }
  return out;
}

class Pantelides {
 public:
  explicit Pantelides(const DerivativeStructure& s)
      : occ_(highestOccurrences(s)),
        order_(s.highestOrder),
        diffs_(occ_.size(), 0),
        assign_(order_.size(), kNone),
        chainMark_(order_.size(), 0),
        equationMark_(occ_.size(), 0) {}

  DifferentiationPlan run() {
    const int limit = static_cast<int>(occ_.size()) + 2;  // no equation needs more (terminates: chainsDetermined)
    for (int e = 0; e < static_cast<int>(occ_.size()); ++e) {
      if (matchFree(e)) continue;
      while (!augment(e)) {
        for (int c : coloredChains_) ++order_[c];
        for (int f : coloredEquations_)
          if (++diffs_[f] > limit) throw std::invalid_argument("pantelides: the system is structurally singular");
      }
    }
    DifferentiationPlan plan{diffs_, order_, std::vector<int>(occ_.size(), kNone)};
    for (int c = 0; c < static_cast<int>(assign_.size()); ++c)
      if (assign_[c] != kNone) plan.matchedChain[assign_[c]] = c;
    return plan;
  }

 private:
  struct Frame {
    int equation;
    size_t cursor;
    int viaChain;  ///< the chain assigned to this equation through which the parent reached it
  };

  bool isHighest(int e, Occurrence o) const { return o.order + diffs_[e] == order_[o.chain]; }

  // Assigns a free highest derivative of e to e, if there is one.
  bool matchFree(int e) {
    for (Occurrence o : occ_[e])
      if (isHighest(e, o) && assign_[o.chain] == kNone) {
        assign_[o.chain] = e;
        return true;
      }
    return false;
  }

  // Depth-first search for an augmenting path from `root` over highest derivatives (explicit stack).
  // On failure, coloredEquations_/coloredChains_ hold everything visited.
  bool augment(int root) {
    ++generation_;
    coloredEquations_.assign(1, root);
    coloredChains_.clear();
    equationMark_[root] = generation_;
    stack_.assign(1, Frame{root, 0, kNone});
    if (matchFree(root)) return true;
    while (!stack_.empty()) {
      Frame& f = stack_.back();
      const auto& list = occ_[f.equation];
      if (f.cursor == list.size()) {
        stack_.pop_back();
        continue;
      }
      Occurrence o = list[f.cursor++];
      if (!isHighest(f.equation, o) || chainMark_[o.chain] == generation_) continue;
      chainMark_[o.chain] = generation_;
      coloredChains_.push_back(o.chain);
      int next = assign_[o.chain];
      if (equationMark_[next] == generation_) continue;
      equationMark_[next] = generation_;
      coloredEquations_.push_back(next);
      stack_.push_back(Frame{next, 0, o.chain});
      if (freeChainFlip(next)) return true;
    }
    return false;
  }

  // If the equation on top of the stack has a free highest derivative, flips the path to it.
  bool freeChainFlip(int top) {
    for (Occurrence o : occ_[top])
      if (isHighest(top, o) && assign_[o.chain] == kNone) {
        assign_[o.chain] = top;
        for (size_t i = stack_.size() - 1; i > 0; --i) assign_[stack_[i].viaChain] = stack_[i - 1].equation;
        return true;
      }
    return false;
  }

  std::vector<std::vector<Occurrence>> occ_;
  std::vector<int> order_, diffs_, assign_;
  std::vector<unsigned> chainMark_, equationMark_;
  unsigned generation_ = 0;
  std::vector<int> coloredEquations_, coloredChains_;
  std::vector<Frame> stack_;
};

}  // namespace

int DifferentiationPlan::maxDifferentiations() const {
  return differentiations.empty() ? 0 : *std::max_element(differentiations.begin(), differentiations.end());
}

bool chainsDetermined(const DerivativeStructure& s) {
  if (s.occurrences.size() != s.highestOrder.size()) return false;
  std::vector<Edge> edges;
  for (int e = 0; e < static_cast<int>(s.occurrences.size()); ++e)
    for (Occurrence o : s.occurrences[e]) edges.push_back({e, o.chain});
  BipartiteGraph g(static_cast<int>(s.occurrences.size()), static_cast<int>(s.highestOrder.size()), edges);
  return maximumMatching(g).size() == static_cast<int>(s.occurrences.size());
}

DifferentiationPlan pantelides(const DerivativeStructure& s) {
  if (!chainsDetermined(s))
    throw std::invalid_argument("pantelides: the system is not square and structurally nonsingular");
  for (const auto& list : s.occurrences)
    for (Occurrence o : list)
      if (o.chain < 0 || o.chain >= static_cast<int>(s.highestOrder.size()) || o.order < 0 ||
          o.order > s.highestOrder[o.chain])
        throw std::invalid_argument("pantelides: occurrence out of range");
  return Pantelides(s).run();
}

}  // namespace qdot::structural
