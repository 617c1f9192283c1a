// Reverse Cuthill–McKee on A + Aᵀ and KLU's user ordering callback (KluOrdering.h).
#include "ida/KluOrdering.h"

#include <klu.h>

#include <algorithm>
#include <cstdlib>
#include <numeric>
#include <type_traits>
#include <utility>

namespace qdot::rt {

namespace {

static_assert(std::is_same_v<SuiteSparse_long, int64_t>, "KLU's long index type must be sunindextype (int64_t)");

/// A + Aᵀ seen through A's columns and its transpose (A's rows), without building it: the
/// neighbours of v are the rows of column v and the columns of row v. The diagonal and an entry
/// present in both directions appear twice; a search skips what it has reached. Building the
/// symmetric graph itself (with duplicates removed) took twice as long at 2 · 10⁶ unknowns.
class SymmetricView {
 public:
  explicit SymmetricView(CscPattern a) : a_(a), rowStarts_(a.size() + 2, 0), rowColumns_(a.nonzeros()) {
    // A counting sort by row: row i is counted at i + 2, so that after the prefix sums entry i + 1
    // is where row i starts, and filling row i moves it on to where row i + 1 starts.
    int64_t n = a.size();
    for (int64_t k = 0; k < a.nonzeros(); ++k) ++rowStarts_[a.rowIndices[k] + 2];
    for (int64_t i = 2; i <= n; ++i) rowStarts_[i] += rowStarts_[i - 1];
    for (int64_t j = 0; j < n; ++j)
      for (int64_t k = a.columnStarts[j]; k < a.columnStarts[j + 1]; ++k)
        rowColumns_[rowStarts_[a.rowIndices[k] + 1]++] = static_cast<uint32_t>(j);
    rowStarts_.pop_back();
  }
  /// The entries of row v and column v: how strongly v is coupled.
  int64_t degree(int64_t v) const {
    return a_.columnStarts[v + 1] - a_.columnStarts[v] + rowStarts_[v + 1] - rowStarts_[v];
  }
  template <class Visit>
  void forEachNeighbour(int64_t v, Visit&& visit) const {
    for (int64_t k = a_.columnStarts[v]; k < a_.columnStarts[v + 1]; ++k) visit(a_.rowIndices[k]);
    for (int64_t k = rowStarts_[v]; k < rowStarts_[v + 1]; ++k) visit(static_cast<int64_t>(rowColumns_[k]));
  }

 private:
  CscPattern a_;
  std::vector<int64_t> rowStarts_;
  std::vector<uint32_t> rowColumns_;  ///< n < 2³² (qdot's unknowns are counted in 32 bits)
};

/// Cuthill–McKee numbers the neighbours a node reaches first in order of increasing degree (ties
/// by index). A node that reaches more than this many at once (a hub) leaves them in the order
/// met: the sorting then costs at most this many comparisons per node, so a search stays
/// O(n + nnz), and the band a hub widens is not narrowed by the order of its neighbours.
constexpr std::size_t kSortedNeighbours = 32;

/// A breadth-first search's level structure: the nodes reached from the root, level by level (at
/// the end of the caller's queue), the number of levels, and where the last level starts.
struct Levels {
  int64_t count = 1;
  std::size_t lastLevel = 0;
};

/// Breadth first from root over its connected component, each node's new neighbours by degree:
/// queue[begin..] is then the Cuthill–McKee order from root (what was there before is kept).
/// reached[v] = stamp marks the nodes met.
Levels cuthillMcKee(const SymmetricView& g, int64_t root, std::vector<int64_t>& queue, std::size_t begin,
                    std::vector<int64_t>& reached, int64_t stamp) {
  queue.resize(begin);
  queue.push_back(root);
  reached[root] = stamp;
  Levels levels;
  levels.lastLevel = begin;
  std::size_t levelEnd = begin + 1;  // the level being expanded is [levels.lastLevel, levelEnd)
  for (std::size_t head = begin; head < queue.size(); ++head) {
    if (head == levelEnd) levels.lastLevel = head, ++levels.count, levelEnd = queue.size();
    std::size_t first = queue.size();
    g.forEachNeighbour(queue[head], [&](int64_t w) {
      if (reached[w] != stamp) reached[w] = stamp, queue.push_back(w);
    });
    if (queue.size() - first > 1 && queue.size() - first <= kSortedNeighbours)
      std::sort(queue.begin() + static_cast<std::ptrdiff_t>(first), queue.end(), [&](int64_t a, int64_t b) {
        int64_t da = g.degree(a), db = g.degree(b);
        return da != db ? da < db : a < b;
      });
  }
  return levels;
}

/// Searches from a node of least degree in the last level lengthen the level structure until it
/// stops growing (George and Liu); each round costs one search of the component, and the rounds
/// are capped so that the whole ordering stays linear. Returns the start it settled on, with
/// queue[begin..] holding the Cuthill–McKee order from it (the last search's).
constexpr int kPeripheralRounds = 5;

int64_t pseudoPeripheralStart(const SymmetricView& g, int64_t root, std::vector<int64_t>& queue, std::size_t begin,
                              std::vector<int64_t>& reached, int64_t& stamp) {
  Levels levels = cuthillMcKee(g, root, queue, begin, reached, ++stamp);
  for (int round = 0; round < kPeripheralRounds; ++round) {
    auto last = queue.begin() + static_cast<std::ptrdiff_t>(levels.lastLevel);
    int64_t x = *std::min_element(last, queue.end(), [&](int64_t a, int64_t b) { return g.degree(a) < g.degree(b); });
    if (x == root) break;  // a component of one node
    Levels fromX = cuthillMcKee(g, x, queue, begin, reached, ++stamp);
    root = x;
    if (fromX.count <= levels.count) break;
    levels = fromX;
  }
  return root;
}

/// KLU's estimate of nnz(L) (diagonal included) for a band of half width b; it sizes L and U from it.
int64_t bandFactorEntries(int64_t n, int64_t bandwidth) { return std::max<int64_t>(1, n * (bandwidth + 1)); }

// KLU's user ordering: the permutation of the n × n block (Ap, Ai) into perm; the return value is
// KLU's estimate of nnz(L), 0 for a failure.
SuiteSparse_long orderForKlu(SuiteSparse_long n, SuiteSparse_long* Ap, SuiteSparse_long* Ai, SuiteSparse_long* perm,
                             klu_l_common* common) {
  const auto* chosen = static_cast<const BandOrdering*>(common->user_data);
  // Without BTF, KLU's one block is the matrix itself, unpermuted (klu_analyze.c): its ordering
  // was made when the band was checked.
  if (common->btf == 0 && chosen && static_cast<SuiteSparse_long>(chosen->order.size()) == n) {
    std::copy(chosen->order.begin(), chosen->order.end(), perm);
    return bandFactorEntries(n, chosen->bandwidth);
  }
  CscPattern block{{Ap, static_cast<std::size_t>(n + 1)}, {Ai, static_cast<std::size_t>(Ap[n])}};
  std::vector<int64_t> order = reverseCuthillMcKee(block);
  std::copy(order.begin(), order.end(), perm);
  return bandFactorEntries(n, permutedBandwidth(block, order));
}

}  // namespace

std::vector<int64_t> reverseCuthillMcKee(CscPattern pattern) {
  int64_t n = pattern.size();
  SymmetricView g(pattern);
  std::vector<int64_t> order, reached(n, 0);  // reached[v] != 0: v's component is numbered
  order.reserve(n);  // the searches' queue: each component's numbering follows the ones before
  int64_t stamp = 0;
  for (int64_t s = 0; s < n; ++s)
    if (reached[s] == 0) pseudoPeripheralStart(g, s, order, order.size(), reached, stamp);
  std::reverse(order.begin(), order.end());
  return order;
}

int64_t permutedBandwidth(CscPattern pattern, std::span<const int64_t> order) {
  int64_t n = pattern.size();
  std::vector<int64_t> position(n);
  for (int64_t k = 0; k < n; ++k) position[order[k]] = k;
  int64_t band = 0;
  for (int64_t j = 0; j < n; ++j)
    for (int64_t k = pattern.columnStarts[j]; k < pattern.columnStarts[j + 1]; ++k)
      band = std::max(band, std::abs(position[pattern.rowIndices[k]] - position[j]));
  return band;
}

// The factor 10 is KLU's own budget: for a COLAMD-ordered matrix its first allocation is
// initmem = 10 entries per entry of A (plus n) for each of L and U (klu_l_defaults), so an accepted
// band fits, even pivoting in every column, in less room than KLU plans for its default ordering.
// The work is bounded with it: LU in a band costs at most b (2b + 1) multiply-adds per column, and
// b <= (10 nnz/n − 1) / 3 — 9 at three entries per column, about 16 at five. A 1-D structure (a
// chain: b = 3 at nnz = 4n, whatever its length) is accepted; a 2-D grid (5-point Laplacian of
// side m: nnz ≈ 5n, RCM's b ≈ m) only up to m ≈ 15, where any ordering is cheap.
bool bandIsNarrow(int64_t n, int64_t nonzeros, int64_t bandwidth) {
  return static_cast<double>(n) * (3.0 * static_cast<double>(bandwidth) + 1.0) <=
         static_cast<double>(kBandFillFactor) * static_cast<double>(nonzeros);
}

bool zeroFreeDiagonal(CscPattern pattern) {
  for (int64_t c = 0; c < pattern.size(); ++c) {
    auto begin = pattern.rowIndices.begin() + pattern.columnStarts[c];
    auto end = pattern.rowIndices.begin() + pattern.columnStarts[c + 1];
    if (std::find(begin, end, c) == end) return false;
  }
  return true;
}

int64_t naturalBandwidth(CscPattern pattern) {
  int64_t band = 0;
  for (int64_t j = 0; j < pattern.size(); ++j)
    for (int64_t k = pattern.columnStarts[j]; k < pattern.columnStarts[j + 1]; ++k)
      band = std::max(band, std::abs(pattern.rowIndices[k] - j));
  return band;
}

int64_t bandwidthLowerBound(CscPattern pattern) {
  int64_t n = pattern.size(), most = 0;
  std::vector<int32_t> inRow(n, 0);
  for (int64_t j = 0; j < n; ++j) {
    int64_t inColumn = 0;
    for (int64_t k = pattern.columnStarts[j]; k < pattern.columnStarts[j + 1]; ++k) {
      int64_t i = pattern.rowIndices[k];
      if (i == j) continue;
      ++inColumn;
      most = std::max<int64_t>(most, ++inRow[i]);
    }
    most = std::max(most, inColumn);
  }
  return (most + 1) / 2;
}

std::optional<BandOrdering> chooseBandOrdering(CscPattern pattern) {
  BandOrdering band;
  // A model's own order is often a band already (a chain's reduced matrix: tridiagonal); when no
  // ordering can do better, RCM's searches are not made.
  if (int64_t natural = naturalBandwidth(pattern); natural <= bandwidthLowerBound(pattern)) {
    if (!bandIsNarrow(pattern.size(), pattern.nonzeros(), natural)) return std::nullopt;
    band.order.resize(pattern.size());
    std::iota(band.order.begin(), band.order.end(), int64_t{0});
    band.bandwidth = natural;
    return band;
  }
  band.order = reverseCuthillMcKee(pattern);
  band.bandwidth = permutedBandwidth(pattern, band.order);
  if (!bandIsNarrow(pattern.size(), pattern.nonzeros(), band.bandwidth)) return std::nullopt;
  return band;
}

void useBandOrdering(klu_l_common& common, const BandOrdering& ordering) {
  common.ordering = 3;  // a user ordering function
  common.user_order = &orderForKlu;
  common.user_data = const_cast<BandOrdering*>(&ordering);  // only read
  common.btf = 0;
}

}  // namespace qdot::rt
