// The Context: node arena, hash-consing (intern) table, constants and symbols.
// Every node is created through Impl::intern, which computes the structural hash, the symbol mask
// and the depth from the (already built) children and returns the existing node when one is equal.
#include <stdexcept>

#include "symbolic/ContextImpl.h"

namespace qdot::sym {

const char* kindSpelling(Kind k) {
  switch (k) {
#define QDOT_EXPR_KIND(K, A, S) \
  case Kind::K:                 \
    return S;
#include "symbolic/ExprKinds.def"
  }
  return "?";
}

int kindArity(Kind k) {
  switch (k) {
#define QDOT_EXPR_KIND(K, A, S) \
  case Kind::K:                 \
    return A;
#include "symbolic/ExprKinds.def"
  }
  return 0;
}

namespace {

uint64_t mix(uint64_t h, uint64_t v) {
  h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
  h ^= h >> 31;
  h *= 0xBF58476D1CE4E5B9ull;
  return h ^ (h >> 29);
}

void computeDerived(Node& n) {
  uint64_t h = mix(static_cast<uint64_t>(n.kind) + 1, n.symbolId);
  h = mix(h, numberBits(n.value));
  uint64_t mask = n.kind == Kind::Symbol ? symbolBit(&n) : 0;
  uint32_t depth = 0;
  for (Expr a : n.args) {
    h = mix(h, a->hash);
    mask |= a->symbolMask;
    depth = std::max(depth, a->depth + 1);
  }
  for (double c : n.coefs) h = mix(h, numberBits(c));
  for (Expr e : n.exps) {
    h = mix(h, e->hash);
    mask |= e->symbolMask;
    depth = std::max(depth, e->depth + 1);
  }
  n.hash = h;
  n.symbolMask = mask;
  n.depth = depth;
}

bool shallowEqual(const Node& a, const Node& b) {
  return a.kind == b.kind && a.symbolId == b.symbolId &&
         numberBits(a.value) == numberBits(b.value) && a.args == b.args && a.exps == b.exps &&
         a.coefs.size() == b.coefs.size() &&
         std::equal(a.coefs.begin(), a.coefs.end(), b.coefs.begin(),
                    [](double x, double y) { return numberBits(x) == numberBits(y); });
}

}  // namespace

Expr Context::Impl::intern(Node&& n) {
  n.value = normalizeNumber(n.value);
  for (double& c : n.coefs) c = normalizeNumber(c);
  computeDerived(n);
  if ((tableUsed + 1) * 2 > table.size()) growTable();
  size_t mask = table.size() - 1;
  size_t i = n.hash & mask;
  for (; table[i].node; i = (i + 1) & mask)  // the stored hash spares loading non-matching nodes
    if (table[i].hash == n.hash && shallowEqual(*table[i].node, n)) return table[i].node;
  nodes.push_back(std::move(n));
  table[i] = {nodes.back().hash, &nodes.back()};
  ++tableUsed;
  return table[i].node;
}

void Context::Impl::growTable() {
  std::vector<TableSlot> old(table.empty() ? 1024 : table.size() * 2);
  old.swap(table);
  size_t mask = table.size() - 1;
  for (const TableSlot& s : old) {
    if (!s.node) continue;
    size_t i = s.hash & mask;
    while (table[i].node) i = (i + 1) & mask;
    table[i] = s;
  }
}

Expr Context::Impl::makeMul(double coef, std::vector<Expr>&& bases, std::vector<Expr>&& exps) {
  if (coef == 0.0) return ctx.zero();
  if (bases.empty()) return ctx.constant(coef);
  if (bases.size() == 1 && coef == 1.0) return exps[0]->isOne() ? bases[0] : ctx.pow(bases[0], exps[0]);
  Node n{};
  n.kind = Kind::Mul;
  n.value = coef;
  n.args = std::move(bases);
  n.exps = std::move(exps);
  return intern(std::move(n));
}

Context::Context() : impl_(std::make_unique<Impl>(*this)) {
  zero_ = constant(0.0);
  one_ = constant(1.0);
}

Context::~Context() = default;

Expr Context::constant(double v) {
  Node n{};
  n.kind = Kind::Constant;
  n.value = v;
  return impl_->intern(std::move(n));
}

Expr Context::symbol(std::string_view name) {
  if (Expr s = findSymbol(name)) return s;
  Node n{};
  n.kind = Kind::Symbol;
  n.symbolId = static_cast<uint32_t>(impl_->symbols.size());
  Expr s = impl_->intern(std::move(n));
  impl_->symbols.push_back(s);
  impl_->symbolNames.emplace_back(name);
  impl_->symbolsByName.emplace(std::string(name), s);
  return s;
}

Expr Context::findSymbol(std::string_view name) const {
  auto it = impl_->symbolsByName.find(std::string(name));
  return it == impl_->symbolsByName.end() ? nullptr : it->second;
}

const std::string& Context::symbolName(Expr s) const {
  if (!s || !s->isSymbol() || s->symbolId >= impl_->symbolNames.size() || impl_->symbols[s->symbolId] != s)
    throw std::invalid_argument("symbolName: not a symbol of this Context");
  return impl_->symbolNames[s->symbolId];
}

size_t Context::symbolCount() const { return impl_->symbols.size(); }

size_t Context::nodeCount() const { return impl_->nodes.size(); }

}  // namespace qdot::sym
