// Internals of the symbolic Context shared by the rule files (not a public header).
// Holds the node arena and intern table, symbol names, derivative memos, the Add/Mul builders that
// produce canonical forms (on inline buffers: no heap for small operand lists), and small helpers
// for children access and iterative traversal.
#pragma once

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <unordered_map>
#include <vector>

#include "symbolic/Arena.h"
#include "symbolic/Expr.h"
#include "symbolic/NodeMap.h"
#include "symbolic/SmallVec.h"

namespace qdot::sym {

/// What a node is made from before it is interned: kind, value and operands, which may point into
/// temporary storage (a new node's are copied behind it). intern fills hash, symbolMask and depth.
struct NodeKey {
  Kind kind = Kind::Constant;
  uint32_t symbolId = 0;
  double value = 0;
  std::span<const Expr> args;
  std::span<const double> coefs;  ///< Add: one per term
  std::span<const Expr> exps;     ///< Mul: one per base
  uint64_t hash = 0, symbolMask = 0;
  uint32_t depth = 0;
};

// --- children: args followed by exps (one array in the arena) -------------------------------------

inline size_t childCount(Expr n) { return n->args.size() + n->exps().size(); }
inline std::span<const Expr> children(Expr n) { return {n->args.data(), childCount(n)}; }
inline Expr child(Expr n, size_t i) { return n->args.data()[i]; }
/// Starts loading a node and its operands (they follow the node in the arena).
inline void prefetchNode(Expr n) {
  __builtin_prefetch(n);
  __builtin_prefetch(reinterpret_cast<const char*>(n) + sizeof(Node));
}
/// Before walking n's children: starts loading each child and its entry in `map`.
template <class Map>
void prefetchChildren(Expr n, const Map& map) {
  for (Expr c : children(n)) {
    prefetchNode(c);
    map.prefetch(c);
  }
}

/// Arity from ExprKinds.def (-1 = n-ary).
int kindArity(Kind k);

/// Bit identifying a symbol in Node::symbolMask.
inline uint64_t symbolBit(Expr s) { return uint64_t{1} << (s->symbolId % 64); }

/// Canonical bit pattern of a double for hashing/equality (-0 -> 0, every NaN -> one NaN).
inline double normalizeNumber(double v) {
  if (v == 0.0) return 0.0;
  if (std::isnan(v)) return std::numeric_limits<double>::quiet_NaN();
  return v;
}
inline uint64_t numberBits(double v) {
  uint64_t b;
  std::memcpy(&b, &v, sizeof b);
  return b;
}
inline bool isIntegerValue(double v) { return std::isfinite(v) && std::floor(v) == v; }

/// Applies a non-arithmetic kind (Pow, functions, comparisons, logic, select) to numbers.
/// Shared by constant folding and evaluation so both agree bit for bit.
double applyKind(Kind k, double a, double b = 0.0, double c = 0.0);

// --- traversal ------------------------------------------------------------------------------------

/// Distinct nodes reachable from roots, children before parents, with each node's position.
/// Children of a node n are only visited if descend(n) is true (else n is visited as a leaf).
struct PostOrder {
  std::vector<Expr> order;
  NodeMap<uint32_t> index;
};
template <class Descend>
PostOrder postOrder(std::span<const Expr> roots, Descend&& descend) {
  PostOrder po;
  std::vector<std::pair<Expr, uint32_t>> stack;
  for (Expr root : roots) {
    if (!po.index.insert(root, 0).second) continue;
    stack.push_back({root, 0});
    while (!stack.empty()) {
      Expr n = stack.back().first;
      uint32_t i = stack.back().second;
      if (i < childCount(n) && descend(n)) {
        stack.back().second = i + 1;
        Expr c = child(n, i);
        if (po.index.insert(c, 0).second) stack.push_back({c, 0});
      } else {
        *po.index.find(n) = static_cast<uint32_t>(po.order.size());
        po.order.push_back(n);
        stack.pop_back();
      }
    }
  }
  return po;
}
inline PostOrder postOrder(std::span<const Expr> roots) {
  return postOrder(roots, [](Expr) { return true; });
}

/// A vector that grows by chunks and never moves what it holds: a Context with millions of symbols
/// adds one more without copying (and first touching twice as much) its tables by symbolId.
template <class T>
class ChunkedVector {
 public:
  static_assert(std::is_trivially_copyable_v<T>);
  size_t size() const { return size_; }
  const T& operator[](size_t i) const { return chunks_[i >> kBits][i & kMask]; }
  void push_back(const T& v) {
    if ((size_ >> kBits) == chunks_.size()) chunks_.push_back(std::make_unique_for_overwrite<T[]>(kChunk));
    chunks_[size_ >> kBits][size_ & kMask] = v;
    ++size_;
  }
  /// Room for `count` more elements, left unwritten: each is then written through at(), by any
  /// thread as long as no two write the same element.
  void grow(size_t count) {
    size_ += count;
    while (chunks_.size() << kBits < size_) chunks_.push_back(std::make_unique_for_overwrite<T[]>(kChunk));
  }
  T& at(size_t i) { return chunks_[i >> kBits][i & kMask]; }

 private:
  static constexpr size_t kBits = 12, kChunk = size_t{1} << kBits, kMask = kChunk - 1;
  std::vector<std::unique_ptr<T[]>> chunks_;
  size_t size_ = 0;
};

// --- the Context internals ------------------------------------------------------------------------

struct Context::Impl {
  explicit Impl(Context& c) : ctx(c) {}

  Context& ctx;
  Arena arena;                      ///< nodes and their operand arrays
  size_t nodeCount = 0;             ///< every node, symbols included
  size_t tableCount = 0;            ///< nodes in the intern table (not symbols: see newSymbol)
  struct TableSlot {  // trivial, so a new table is not touched before it is advised
    uint64_t hash;
    Expr node;
  };
  std::unique_ptr<TableSlot[]> table;  ///< open-addressing intern table (power-of-two size)
  size_t tableSize = 0;
  struct ConstantSlot {
    uint64_t bits = 0;
    Expr node = nullptr;
  };
  static constexpr int kConstantCacheBits = 10;
  /// Direct-mapped cache of recent constants, indexed by a hash of the value's bits.
  std::vector<ConstantSlot> recentConstants = std::vector<ConstantSlot>(size_t{1} << kConstantCacheBits);
  ChunkedVector<std::string_view> symbolNames;  ///< by symbolId; the characters are in the arena
  ChunkedVector<Expr> symbols;                ///< by symbolId
  /// The symbols symbolArray made, one block per array: `prefix[i,j]suffix`, row-major over
  /// `shape`, with consecutive ids from `first`. They are not in the name table: a name is found
  /// in its block by its family (prefix and suffix) and its subscripts.
  struct SymbolBlock {
    uint32_t first = 0;
    uint32_t count = 0;
    std::string prefix, suffix;
    std::vector<int> shape;
  };
  std::vector<SymbolBlock> blocks;                      ///< in order of `first`
  size_t inBlocks = 0;                                   ///< symbols in blocks
  std::unordered_map<uint64_t, uint32_t> blockByFamily;  ///< family hash -> index in blocks
  /// A Bloom filter of the families of the subscripted names in the name table: an array whose
  /// family may be among them is made name by name, through the table (so a name has one symbol).
  static constexpr size_t kFamilyBits = size_t{1} << 16;
  std::vector<uint64_t> tableFamilies;  ///< kFamilyBits bits once a subscripted name is made
  struct NameSlot {  // trivial, like TableSlot: a large table asks for huge pages before it is touched
    uint32_t tag;    ///< low half of the name's hash (all the table's position needs)
    uint32_t entry;  ///< symbolId + 1; 0 = empty
  };
  std::unique_ptr<NameSlot[]> symbolsByName;  ///< open addressing over the name hashes
  size_t nameTableSize = 0;                   ///< a power of two, or 0
  /// By symbolId of the variable differentiated by: node -> derivative. A map, not a vector by id:
  /// a large model differentiates by few of its millions of symbols (and the memo's references
  /// stay valid while a derivative by another symbol is added).
  std::unordered_map<uint32_t, NodeMap<Expr>> diffMemo;

  /// Returns the unique node structurally equal to `key`, creating it if new (then its operands
  /// are copied into the arena, so the key's spans may point to temporary storage). Fills the key's
  /// hash, mask and depth and normalizes its value; Add coefficients must already be normalized.
  Expr intern(NodeKey& key);
  /// A Mul node from already canonical, sorted, merged (base, exponent) pairs; applies the
  /// single-factor rules (no factor -> constant, one factor with coef 1 -> base or Pow).
  Expr makeMul(double coef, std::span<const Expr> bases, std::span<const Expr> exps);
  /// Rebuilds n with new children (args then exps), re-simplifying. Returns n if unchanged.
  Expr rebuild(Expr n, std::span<const Expr> kids);
  /// The slot of the symbol with this name in symbolsByName, or the empty slot where it belongs.
  NameSlot& nameSlot(std::string_view name, uint64_t hash);
  /// The symbol with this name, made if new; the name table must have room for one more.
  Expr symbol(std::string_view name, uint64_t hash);
  /// A symbol node with the next symbolId, stored without entering the intern table: a symbol is
  /// only ever found by name, never by structure, so the table need not hold (or rehash) it.
  Expr newSymbol(std::string_view name);
  /// The symbol of a block with this name, or nullptr.
  Expr findInBlocks(std::string_view name) const;
  /// The block holding symbol id, or nullptr.
  const SymbolBlock* blockOf(uint32_t id) const;
  /// Whether symbolArray may make this family as a block (no name of it can exist yet).
  bool familyFree(uint64_t family) const {
    bool maybeInTable = !tableFamilies.empty() && (tableFamilies[family % kFamilyBits / 64] >> (family % 64) & 1);
    return !maybeInTable && !blockByFamily.contains(family);
  }
  /// A copy of the name in the arena.
  std::string_view storeName(std::string_view name);
  /// Room for `symbols` more symbols and `nodes` more interned nodes without rehashing.
  void reserve(size_t symbols, size_t nodes);

 private:
  Expr store(const NodeKey& key);
  void resizeTable(size_t size);
  void resizeSymbolsByName(size_t size);
};

/// Accumulates constant + Σ coef·term and builds the canonical Add (flattening nested sums and
/// moving numeric coefficients of products into the term coefficients).
class AddBuilder {
 public:
  explicit AddBuilder(Context& ctx) : ctx_(ctx) {}
  void add(double coef, Expr e);
  void addConstant(double v) { constants_.push_back(v); }
  /// Room for n more terms.
  void reserve(size_t n) { terms_.reserve(terms_.size() + n); }
  Expr build();

  struct Term {
    Expr e;
    double coef;
  };

 private:
  void addTerms(double coef, Expr sum);
  void sortTerms();
  Context& ctx_;
  SmallVec<double, 4> constants_;  // summed in sorted order: the result is permutation invariant
  SmallVec<Term, 8> terms_;
};

/// Accumulates coef · Π base^exp and builds the canonical Mul (collecting equal bases).
class MulBuilder {
 public:
  explicit MulBuilder(Context& ctx, double coef = 1.0) : ctx_(ctx) {
    if (coef != 1.0) coefs_.push_back(coef);
  }
  /// Multiplies by an arbitrary expression (decomposes Mul and Pow).
  void factor(Expr f);
  /// Multiplies by b^e.
  void power(Expr b, Expr e);
  /// Multiplies by a (base, exponent) pair taken from a canonical Mul, as is.
  void pair(Expr b, Expr e) { pairs_.push_back({b, e}); }
  void scale(double c) { coefs_.push_back(c); }
  Expr build();

  struct Factor {
    Expr base, exp;
  };

 private:
  void mergeEqualBases();
  Expr sumExponents(size_t begin, size_t end);
  bool redecompose();
  double coefficient();
  Context& ctx_;
  SmallVec<double, 4> coefs_;  // multiplied in sorted order: the result is permutation invariant
  SmallVec<Factor, 8> pairs_;
};

}  // namespace qdot::sym
