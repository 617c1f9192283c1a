// eliminateCommonSubexpressions: one post-order pass numbers the distinct inner nodes and records
// each node's children (so later passes need no hash lookups); uses are counted once per child slot
// of each distinct parent, plus once per output; a second pass rebuilds the nodes bottom-up, turning
// every non-leaf node used more than once into a temporary symbol. One hash lookup per edge to an
// inner node, none for leaves: O(DAG size).
#include <charconv>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

// Temporary names <prefix>k that do not clash with a symbol already used by the outputs.
class TempNamer {
 public:
  TempNamer(Context& ctx, std::string_view prefix, std::vector<uint8_t> used)
      : ctx_(ctx), name_(prefix), used_(std::move(used)) {}
  Expr next() {
    for (size_t prefix = name_.size();; name_.resize(prefix)) {
      char digits[24];
      name_.append(digits, std::to_chars(digits, digits + sizeof digits, counter_++).ptr);
      Expr s = ctx_.symbol(name_);
      if (s->symbolId >= used_.size() || !used_[s->symbolId]) {
        name_.resize(prefix);
        return s;
      }
    }
  }

 private:
  Context& ctx_;
  std::string name_;           // the prefix (digits are appended and removed)
  std::vector<uint8_t> used_;  // by symbolId: occurs in the outputs
  size_t counter_ = 0;
};

bool isLeaf(Expr n) { return n->isConstant() || n->isSymbol(); }

// A child or output: a leaf (constant or symbol, never a temporary, so not numbered: they are the
// most shared nodes and would cost most of the lookups) or the number of an inner node.
class Ref {
 public:
  Ref() = default;
  static Ref leaf(Expr n) { return Ref(reinterpret_cast<uintptr_t>(n)); }
  static Ref inner(uint32_t k) { return Ref((uintptr_t{k} << 1) | 1); }
  bool isInner() const { return bits_ & 1; }
  uint32_t number() const { return static_cast<uint32_t>(bits_ >> 1); }
  Expr node() const { return reinterpret_cast<Expr>(bits_); }

 private:
  explicit Ref(uintptr_t bits) : bits_(bits) {}
  uintptr_t bits_ = 0;  // nodes are 8-aligned: bit 0 is free
};

// The distinct inner nodes under the outputs, children before parents, with each node's children:
// kids[kidStart[i], kidStart[i + 1]) for node i (args then exps, as stored).
struct NumberedDag {
  std::vector<Expr> order;
  std::vector<uint32_t> kidStart{0};
  std::vector<Ref> kids;
  std::vector<Ref> outputs;
  std::vector<uint8_t> symbols;  // by symbolId: occurs
};

// Iterative post-order. A child is finished before its next sibling is looked at, so when a node
// finishes, its children are the top entries of `pending`, in order.
NumberedDag numberDag(std::span<const Expr> outputs) {
  NumberedDag dag;
  NodeMap<uint32_t> number;
  std::vector<Ref> pending;
  auto leaf = [&](Expr n) {
    if (n->isSymbol()) {
      if (dag.symbols.size() <= n->symbolId) dag.symbols.resize(n->symbolId + 1, 0);
      dag.symbols[n->symbolId] = 1;
    }
    return Ref::leaf(n);
  };
  struct Frame {
    Expr node;
    uint32_t next;
  };
  std::vector<Frame> stack;
  for (Expr root : outputs) {
    if (isLeaf(root)) {
      dag.outputs.push_back(leaf(root));
      continue;
    }
    if (!number.find(root)) stack.push_back({root, 0});
    while (!stack.empty()) {
      Frame& f = stack.back();
      if (f.next == 0) prefetchChildren(f.node, number);
      if (f.next < childCount(f.node)) {
        Expr c = child(f.node, f.next++);
        if (isLeaf(c)) pending.push_back(leaf(c));
        else if (const uint32_t* k = number.find(c)) pending.push_back(Ref::inner(*k));
        else stack.push_back({c, 0});  // not reached before: a DAG has no path back to an open node
        continue;
      }
      Expr n = f.node;
      stack.pop_back();
      auto k = static_cast<uint32_t>(dag.order.size());
      number.insert(n, k);
      dag.order.push_back(n);
      size_t kidCount = childCount(n);
      dag.kids.insert(dag.kids.end(), pending.end() - kidCount, pending.end());
      pending.resize(pending.size() - kidCount);
      dag.kidStart.push_back(static_cast<uint32_t>(dag.kids.size()));
      if (!stack.empty()) pending.push_back(Ref::inner(k));
    }
    dag.outputs.push_back(Ref::inner(*number.find(root)));
  }
  return dag;
}

}  // namespace

CseResult eliminateCommonSubexpressions(Context& ctx, std::span<const Expr> outputs, std::string_view prefix) {
  NumberedDag dag = numberDag(outputs);
  const std::vector<Expr>& order = dag.order;
  std::vector<uint32_t> uses(order.size(), 0);
  for (Ref r : dag.kids)
    if (r.isInner()) ++uses[r.number()];
  for (Ref r : dag.outputs)
    if (r.isInner()) ++uses[r.number()];

  CseResult result;
  TempNamer names(ctx, prefix, std::move(dag.symbols));
  std::vector<Expr> rewritten(order.size());
  auto valueOf = [&](Ref r) { return r.isInner() ? rewritten[r.number()] : r.node(); };
  // A node none of whose children changed is itself (what rebuild returns), known without loading it.
  auto changed = [&](size_t i) {
    for (uint32_t k = dag.kidStart[i]; k < dag.kidStart[i + 1]; ++k)
      if (Ref r = dag.kids[k]; r.isInner() && rewritten[r.number()] != order[r.number()]) return true;
    return false;
  };
  std::vector<Expr> kids;
  for (size_t i = 0; i < order.size(); ++i) {
    Expr value = order[i];
    if (changed(i)) {
      kids.clear();
      for (uint32_t k = dag.kidStart[i]; k < dag.kidStart[i + 1]; ++k) kids.push_back(valueOf(dag.kids[k]));
      value = ctx.impl().rebuild(order[i], kids);
    }
    if (uses[i] > 1 && !isLeaf(value)) {
      Expr temp = names.next();
      result.temporaries.emplace_back(temp, value);
      value = temp;
    }
    rewritten[i] = value;
  }
  for (Ref r : dag.outputs) result.outputs.push_back(valueOf(r));
  return result;
}

}  // namespace qdot::sym
