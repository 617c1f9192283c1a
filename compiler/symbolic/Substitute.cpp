// Context::substitute: replaces nodes (normally symbols) by expressions, all at once, and rebuilds
// the ancestors through the canonical constructors. One post-order pass with a per-call memo: each
// distinct node is visited once, and subtrees whose symbol mask misses every key are not entered.
#include "symbolic/ContextImpl.h"

namespace qdot::sym {

uint64_t Context::keyMaskOf(const std::unordered_map<Expr, Expr>& map) {
  uint64_t keyMask = 0;
  for (auto& [from, to] : map) keyMask |= from->symbolMask;
  return keyMask;
}

Expr Context::substitute(Expr e, const std::unordered_map<Expr, Expr>& map) {
  return substitute(e, map, keyMaskOf(map));
}

namespace {

// The one pass both forms share; replacement(n) is n's replacement or nullptr.
template <class Replacement>
Expr substituteBy(Context::Impl& impl, Expr e, uint64_t keyMask, Replacement&& replacement) {
  if (!(e->symbolMask & keyMask)) return e;
  auto enter = [&](Expr n) { return (n->symbolMask & keyMask) && !replacement(n); };
  PostOrder po = postOrder(std::span<const Expr>(&e, 1), enter);

  std::vector<Expr> result(po.order.size());
  std::vector<Expr> kids;
  for (size_t i = 0; i < po.order.size(); ++i) {
    Expr n = po.order[i];
    if (Expr to = replacement(n)) {
      result[i] = to;
    } else if (!(n->symbolMask & keyMask) || childCount(n) == 0) {
      result[i] = n;
    } else {
      kids.clear();
      bool changed = false;
      for (size_t c = 0; c < childCount(n); ++c) {
        kids.push_back(result[*po.index.find(child(n, c))]);
        changed |= kids.back() != child(n, c);
      }
      // A node whose mask only seemed to meet the keys' (64 bits for all symbols: with many keys
      // every node does) is itself; rebuilding it would find the same node, at the cost of
      // canonicalising it again.
      result[i] = changed ? impl.rebuild(n, kids) : n;
    }
  }
  return result.back();
}

}  // namespace

Expr Context::substitute(Expr e, const std::unordered_map<Expr, Expr>& map, uint64_t keyMask) {
  if (map.empty()) return e;
  return substituteBy(*impl_, e, keyMask, [&](Expr n) -> Expr {
    auto it = map.find(n);
    return it == map.end() ? nullptr : it->second;
  });
}

Expr Context::substitute(Expr e, std::span<const Expr> bySymbolId, uint64_t keyMask) {
  return substituteBy(*impl_, e, keyMask, [&](Expr n) -> Expr {
    return n->isSymbol() && n->symbolId < bySymbolId.size() ? bySymbolId[n->symbolId] : nullptr;
  });
}

}  // namespace qdot::sym
