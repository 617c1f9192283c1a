// structuralCompare: the deterministic total order of canonical Add terms and Mul factors.
// Iterative: because equal subtrees are the same node, two distinct nodes with equal shallow keys
// differ in their first differing child, so the comparison walks one path down. The walk is cut
// after 12 levels, where the structural hash (built from kinds, values and symbol ids, never from
// addresses) decides, so comparing two long look-alike chains stays O(1).
#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

template <class T>
int cmp(T a, T b) {
  return a < b ? -1 : (b < a ? 1 : 0);
}

// NaN sorts after every number.
int cmpNumber(double a, double b) {
  bool na = std::isnan(a), nb = std::isnan(b);
  if (na || nb) return cmp(na, nb);
  return cmp(a, b);
}

// Compares everything but the children; 0 means "decide by children, then by tieBreak".
int shallowCompare(Expr a, Expr b) {
  if (int c = cmp(a->kind, b->kind)) return c;
  if (a->kind == Kind::Constant) return cmpNumber(a->value, b->value);
  if (a->kind == Kind::Symbol) return cmp(a->symbolId, b->symbolId);
  return cmp(a->depth, b->depth);
}

// Decides between nodes whose children are pairwise identical: arity, coefficients, value.
int tieBreak(Expr a, Expr b) {
  if (int c = cmp(childCount(a), childCount(b))) return c;
  for (size_t i = 0; i < a->coefs().size(); ++i)
    if (int c = cmpNumber(a->coefs()[i], b->coefs()[i])) return c;
  return cmpNumber(a->value, b->value);
}

// Lexicographic over (shallow key, children, tie-break). After `levels` descents the structural
// hash decides (then an unbounded descent on a hash collision), so one comparison costs O(levels).
int compareWithin(Expr a, Expr b, int levels) {
  while (a != b) {
    if (int c = shallowCompare(a, b)) return c;
    if (a->kind == Kind::Constant || a->kind == Kind::Symbol) return 0;  // equal leaves are one node
    if (levels-- == 0) {
      if (a->hash != b->hash) return cmp(a->hash, b->hash);
      levels = -1;  // hash collision: unbounded descent
    }
    size_t n = std::min(childCount(a), childCount(b)), i = 0;
    while (i < n && child(a, i) == child(b, i)) ++i;
    if (i == n) return tieBreak(a, b);
    a = child(a, i);
    b = child(b, i);
  }
  return 0;
}

}  // namespace

int structuralCompare(Expr a, Expr b) { return compareWithin(a, b, 12); }

}  // namespace qdot::sym
