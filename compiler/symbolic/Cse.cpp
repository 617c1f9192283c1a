// eliminateCommonSubexpressions: one post-order pass counts how often each distinct node is used
// (once per child slot of each distinct parent, plus once per output); a second pass rebuilds the
// nodes bottom-up, turning every non-leaf node used more than once into a temporary symbol.
#include "symbolic/ContextImpl.h"

namespace qdot::sym {

namespace {

// Temporary names <prefix>k that do not clash with a symbol already used by the outputs.
class TempNamer {
 public:
  TempNamer(Context& ctx, std::string_view prefix, const std::vector<Expr>& nodes)
      : ctx_(ctx), prefix_(prefix) {
    for (Expr n : nodes)
      if (n->isSymbol()) used_.insert(n, 1);
  }
  Expr next() {
    for (;;) {
      Expr s = ctx_.symbol(prefix_ + std::to_string(counter_++));
      if (!used_.find(s)) return s;
    }
  }

 private:
  Context& ctx_;
  std::string prefix_;
  NodeMap<char> used_;
  size_t counter_ = 0;
};

}  // namespace

CseResult eliminateCommonSubexpressions(Context& ctx, std::span<const Expr> outputs, std::string_view prefix) {
  PostOrder po = postOrder(outputs);
  const std::vector<Expr>& order = po.order;
  std::vector<uint32_t> uses(order.size(), 0);
  for (Expr n : order)
    for (size_t c = 0; c < childCount(n); ++c) ++uses[*po.index.find(child(n, c))];
  for (Expr r : outputs) ++uses[*po.index.find(r)];

  CseResult result;
  TempNamer names(ctx, prefix, order);
  std::vector<Expr> rewritten(order.size());
  std::vector<Expr> kids;
  for (size_t i = 0; i < order.size(); ++i) {
    Expr n = order[i];
    kids.clear();
    for (size_t c = 0; c < childCount(n); ++c) kids.push_back(rewritten[*po.index.find(child(n, c))]);
    Expr value = ctx.impl().rebuild(n, kids);
    bool leaf = value->isConstant() || value->isSymbol();
    if (uses[i] > 1 && !leaf) {
      Expr temp = names.next();
      result.temporaries.emplace_back(temp, value);
      value = temp;
    }
    rewritten[i] = value;
  }
  for (Expr r : outputs) result.outputs.push_back(rewritten[*po.index.find(r)]);
  return result;
}

}  // namespace qdot::sym
