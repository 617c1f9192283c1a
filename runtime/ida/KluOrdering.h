// A fill-reducing ordering for KLU that costs a few breadth-first searches: reverse Cuthill–McKee
// (RCM) of the symmetrized pattern A + Aᵀ, used when the band it leaves is narrow enough that LU
// with partial pivoting inside it has bounded fill. Otherwise KLU keeps its default (COLAMD),
// whose analysis took most of the first step of a 10⁶-mass chain. Pure functions on a CSC
// pattern, and the hook that hands a chosen ordering to KLU's user ordering callback.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

struct klu_l_common_struct;  // <klu.h>: KLU's 64-bit settings, which SUNDIALS' KLU solver uses

namespace qdot::rt {

/// A square sparsity pattern in compressed sparse column form: n + 1 column starts, and the row of
/// every entry (any order within a column; the diagonal and duplicates allowed).
struct CscPattern {
  std::span<const int64_t> columnStarts;
  std::span<const int64_t> rowIndices;
  int64_t size() const { return columnStarts.empty() ? 0 : static_cast<int64_t>(columnStarts.size()) - 1; }
  int64_t nonzeros() const { return columnStarts.empty() ? 0 : columnStarts.back(); }
};

/// RCM of A + Aᵀ: order[k] is the unknown placed at position k (a symmetric permutation). Each
/// connected component is numbered from a pseudo-peripheral node (George–Liu), neighbours in order
/// of increasing degree; the whole numbering is then reversed. Iterative, O(n + nnz); n < 2³².
std::vector<int64_t> reverseCuthillMcKee(CscPattern pattern);

/// Largest |p(i) − p(j)| over the entries (i, j), p(order[k]) = k: the half bandwidth of the
/// symmetrically permuted matrix (the same for A and A + Aᵀ).
int64_t permutedBandwidth(CscPattern pattern, std::span<const int64_t> order);

/// Whether LU inside a band of half width b has bounded fill: with row pivoting L keeps b entries
/// below the diagonal and U at most 2b above it, so nnz(L + U) <= n (3b + 1); accepted when that
/// is at most kBandFillFactor times nnz(A) (KluOrdering.cpp says why 10).
bool bandIsNarrow(int64_t n, int64_t nonzeros, int64_t bandwidth);
inline constexpr int64_t kBandFillFactor = 10;

/// An RCM ordering whose band was found narrow.
struct BandOrdering {
  std::vector<int64_t> order;  ///< order[k]: the unknown at position k
  int64_t bandwidth = 0;       ///< half bandwidth after the permutation
};

/// Largest |i − j| over the entries (i, j): the half bandwidth in the pattern's own order.
int64_t naturalBandwidth(CscPattern pattern);

/// A half bandwidth no symmetric ordering can go below: ⌈d / 2⌉ for the most off-diagonal entries
/// d in one row or column (a node's d neighbours cannot all be within b − 1 of it). Exact for
/// patterns without duplicate entries; with them, an upper estimate of this bound.
int64_t bandwidthLowerBound(CscPattern pattern);

/// Whether every column c has an entry in row c (KLU's block triangular form needs a maximum
/// transversal otherwise: O(n · nnz) at worst).
bool zeroFreeDiagonal(CscPattern pattern);

/// RCM of the pattern if its band is narrow (bandIsNarrow), else nullopt: KLU keeps COLAMD. The
/// pattern's own order instead when its bandwidth is already the lower bound (no search made).
std::optional<BandOrdering> chooseBandOrdering(CscPattern pattern);

/// Has KLU order its matrix with `ordering` (ordering = 3, a user callback) and factor it without
/// block triangular form: the band bound holds for the whole matrix, and the callback then meets
/// the matrix itself, whose ordering is already made. Were it given a BTF block it would order
/// that block by RCM. `ordering` must outlive KLU's analysis (the solver's first setup).
void useBandOrdering(klu_l_common_struct& common, const BandOrdering& ordering);

}  // namespace qdot::rt
