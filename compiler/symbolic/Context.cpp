// The Context: node arena, hash-consing (intern) table, constants and symbols.
// Every node is created through Impl::intern, which computes the structural hash, the symbol mask
// and the depth from the (already built) children and returns the existing node when one is equal;
// only a new node is copied into the arena (node and operands), so a lookup that hits allocates nothing.
// Symbols are the exception: unique by name, they are found through the name table and never enter
// the intern table (a large model has millions; the table would only grow and rehash for them).
#include <algorithm>
#include <bit>
#include <charconv>
#include <cstring>
#include <optional>
#include <cstddef>
#include <functional>
#include <new>
#include <type_traits>
#include <utility>
#include <stdexcept>

#include "support/Assert.h"
#include "qdot/two_halves.hpp"
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

void computeDerived(NodeKey& n) {
  uint64_t h = mix(static_cast<uint64_t>(n.kind) + 1, n.symbolId);
  h = mix(h, numberBits(n.value));
  uint64_t mask = n.kind == Kind::Symbol ? uint64_t{1} << (n.symbolId % 64) : 0;
  uint32_t depth = 0;
  for (Expr a : n.args) {
    h = mix(h, a->hash);
    mask |= a->symbolMask;
    depth = std::max<uint32_t>(depth, a->depth + 1);
  }
  for (double c : n.coefs) h = mix(h, numberBits(c));
  for (Expr e : n.exps) {
    h = mix(h, e->hash);
    mask |= e->symbolMask;
    depth = std::max<uint32_t>(depth, e->depth + 1);
  }
  n.hash = h;
  n.symbolMask = mask;
  n.depth = std::min(depth, Node::kMaxDepth);
}

// What computeDerived gives a symbol's node, without a NodeKey (symbolArray makes millions).
uint64_t symbolHash(uint32_t id) { return mix(mix(static_cast<uint64_t>(Kind::Symbol) + 1, id), numberBits(0.0)); }

// The names prefix[i,j,…]suffix of a shape's points in row-major order, advanced in place: the
// last subscript's digits count up as text, and the whole name is written again only when that
// subscript wraps or gains a digit (a few times per array).
class SubscriptedNames {
 public:
  /// From the point `first` (0-based, row-major) on.
  SubscriptedNames(std::string_view prefix, std::span<const int> shape, std::string_view suffix, size_t first = 0)
      : prefix_(prefix), suffix_(suffix), shape_(shape), index_(shape.size(), 1) {
    for (size_t d = index_.size(); d-- > 0; first /= static_cast<size_t>(shape_[d]))
      index_[d] = 1 + static_cast<int>(first % static_cast<size_t>(shape_[d]));
    write();
  }
  /// The most characters a name of the shape takes.
  static size_t longest(std::string_view prefix, std::span<const int> shape, std::string_view suffix) {
    size_t chars = prefix.size() + suffix.size() + 1;
    char digits[16];
    for (int n : shape) chars += 1 + static_cast<size_t>(std::to_chars(digits, digits + sizeof digits, n).ptr - digits);
    return chars;
  }
  std::string_view current() const { return name_; }
  void advance() {
    if (index_.empty()) return;
    size_t d = index_.size() - 1;
    if (++index_[d] <= shape_[d] && countUpLastDigits()) return;
    while (index_[d] > shape_[d] && d > 0) index_[d] = 1, ++index_[--d];
    write();
  }

 private:
  bool countUpLastDigits() {
    for (size_t i = lastDigitsEnd_; i-- > lastDigitsBegin_;) {
      if (name_[i] != '9') return ++name_[i], true;
      name_[i] = '0';
    }
    return false;  // 99… → 100…: one digit more
  }
  void write() {
    name_.assign(prefix_);
    char digits[16];
    for (size_t d = 0; d < index_.size(); ++d) {
      name_ += d ? ',' : '[';
      lastDigitsBegin_ = name_.size();
      name_.append(digits, std::to_chars(digits, digits + sizeof digits, index_[d]).ptr);
    }
    lastDigitsEnd_ = name_.size();
    name_ += ']';
    name_ += suffix_;
  }
  std::string_view prefix_, suffix_;
  std::span<const int> shape_;
  std::vector<int> index_;
  std::string name_;
  size_t lastDigitsBegin_ = 0, lastDigitsEnd_ = 0;
};

template <class T>
bool sameElements(std::span<const T> a, std::span<const T> b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// Numbers compare by bit pattern (they are normalized, so -0 and NaN payloads cannot differ).
bool shallowEqual(const Node& a, const NodeKey& b) {
  return a.kind == b.kind && a.symbolId == b.symbolId && numberBits(a.value) == numberBits(b.value) &&
         sameElements(a.args, b.args) && sameElements(a.exps(), b.exps) && sameElements(a.coefs(), b.coefs);
}

}  // namespace

Expr Context::Impl::intern(NodeKey& key) {
  key.value = normalizeNumber(key.value);
  computeDerived(key);
  if ((tableCount + 1) * 2 > tableSize) resizeTable(tableSize ? 2 * tableSize : 1024);
  size_t mask = tableSize - 1;
  size_t i = key.hash & mask;
  for (; table[i].node; i = (i + 1) & mask)  // the stored hash spares loading non-matching nodes
    if (table[i].hash == key.hash && shallowEqual(*table[i].node, key)) return table[i].node;
  table[i] = {key.hash, store(key)};
  ++tableCount;
  return table[i].node;
}

// Copies the node into the arena with its operands right behind it (one allocation, one or two
// cache lines for a small node): the args, then a Mul's exponents or an Add's coefficients (Node's
// exps() and coefs() find them there).
Expr Context::Impl::store(const NodeKey& key) {
  size_t nArgs = key.args.size();
  QDOT_ASSERT(key.exps.size() == (key.kind == Kind::Mul ? nArgs : 0), "a Mul has one exponent per base, nothing else has any");
  QDOT_ASSERT(key.coefs.size() == (key.kind == Kind::Add ? nArgs : 0), "an Add has one coefficient per term, nothing else has any");
  static_assert(std::is_trivially_destructible_v<Node> && sizeof(Node) == 48 && sizeof(Node) % alignof(Expr) == 0 &&
                alignof(Expr) == alignof(double) && alignof(Node) >= alignof(Expr) && sizeof(Expr) == sizeof(double));
  size_t operands = nArgs + key.exps.size() + key.coefs.size();
  void* bytes = arena.allocateBytes(sizeof(Node) + operands * sizeof(Expr), alignof(Node));
  auto* kids = reinterpret_cast<Expr*>(static_cast<std::byte*>(bytes) + sizeof(Node));
  std::copy(key.args.begin(), key.args.end(), kids);
  std::copy(key.exps.begin(), key.exps.end(), kids + nArgs);
  std::copy(key.coefs.begin(), key.coefs.end(), reinterpret_cast<double*>(kids + nArgs));
  Node* n = new (bytes) Node{.kind = key.kind, .depth = key.depth, .symbolId = key.symbolId, .hash = key.hash,
                             .symbolMask = key.symbolMask, .value = key.value, .args = {kids, nArgs}};
  ++nodeCount;
  return n;
}

void Context::Impl::resizeTable(size_t size) {
  size_t oldSize = std::exchange(tableSize, size);
  auto old = std::exchange(table, allocateLarge<TableSlot>(tableSize));
  std::fill_n(table.get(), tableSize, TableSlot{});
  size_t mask = tableSize - 1;
  for (size_t k = 0; k < oldSize; ++k) {
    if (!old[k].node) continue;
    size_t i = old[k].hash & mask;
    while (table[i].node) i = (i + 1) & mask;
    table[i] = old[k];
  }
}

// Each table stays at most half full (the symbols by id grow by chunks and need no reserve).
void Context::Impl::reserve(size_t moreSymbols, size_t moreNodes) {
  size_t nodes = tableCount + moreNodes;
  if (nodes * 2 > tableSize) resizeTable(std::bit_ceil(std::max<size_t>(nodes * 2, 1024)));
  // the name table holds the symbols not in blocks (symbolArray's are found without it)
  size_t inTable = symbols.size() - inBlocks + moreSymbols;
  if (inTable * 2 > nameTableSize) resizeSymbolsByName(std::bit_ceil(std::max<size_t>(inTable * 2, 64)));
}

Expr Context::Impl::makeMul(double coef, std::span<const Expr> bases, std::span<const Expr> exps) {
  if (coef == 0.0) return ctx.zero();
  if (bases.empty()) return ctx.constant(coef);
  if (bases.size() == 1 && coef == 1.0) return exps[0]->isOne() ? bases[0] : ctx.pow(bases[0], exps[0]);
  NodeKey n{.kind = Kind::Mul, .value = coef, .args = bases, .exps = exps};
  return intern(n);
}

Context::Context() : impl_(std::make_unique<Impl>(*this)) {
  zero_ = constant(0.0);
  one_ = constant(1.0);
}

Context::~Context() = default;

void Context::clear() {
  impl_ = std::make_unique<Impl>(*this);
  zero_ = constant(0.0);
  one_ = constant(1.0);
}

// The key a number is interned under (normalized: -0 and NaN payloads are one node each).
namespace {
NodeKey constantKey(double v) { return {.kind = Kind::Constant, .value = normalizeNumber(v)}; }
}  // namespace

// Numbers recur constantly (0, 1, 2, -1, 0.5, model parameters): a direct-mapped cache in front
// of the intern table answers most of them without hashing the node.
Expr Context::constant(double v) {
  NodeKey n = constantKey(v);
  uint64_t bits = numberBits(n.value);
  auto& slot = impl_->recentConstants[(bits * 0x9E3779B97F4A7C15ull) >> (64 - Impl::kConstantCacheBits)];
  if (slot.node && slot.bits == bits) return slot.node;
  slot = {bits, impl_->intern(n)};
  return slot.node;
}

std::vector<Expr> Context::constants(std::span<const double> values) {
  constexpr size_t kAhead = 16;
  impl_->reserve(0, values.size());  // the table does not move while it is read ahead
  std::vector<uint64_t> hashes(values.size());
  for (size_t i = 0; i < values.size(); ++i) {
    NodeKey key = constantKey(values[i]);
    computeDerived(key);
    hashes[i] = key.hash;
  }
  std::vector<Expr> out;
  out.reserve(values.size());
  size_t mask = impl_->tableSize - 1;
  for (size_t i = 0; i < values.size(); ++i) {
    if (i + kAhead < values.size()) __builtin_prefetch(&impl_->table[hashes[i + kAhead] & mask]);
    NodeKey key = constantKey(values[i]);
    out.push_back(impl_->intern(key));
  }
  return out;
}

void Context::reserve(size_t symbols, size_t nodes) { impl_->reserve(symbols, nodes); }

Expr Context::symbol(std::string_view name) {
  impl_->reserve(1, 0);
  return impl_->symbol(name, std::hash<std::string_view>{}(name));
}

// Hashes every name first; then, while one name is looked up, the slot of a name some places
// further on is already being loaded (the table is reserved up front, so it does not move).
std::vector<Expr> Context::symbols(std::span<const std::string_view> names) {
  constexpr size_t kAhead = 16;
  impl_->reserve(names.size(), 0);
  std::vector<uint64_t> hashes(names.size());
  for (size_t i = 0; i < names.size(); ++i) hashes[i] = std::hash<std::string_view>{}(names[i]);
  std::vector<Expr> out;
  out.reserve(names.size());
  size_t mask = impl_->nameTableSize - 1;
  for (size_t i = 0; i < names.size(); ++i) {
    if (i + kAhead < names.size()) __builtin_prefetch(&impl_->symbolsByName[hashes[i + kAhead] & mask]);
    out.push_back(impl_->symbol(names[i], hashes[i]));
  }
  return out;
}

// A name of an array element is its family (what precedes the last `[` and follows the `]` after
// it) and its subscripts; symbols of a family made by symbolArray are found through both.
namespace {
struct SubscriptedName {
  std::string_view prefix, subscripts, suffix;
};
std::optional<SubscriptedName> splitSubscripts(std::string_view name) {
  size_t open = name.rfind('[');
  if (open == std::string_view::npos) return std::nullopt;
  size_t close = name.find(']', open);
  if (close == std::string_view::npos) return std::nullopt;
  return SubscriptedName{name.substr(0, open), name.substr(open + 1, close - open - 1), name.substr(close + 1)};
}
uint64_t familyHash(std::string_view prefix, std::string_view suffix) {
  return mix(std::hash<std::string_view>{}(prefix), std::hash<std::string_view>{}(suffix));
}
// The row-major index of `i,j,…` (1-based, decimal) in shape, or -1 if not one of its elements.
long elementIndex(std::string_view subscripts, std::span<const int> shape) {
  long k = 0;
  size_t pos = 0;
  for (size_t d = 0; d < shape.size(); ++d) {
    size_t end = d + 1 < shape.size() ? subscripts.find(',', pos) : subscripts.size();
    if (end == std::string_view::npos || end == pos || end - pos > 10) return -1;
    long v = 0;
    for (char c : subscripts.substr(pos, end - pos)) {
      if (c < '0' || c > '9') return -1;
      v = 10 * v + (c - '0');
    }
    if (v < 1 || v > shape[d]) return -1;
    k = k * shape[d] + (v - 1);
    pos = end + 1;
  }
  return k;
}
}  // namespace

Expr Context::Impl::symbol(std::string_view name, uint64_t hash) {
  NameSlot& slot = nameSlot(name, hash);
  if (slot.entry) return symbols[slot.entry - 1];
  if (!blocks.empty())
    if (Expr s = findInBlocks(name)) return s;
  if (auto parts = splitSubscripts(name)) {
    uint64_t family = familyHash(parts->prefix, parts->suffix);
    if (tableFamilies.empty()) tableFamilies.resize(kFamilyBits / 64);
    tableFamilies[family % kFamilyBits / 64] |= uint64_t{1} << (family % 64);
  }
  Expr s = newSymbol(name);
  slot = {static_cast<uint32_t>(hash), s->symbolId + 1};
  return s;
}

// The stored name is compared at the end, so `x[01]` or `x[1, 2]` find nothing (as in the table).
Expr Context::Impl::findInBlocks(std::string_view name) const {
  auto parts = splitSubscripts(name);
  if (!parts) return nullptr;
  auto it = blockByFamily.find(familyHash(parts->prefix, parts->suffix));
  if (it == blockByFamily.end()) return nullptr;
  const SymbolBlock& b = blocks[it->second];
  if (b.prefix != parts->prefix || b.suffix != parts->suffix) return nullptr;
  long k = elementIndex(parts->subscripts, b.shape);
  if (k < 0) return nullptr;
  uint32_t id = b.first + static_cast<uint32_t>(k);
  return symbolNames[id] == name ? symbols[id] : nullptr;
}

const Context::Impl::SymbolBlock* Context::Impl::blockOf(uint32_t id) const {
  auto it = std::upper_bound(blocks.begin(), blocks.end(), id, [](uint32_t i, const SymbolBlock& b) { return i < b.first; });
  if (it == blocks.begin()) return nullptr;
  --it;
  return id < it->first + it->count ? &*it : nullptr;
}

std::string_view Context::Impl::storeName(std::string_view name) {
  if (name.empty()) return {};
  char* chars = arena.allocate<char>(name.size());
  std::memcpy(chars, name.data(), name.size());
  return {chars, name.size()};
}

Expr Context::findSymbol(std::string_view name) const {
  if (impl_->nameTableSize != 0) {
    const Impl::NameSlot& slot = impl_->nameSlot(name, std::hash<std::string_view>{}(name));
    if (slot.entry) return impl_->symbols[slot.entry - 1];
  }
  return impl_->blocks.empty() ? nullptr : impl_->findInBlocks(name);
}

// The names are written straight into the name store and the nodes made in id order: no hashing
// of names, no name-table slots (a million-element array's three families are 3·10⁶ of each).
std::vector<Expr> Context::symbolArray(std::string_view prefix, std::span<const int> shape, std::string_view suffix) {
  size_t count = 1;
  for (int n : shape) count *= n > 0 ? static_cast<size_t>(n) : 0;
  if (count == 0) return {};
  uint64_t family = familyHash(prefix, suffix);
  bool asBlock = !shape.empty() && suffix.find_first_of("[]") == std::string_view::npos &&
                 impl_->symbols.size() + count < UINT32_MAX && impl_->familyFree(family);
  SubscriptedNames names(prefix, shape, suffix);
  if (!asBlock) {
    std::vector<std::string> owned;
    for (size_t k = 0; k < count; ++k, names.advance()) owned.emplace_back(names.current());
    std::vector<std::string_view> views(owned.begin(), owned.end());
    return symbols(views);
  }
  Impl& im = *impl_;
  auto first = static_cast<uint32_t>(im.symbols.size());
  im.blockByFamily.emplace(family, static_cast<uint32_t>(im.blocks.size()));
  im.blocks.push_back({first, static_cast<uint32_t>(count), std::string(prefix), std::string(suffix), {shape.begin(), shape.end()}});
  im.inBlocks += count;
  // The nodes in one piece of the arena, as newSymbol makes each (no intern table); the names in
  // another, each at most `longest` characters.
  Node* nodes = im.arena.allocate<Node>(count);
  size_t longest = SubscriptedNames::longest(prefix, shape, suffix);
  char* chars = im.arena.allocate<char>(count * longest);
  im.symbols.grow(count);
  im.symbolNames.grow(count);
  std::vector<Expr> out(count);
  // Points [begin, end): everything a point writes is its own (its node, its slots, its part of
  // the characters), so two threads can make two parts.
  auto make = [&](size_t begin, size_t end) {
    SubscriptedNames names(prefix, shape, suffix, begin);
    char* next = chars + begin * longest;
    for (size_t k = begin; k < end; ++k, names.advance()) {
      uint32_t id = first + static_cast<uint32_t>(k);
      Expr s = new (nodes + k) Node{.kind = Kind::Symbol, .depth = 0, .symbolId = id, .hash = symbolHash(id),
                                    .symbolMask = uint64_t{1} << (id % 64)};
      std::string_view name = names.current();
      std::memcpy(next, name.data(), name.size());
      im.symbols.at(id) = s;
      im.symbolNames.at(id) = {next, name.size()};
      next += name.size();
      out[k] = s;
    }
  };
  // A 10⁶-element array of symbols is 0.05 s of the compile on one thread.
  inTwoHalves(count, make);
  im.nodeCount += count;
  return out;
}

std::optional<Context::SymbolArrayInfo> Context::symbolArrayOf(Expr s) const {
  if (!s || !s->isSymbol() || impl_->blocks.empty()) return std::nullopt;
  const Impl::SymbolBlock* b = impl_->blockOf(s->symbolId);
  if (!b) return std::nullopt;
  return SymbolArrayInfo{b->prefix, b->suffix, b->shape, b->first};
}

size_t Context::wholeSymbolArrayAt(std::span<const Expr> symbols) const {
  if (symbols.empty()) return 0;
  auto array = symbolArrayOf(symbols[0]);
  if (!array || array->first != symbols[0]->symbolId) return 0;
  size_t count = 1;
  for (int n : array->shape) count *= static_cast<size_t>(n);
  if (count > symbols.size()) return 0;
  for (size_t j = 0; j < count; ++j)
    if (!symbols[j]->isSymbol() || symbols[j]->symbolId != array->first + j) return 0;
  return count;
}

std::vector<Expr> Context::symbolArrayAround(Expr first, std::string_view before, std::string_view after) {
  auto array = symbolArrayOf(first);
  if (!array || array->first != first->symbolId)
    throw std::logic_error("symbolArrayAround: not the first element of a symbol array");
  // Copies first: making the new block may move the strings and shapes the views point into.
  std::string prefix = std::string(before) + std::string(array->prefix);
  std::string suffix = std::string(array->suffix) + std::string(after);
  std::vector<int> shape(array->shape.begin(), array->shape.end());
  return symbolArray(prefix, shape, suffix);
}

// Linear probing; a slot whose tag differs cannot hold the name, so most misses compare no string.
Context::Impl::NameSlot& Context::Impl::nameSlot(std::string_view name, uint64_t hash) {
  size_t mask = nameTableSize - 1;
  auto tag = static_cast<uint32_t>(hash);
  for (size_t i = hash & mask;; i = (i + 1) & mask) {
    NameSlot& slot = symbolsByName[i];
    if (slot.entry == 0 || (slot.tag == tag && symbolNames[slot.entry - 1] == name)) return slot;
  }
}

Expr Context::Impl::newSymbol(std::string_view name) {
  NodeKey n{.kind = Kind::Symbol, .symbolId = static_cast<uint32_t>(symbols.size())};
  computeDerived(n);
  Expr s = store(n);
  symbols.push_back(s);
  symbolNames.push_back(storeName(name));
  return s;
}

// A tag is the low half of the name's hash, so it places its slot in any table of up to 2^32 slots.
void Context::Impl::resizeSymbolsByName(size_t size) {
  size_t oldSize = std::exchange(nameTableSize, size);
  auto old = std::exchange(symbolsByName, allocateLarge<NameSlot>(size));
  std::fill_n(symbolsByName.get(), size, NameSlot{0, 0});
  size_t mask = size - 1;
  for (size_t k = 0; k < oldSize; ++k) {
    if (!old[k].entry) continue;
    size_t i = old[k].tag & mask;
    while (symbolsByName[i].entry) i = (i + 1) & mask;
    symbolsByName[i] = old[k];
  }
}

std::string_view Context::symbolName(Expr s) const {
  if (!s || !s->isSymbol() || s->symbolId >= impl_->symbolNames.size() || impl_->symbols[s->symbolId] != s)
    throw std::invalid_argument("symbolName: not a symbol of this Context");
  return impl_->symbolNames[s->symbolId];
}

size_t Context::symbolCount() const { return impl_->symbols.size(); }

size_t Context::nodeCount() const { return impl_->nodeCount; }

}  // namespace qdot::sym
