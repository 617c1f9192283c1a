// PartialDerivatives: one sparse forward pass. Every node below a root that contains listed symbols
// gets, once, the sorted positions of those symbols (its set) and its derivative with respect to
// each of them. A node's set is the union of its children's; for each symbol in it, the derivative
// comes from the rule of Derivative.cpp applied to just the children containing that symbol, so no
// node is looked at for a symbol it does not contain and no memo lookup is needed per symbol.
// Context::diff would give the same nodes (the rules skip zero derivatives alike) but, once more than
// 64 symbols alias the mask's bits, visits for every symbol every node sharing its bit.
#include <bit>
#include <stdexcept>
#include <utility>

#include "symbolic/DerivativeRules.h"

namespace qdot::sym {

namespace {

constexpr uint32_t kNotListed = UINT32_MAX;

uint64_t bitsOf(Expr e) { return reinterpret_cast<uintptr_t>(e); }

// Results of the rules of linear nodes, keyed by all they depend on: a sum's derivative by the
// coefficients and derivatives of its moving terms, a product's with one moving factor b^1 by the
// other factors and db. In a kinematic chain, the partial sums x_k = x_(k-1) + l sin(θ_k) make many
// nodes differ only in which partial sum they hold, while the sums' derivatives with respect to a
// θ_j they share are one node: those nodes then have equal keys, and all but the first skip the
// builders (and their intern lookups). Keys are short strings of words, kept in the slot when they
// fit (a lookup is then one cache miss); open addressing.
template <size_t kInline>
class RuleCache {
 public:
  using Key = std::span<const uint64_t>;
  const Expr* find(Key key) const {
    if (slots_.empty()) return nullptr;
    uint32_t h = hash(key);
    for (size_t i = h & mask(); slots_[i].value; i = (i + 1) & mask())
      if (slots_[i].hash == h && same(slots_[i], key)) return &slots_[i].value;
    return nullptr;
  }
  void insert(Key key, Expr value) {
    if ((size_ + 1) * 2 > slots_.size()) grow();
    Slot slot{hash(key), static_cast<uint32_t>(key.size()), value, {}};
    if (key.size() <= kInline) {
      std::copy(key.begin(), key.end(), slot.words);
    } else {
      slot.words[0] = pool_.size();
      pool_.insert(pool_.end(), key.begin(), key.end());
    }
    place(slot);
    ++size_;
  }

 private:
  struct Slot {
    uint32_t hash = 0, size = 0;
    Expr value = nullptr;
    uint64_t words[kInline];  // the key, or for a longer one its offset in pool_
  };
  static uint32_t hash(Key key) {
    uint64_t h = key.size();
    for (uint64_t w : key) h = (h ^ w ^ (w >> 29)) * 0x9E3779B97F4A7C15ull;
    return static_cast<uint32_t>(h ^ (h >> 32));
  }
  bool same(const Slot& s, Key key) const {
    if (s.size != key.size()) return false;
    const uint64_t* w = key.size() <= kInline ? s.words : pool_.data() + s.words[0];
    for (size_t i = 0; i < key.size(); ++i)
      if (w[i] != key[i]) return false;
    return true;
  }
  size_t mask() const { return slots_.size() - 1; }
  void place(const Slot& slot) {
    size_t i = slot.hash & mask();
    while (slots_[i].value) i = (i + 1) & mask();
    slots_[i] = slot;
  }
  void grow() {
    std::vector<Slot> old(slots_.empty() ? 1024 : 2 * slots_.size());
    old.swap(slots_);
    for (const Slot& s : old)
      if (s.value) place(s);
  }

  std::vector<Slot> slots_;
  std::vector<uint64_t> pool_;
  size_t size_ = 0;
};

}  // namespace

struct PartialDerivatives::Impl {
  Impl(Context& c, std::span<const Expr> list);

  // A node's set: positions_[set, set + size); its derivatives: derivs_[deriv, deriv + size).
  struct Info {
    uint32_t set = 0, size = 0, deriv = 0;
  };
  // One child's derivative with respect to one listed symbol.
  struct Occurrence {
    uint32_t position, kid;
    Expr d;
  };

  Info infoOf(Expr e);
  Info known(Expr c) const;
  void computeBelow(Expr root);
  Info compute(Expr n);
  Expr derivative(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d);
  bool sumKey(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d);
  bool productKey(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d);
  // A child with listed symbols, as gather() reads it.
  struct Source {
    Info info;
    uint32_t kid;
  };
  static constexpr size_t kMergeLimit = 8;
  void gather(Expr n);
  void append(const Source& src);
  void sortOccurrences();

  Context& ctx;
  std::vector<Expr> symbols;
  std::vector<uint32_t> positionOf;  // by symbolId
  uint64_t mask = 0;                 // bits of every listed symbol
  NodeMap<Info> info;                // done nodes (not symbols) whose mask meets `mask`
  std::vector<uint32_t> positions;   // starts with 0, 1, ...: the set of the symbol at each position
  std::vector<Expr> derivs;          // starts with a 1 per symbol: ∂s/∂s
  // Scratch of compute(): the children's occurrences; with `shared`, the node's set is the slice
  // every child with a non-empty set has (so it is not stored again).
  std::vector<Occurrence> occurrences;
  bool shared = false;
  Info sharedSet;
  std::vector<Source> sources;
  std::vector<uint32_t> cursors;
  std::vector<Occurrence> sorted;
  std::vector<uint32_t> bucket, distinct;  // sortOccurrences: per symbol count, then next slot
  std::vector<uint32_t> runKids;
  std::vector<Expr> runDerivs;
  RuleCache<4> sums;               // (coefficient, derivative) of each moving term: one or two terms inline
  RuleCache<2> products;           // (other factors, db) inline; the rarer 4-word keys in the pool
  std::vector<uint64_t> key;       // scratch of sumKey / productKey
  std::vector<Expr> otherFactors;  // by factor of the node in compute(): the product of the others
  std::vector<Expr> scratch;
};

PartialDerivatives::Impl::Impl(Context& c, std::span<const Expr> list) : ctx(c), symbols(list.begin(), list.end()) {
  for (uint32_t k = 0; k < symbols.size(); ++k) {
    Expr s = symbols[k];
    if (!s || !s->isSymbol()) throw std::invalid_argument("PartialDerivatives: not a symbol");
    if (positionOf.size() <= s->symbolId) positionOf.resize(s->symbolId + 1, kNotListed);
    if (positionOf[s->symbolId] != kNotListed) throw std::invalid_argument("PartialDerivatives: symbol listed twice");
    positionOf[s->symbolId] = k;
    mask |= symbolBit(s);
    positions.push_back(k);
    derivs.push_back(ctx.one());
  }
}

// A symbol's set and derivative come from the first entries of the pools: symbols, the most shared
// nodes, need no entry in `info`.
PartialDerivatives::Impl::Info PartialDerivatives::Impl::known(Expr c) const {
  if (!c->isSymbol()) return *info.find(c);
  uint32_t k = c->symbolId < positionOf.size() ? positionOf[c->symbolId] : kNotListed;
  return k == kNotListed ? Info{} : Info{k, 1, k};
}

PartialDerivatives::Impl::Info PartialDerivatives::Impl::infoOf(Expr e) {
  if (!(e->symbolMask & mask)) return {};
  if (!e->isSymbol() && !info.find(e)) computeBelow(e);
  return known(e);
}

// Post-order over the nodes below root that may hold a listed symbol and are not done yet; a child
// is finished before its next sibling is looked at (as in the memoised walk).
void PartialDerivatives::Impl::computeBelow(Expr root) {
  struct Frame {
    Expr node;
    uint32_t next;
  };
  SmallVec<Frame, 16> stack;
  stack.push_back({root, 0});
  while (!stack.empty()) {
    Frame& f = stack.back();
    if (f.next == 0) prefetchChildren(f.node, info);
    if (f.next < childCount(f.node)) {
      Expr c = child(f.node, f.next++);
      if ((c->symbolMask & mask) && !c->isSymbol() && !info.find(c)) stack.push_back({c, 0});
    } else {
      Expr n = f.node;
      stack.pop_back();
      Info done = compute(n);
      info.insert(n, done);
    }
  }
}

// The children's (symbol, child, derivative) triples, ordered by symbol, then child. Each child's
// set is sorted already: a few children are merged, many are bucketed (sortOccurrences).
void PartialDerivatives::Impl::gather(Expr n) {
  occurrences.clear();
  sources.clear();
  for (uint32_t i = 0; i < childCount(n); ++i) {
    Expr c = child(n, i);
    if (!(c->symbolMask & mask)) continue;
    Info ci = known(c);
    if (ci.size != 0) sources.push_back({ci, i});
  }
  shared = !sources.empty();
  for (const Source& src : sources)
    shared = shared && src.info.set == sources[0].info.set && src.info.size == sources[0].info.size;
  if (shared) sharedSet = sources[0].info;
  if (sources.size() > kMergeLimit) {
    for (const Source& src : sources) append(src);
    return sortOccurrences();
  }
  cursors.assign(sources.size(), 0);
  for (;;) {  // k-way merge; ties go to the first child
    size_t best = SIZE_MAX;
    uint32_t bestPosition = UINT32_MAX;
    for (size_t k = 0; k < sources.size(); ++k)
      if (cursors[k] < sources[k].info.size && positions[sources[k].info.set + cursors[k]] < bestPosition)
        best = k, bestPosition = positions[sources[k].info.set + cursors[k]];
    if (best == SIZE_MAX) return;
    uint32_t k = cursors[best]++;
    occurrences.push_back({bestPosition, sources[best].kid, derivs[sources[best].info.deriv + k]});
  }
}

void PartialDerivatives::Impl::append(const Source& src) {
  for (uint32_t k = 0; k < src.info.size; ++k)
    occurrences.push_back({positions[src.info.set + k], src.kid, derivs[src.info.deriv + k]});
}

// By symbol, then child (they were gathered child by child). A wide node's (a residual with a term
// per link of a chain) are bucketed by symbol: a stable counting sort costing O(occurrences +
// distinct symbols · log).
void PartialDerivatives::Impl::sortOccurrences() {
  if (bucket.empty()) bucket.assign(symbols.size(), 0);
  distinct.clear();
  for (const Occurrence& o : occurrences)
    if (bucket[o.position]++ == 0) distinct.push_back(o.position);
  std::sort(distinct.begin(), distinct.end());
  uint32_t offset = 0;
  for (uint32_t p : distinct) offset += std::exchange(bucket[p], offset);
  sorted.resize(occurrences.size());
  for (const Occurrence& o : occurrences) sorted[bucket[o.position]++] = o;
  for (uint32_t p : distinct) bucket[p] = 0;
  occurrences.swap(sorted);
}

// For each symbol of n (a run of occurrences), the rule over the children containing it.
PartialDerivatives::Impl::Info PartialDerivatives::Impl::compute(Expr n) {
  gather(n);
  if (occurrences.empty()) return {};
  otherFactors.assign(n->kind == Kind::Mul ? n->args.size() : 0, nullptr);
  Info r{shared ? sharedSet.set : static_cast<uint32_t>(positions.size()), 0, static_cast<uint32_t>(derivs.size())};
  for (size_t a = 0; a < occurrences.size();) {
    uint32_t position = occurrences[a].position;
    runKids.clear();
    runDerivs.clear();
    for (; a < occurrences.size() && occurrences[a].position == position; ++a) {
      runKids.push_back(occurrences[a].kid);
      runDerivs.push_back(occurrences[a].d);
    }
    Expr d = derivative(n, runKids, runDerivs);
    if (!shared) positions.push_back(position);
    derivs.push_back(d);
    ++r.size;
  }
  return r;
}

// The rule for n, whose children `kids` move with derivatives d; through the cache where n is linear.
Expr PartialDerivatives::Impl::derivative(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d) {
  auto cached = [&](auto& cache) {
    if (const Expr* known = cache.find(key)) return *known;
    Expr r = applyRule(Diff{.ctx = ctx, .node = n, .moving = kids, .movingD = d});
    cache.insert(key, r);
    return r;
  };
  if (n->kind == Kind::Add && sumKey(n, kids, d)) return cached(sums);
  if (n->kind == Kind::Mul && productKey(n, kids, d)) return cached(products);
  return applyRule(Diff{.ctx = ctx, .node = n, .moving = kids, .movingD = d});
}

// dAdd gives TermSum over the non-zero (coefficient, derivative) pairs in order: that is the key.
// Not worth it for one term with coefficient 1 (no builder) nor for long sums (a residual's: unique).
// Constants are interned like every node, so 0 and 1 are compared by address (on a cache hit most
// derivative nodes are not otherwise loaded).
bool PartialDerivatives::Impl::sumKey(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d) {
  key.clear();
  for (size_t k = 0; k < kids.size(); ++k)
    if (d[k] != ctx.zero()) key.push_back(std::bit_cast<uint64_t>(n->coefs()[kids[k]])), key.push_back(bitsOf(d[k]));
  size_t terms = key.size() / 2;
  bool plain = terms == 0 || (terms == 1 && key[0] == std::bit_cast<uint64_t>(1.0));
  return !plain && terms <= 16;
}

// dMul with one moving base b (exponent 1) builds coefficient · (other factors) · db. The other
// factors, with the coefficient, are one Mul node when there are two or more of them (interned once
// per node and factor: key (Q, db)), else spelled out (key of four words): the key is then exactly
// the builder's input.
bool PartialDerivatives::Impl::productKey(Expr n, std::span<const uint32_t> kids, std::span<const Expr> d) {
  size_t m = n->args.size();
  if (kids.size() != 1 || kids[0] >= m || n->exps()[kids[0]] != ctx.one() || d[0] == ctx.zero()) return false;
  size_t a = kids[0];
  if (m - 1 >= 2) {
    if (!otherFactors[a]) {
      scratch.clear();
      for (size_t j = 0; j < m; ++j)
        if (j != a) scratch.push_back(n->args[j]);
      for (size_t j = 0; j < m; ++j)
        if (j != a) scratch.push_back(n->exps()[j]);
      std::span<const Expr> all = scratch;
      otherFactors[a] = ctx.impl().makeMul(n->value, all.first(m - 1), all.subspan(m - 1));
    }
    key.assign(2, bitsOf(otherFactors[a]));
    key[1] = bitsOf(d[0]);
    return true;
  }
  key.resize(4);  // other base and exponent (or none), coefficient, db
  key[0] = m == 2 ? bitsOf(n->args[1 - a]) : 0;
  key[1] = m == 2 ? bitsOf(n->exps()[1 - a]) : 0;
  key[2] = std::bit_cast<uint64_t>(n->value);
  key[3] = bitsOf(d[0]);
  return true;
}

PartialDerivatives::PartialDerivatives(Context& ctx, std::span<const Expr> symbols)
    : impl_(std::make_unique<Impl>(ctx, symbols)) {}
PartialDerivatives::~PartialDerivatives() = default;

std::span<const uint32_t> PartialDerivatives::symbolsIn(Expr e) {
  Impl::Info i = impl_->infoOf(e);
  return {impl_->positions.data() + i.set, i.size};
}

std::span<const Expr> PartialDerivatives::gradient(Expr e) {
  Impl::Info i = impl_->infoOf(e);
  return {impl_->derivs.data() + i.deriv, i.size};
}

Expr PartialDerivatives::diff(Expr e, uint32_t position) {
  std::span<const uint32_t> set = symbolsIn(e);
  auto at = std::lower_bound(set.begin(), set.end(), position);
  return at != set.end() && *at == position ? gradient(e)[at - set.begin()] : impl_->ctx.zero();
}

}  // namespace qdot::sym
