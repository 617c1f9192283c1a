// Read-only DAG queries: dependsOn, freeSymbols and dagSize. All iterative (explicit stacks) and
// DAG-aware (each node visited once), so deep or heavily shared expressions are safe and linear;
// small expressions (the common case) are traversed without touching the heap.
#include "symbolic/ContextImpl.h"

namespace qdot::sym {

bool Context::dependsOn(Expr e, Expr s) const {
  if (!s || !(e->symbolMask & s->symbolMask)) return false;
  NodeSet seen;
  SmallVec<Expr, 32> stack;
  stack.push_back(e);
  seen.insert(e);
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    if (n == s) return true;
    for (Expr c : children(n))
      if ((c->symbolMask & s->symbolMask) && seen.insert(c)) stack.push_back(c);
  }
  return false;
}

std::vector<Expr> Context::freeSymbols(Expr e) const {
  std::vector<Expr> out;
  NodeSet seen;
  SmallVec<Expr, 32> stack;
  stack.push_back(e);
  while (!stack.empty()) {  // pre-order, left to right; a node is marked when it is reached
    Expr n = stack.back();
    stack.pop_back();
    if (!n->symbolMask || !seen.insert(n)) continue;
    if (n->isSymbol()) out.push_back(n);
    for (size_t i = childCount(n); i-- > 0;) stack.push_back(child(n, i));
  }
  return out;
}

size_t Context::dagSize(std::span<const Expr> roots) const {
  NodeSet seen;
  SmallVec<Expr, 32> stack;
  for (Expr r : roots)
    if (seen.insert(r)) stack.push_back(r);
  while (!stack.empty()) {
    Expr n = stack.back();
    stack.pop_back();
    for (Expr c : children(n))
      if (seen.insert(c)) stack.push_back(c);
  }
  return seen.size();
}

}  // namespace qdot::sym
