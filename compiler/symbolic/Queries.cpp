// Read-only DAG queries: dependsOn, freeSymbols and dagSize. All iterative (explicit stacks) and
// DAG-aware (each node visited once), so deep or heavily shared expressions are safe and linear.
#include "symbolic/ContextImpl.h"

namespace qdot::sym {

bool Context::dependsOn(Expr e, Expr s) const {
  if (!s || !(e->symbolMask & s->symbolMask)) return false;
  NodeMap<char> seen;
  std::vector<Expr> stack{e};
  seen.insert(e, 1);
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    if (n == s) return true;
    for (size_t i = 0; i < childCount(n); ++i) {
      Expr c = child(n, i);
      if ((c->symbolMask & s->symbolMask) && seen.insert(c, 1).second) stack.push_back(c);
    }
  }
  return false;
}

std::vector<Expr> Context::freeSymbols(Expr e) const {
  std::vector<Expr> out;
  NodeMap<char> seen;
  std::vector<Expr> stack{e};
  while (!stack.empty()) {  // pre-order, left to right; a node is marked when it is reached
    Expr n = stack.back();
    stack.pop_back();
    if (!n->symbolMask || !seen.insert(n, 1).second) continue;
    if (n->isSymbol()) out.push_back(n);
    for (size_t i = childCount(n); i-- > 0;) stack.push_back(child(n, i));
  }
  return out;
}

size_t Context::dagSize(std::span<const Expr> roots) const {
  NodeMap<char> seen;
  std::vector<Expr> stack;
  for (Expr r : roots)
    if (seen.insert(r, 1).second) stack.push_back(r);
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    for (size_t i = 0; i < childCount(n); ++i)
      if (seen.insert(child(n, i), 1).second) stack.push_back(child(n, i));
  }
  return seen.size();
}

}  // namespace qdot::sym
