// Rows of Newton's matrix with two entries, eliminated before the sparse LU. A mechanics model's
// DAE has one kinematic row per coordinate, der(q) − v = 0: in IDA's matrix J = ∂F/∂y + cj ∂F/∂y'
// that row is cj · dq − dv = r, two entries. Solving it for one of its two unknowns and putting
// that into the other rows leaves a system with one row and one unknown fewer per such row (the
// Schur complement, exact: det J = ± pivot · det S), whose pattern is that of the other rows with
// the pair's two columns merged. For a chain of masses: n × n tridiagonal instead of 2n × 2n with
// eight entries per mass, so that KLU factors a third of the entries in a band a third as wide.
//
// Pure functions on a CSC pattern and its values (no SUNDIALS); ida/ReducedKlu.h is the solver.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "ida/KluOrdering.h"

namespace qdot::rt {

/// Which rows are eliminated and the reduced system's pattern. A pair row r has exactly two
/// entries, one of them its diagonal (r, r) and the other (r, o) in a column no other pair uses
/// (chosen greedily in row order). S keeps every index outside the pair rows, for its rows and its
/// columns alike, numbered in order; a pair's column o in S stands for both unknowns r and o. So
/// S's diagonal is J's (a model's equations are matched to its unknowns so; BTF and RCM read the
/// pattern that way), and a band of J stays a band of S.
struct TwoEntryRows {
  // Indices in 32 bits (findTwoEntryRows declines larger matrices): at 2·10⁶ unknowns these tables
  // are made while IDA is set up, and half the bytes is half the time. S's pattern is KLU's type.
  int64_t n = 0;                                  ///< J's size
  std::vector<int32_t> row;                       ///< per pair: its row r (and the column r merged into o)
  std::vector<int32_t> partner;                   ///< per pair: the row's other column o
  std::vector<int32_t> rowEntry, partnerEntry;    ///< per pair: where (r, r) and (r, o) are in J's values
  std::vector<int32_t> pairOf;                    ///< per index of J: the pair whose r or o it is, or −1
  std::vector<int32_t> reducedIndex;              ///< per index of J: its row and column in S, or −1 (a pair row)
  std::vector<int32_t> originalIndex;             ///< per index of S: the index of J it keeps
  std::vector<int64_t> columnStarts, rowIndices;  ///< S's pattern (CSC, no duplicates)
  std::vector<int32_t> target;                    ///< per entry of J: its entry in S, or −1 (a pair row's)

  int64_t pairs() const { return static_cast<int64_t>(row.size()); }
  int64_t size() const { return n - pairs(); }  ///< S's size
  CscPattern reducedPattern() const { return {columnStarts, rowIndices}; }
  /// The column of S that column j of J goes to.
  int32_t reducedColumn(int64_t j) const {
    int32_t q = pairOf[j];
    return q >= 0 && row[q] == j ? reducedIndex[partner[q]] : reducedIndex[j];
  }
};

/// The pair rows of a square CSC pattern and S's pattern; nullopt when there are none (or J has
/// more than 2³¹ − 1 entries or columns).
std::optional<TwoEntryRows> findTwoEntryRows(CscPattern pattern);

/// Per factorization: which of each pair's two unknowns its row is solved for (the entry of larger
/// magnitude is the pivot, so that every multiplier is at most 1 in magnitude) and its values.
struct PairPivots {
  std::vector<uint8_t> solvesRow;    ///< 1: the row is solved for unknown r, 0: for unknown o
  std::vector<double> pivot, other;  ///< the row's value at the unknown solved for and at the other
  /// Per pair (CSR, entryStarts of size pairs + 1): the column solved for in S's rows, as (S row,
  /// J value / pivot) — what a solve moves of the pair row's b to the other rows, made once per
  /// factorization (a solve then reads 12 bytes per entry instead of J's 20 and divides nothing).
  std::vector<int32_t> entryStarts, entryRow;
  std::vector<double> entryFactor;
  int64_t solvedFor(const TwoEntryRows& rows, int64_t q) const { return solvesRow[q] ? rows.row[q] : rows.partner[q]; }
  int64_t kept(const TwoEntryRows& rows, int64_t q) const { return solvesRow[q] ? rows.partner[q] : rows.row[q]; }
};

/// S's values from J's (`reduced` at least S's nonzero count) and the pivots with their entries;
/// the first pair whose row is zero (J singular), or −1.
int64_t reduceMatrix(const TwoEntryRows& rows, std::span<const int64_t> columnStarts,
                     std::span<const int64_t> rowIndices, std::span<const double> values, std::span<double> reduced,
                     PairPivots& pivots);

/// S's right-hand side from b (size n) into `reduced` (size S), and each pair row's b into
/// `pairRhs` (size pairs), which completeSolution needs (b may be overwritten in between).
void reduceRightHandSide(const TwoEntryRows& rows, const PairPivots& pivots, std::span<const double> b,
                         std::span<double> reduced, std::span<double> pairRhs);

/// J's solution x (size n) from S's solution and the pair rows' right-hand sides.
void completeSolution(const TwoEntryRows& rows, const PairPivots& pivots, std::span<const double> reducedSolution,
                      std::span<const double> pairRhs, std::span<double> x);

}  // namespace qdot::rt
