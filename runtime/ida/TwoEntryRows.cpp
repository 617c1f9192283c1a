// Two-entry rows of Newton's matrix eliminated before the LU (TwoEntryRows.h).
#include "ida/TwoEntryRows.h"

#include <cmath>
#include <limits>

namespace qdot::rt {

namespace {

/// Per row of two entries, one of them its diagonal: the other column and both positions.
struct RowsOfTwo {
  std::vector<int32_t> count;                          // entries per row, saturated at 3
  std::vector<int32_t> partner, rowEntry, otherEntry;  // filled for rows of two only (else −1)
};

RowsOfTwo rowsOfTwo(CscPattern p) {
  int64_t n = p.size();
  RowsOfTwo r;
  r.count.assign(n, 0);
  for (int64_t k = 0; k < p.nonzeros(); ++k) {
    int32_t& c = r.count[p.rowIndices[k]];
    if (c < 3) ++c;
  }
  r.partner.assign(n, -1);
  r.rowEntry.assign(n, -1);
  r.otherEntry.assign(n, -1);
  for (int64_t j = 0; j < n; ++j)
    for (int64_t k = p.columnStarts[j]; k < p.columnStarts[j + 1]; ++k) {
      int64_t i = p.rowIndices[k];
      if (r.count[i] != 2) continue;
      if (i == j) {
        r.rowEntry[i] = static_cast<int32_t>(k);
      } else {
        r.partner[i] = static_cast<int32_t>(j);
        r.otherEntry[i] = static_cast<int32_t>(k);
      }
    }
  return r;
}

/// Greedy choice of pair rows in row order: the diagonal and one other entry, in columns no other
/// pair uses.
void choosePairs(const RowsOfTwo& r, TwoEntryRows& out) {
  int64_t n = out.n;
  out.pairOf.assign(n, -1);
  for (int64_t i = 0; i < n; ++i) {
    if (r.count[i] != 2 || r.rowEntry[i] < 0 || r.partner[i] < 0) continue;  // also: (i, i) twice
    int32_t o = r.partner[i];
    if (out.pairOf[i] >= 0 || out.pairOf[o] >= 0) continue;
    out.pairOf[i] = out.pairOf[o] = static_cast<int32_t>(out.pairs());
    out.row.push_back(static_cast<int32_t>(i));
    out.partner.push_back(o);
    out.rowEntry.push_back(r.rowEntry[i]);
    out.partnerEntry.push_back(r.otherEntry[i]);
  }
}

/// S's indices: J's without the pair rows, in order.
void numberReduced(TwoEntryRows& out) {
  int64_t n = out.n;
  out.reducedIndex.assign(n, 0);
  for (int32_t i : out.row) out.reducedIndex[i] = -1;
  out.originalIndex.clear();
  out.originalIndex.reserve(out.size());
  for (int64_t i = 0; i < n; ++i) {
    if (out.reducedIndex[i] < 0) continue;
    out.reducedIndex[i] = static_cast<int32_t>(out.originalIndex.size());
    out.originalIndex.push_back(static_cast<int32_t>(i));
  }
}

/// S's pattern: each S column is the union of its J columns' entries in kept rows; `target` maps
/// every entry of J there.
void buildReducedPattern(CscPattern p, TwoEntryRows& out) {
  int64_t m = out.size();
  out.columnStarts.assign(m + 1, 0);
  out.rowIndices.clear();
  out.rowIndices.reserve(p.nonzeros());
  out.target.assign(p.nonzeros(), -1);
  std::vector<int32_t> seenIn(m, -1), at(m, 0);  // per S row: the S column it was last seen in, and where
  auto add = [&](int64_t s, int64_t j) {
    for (int64_t k = p.columnStarts[j]; k < p.columnStarts[j + 1]; ++k) {
      int32_t r = out.reducedIndex[p.rowIndices[k]];
      if (r < 0) continue;
      if (seenIn[r] != s) {
        seenIn[r] = static_cast<int32_t>(s);
        at[r] = static_cast<int32_t>(out.rowIndices.size());
        out.rowIndices.push_back(r);
      }
      out.target[k] = at[r];
    }
  };
  for (int64_t s = 0; s < m; ++s) {
    int64_t j = out.originalIndex[s];
    add(s, j);
    if (int32_t q = out.pairOf[j]; q >= 0) add(s, out.row[q]);  // j is the pair's o: r merges into it
    out.columnStarts[s + 1] = static_cast<int64_t>(out.rowIndices.size());
  }
}

}  // namespace

std::optional<TwoEntryRows> findTwoEntryRows(CscPattern pattern) {
  constexpr int64_t kLargest = std::numeric_limits<int32_t>::max();
  if (pattern.nonzeros() > kLargest || pattern.size() > kLargest) return std::nullopt;
  TwoEntryRows out;
  out.n = pattern.size();
  choosePairs(rowsOfTwo(pattern), out);
  if (out.pairs() == 0) return std::nullopt;
  numberReduced(out);
  buildReducedPattern(pattern, out);
  return out;
}

int64_t reduceMatrix(const TwoEntryRows& rows, std::span<const int64_t> columnStarts,
                     std::span<const int64_t> rowIndices, std::span<const double> values, std::span<double> reduced,
                     PairPivots& pivots) {
  int64_t pairs = rows.pairs();
  pivots.solvesRow.resize(pairs);
  pivots.pivot.resize(pairs);
  pivots.other.resize(pairs);
  int64_t singular = -1;
  for (int64_t q = 0; q < pairs; ++q) {
    double a = values[rows.rowEntry[q]], b = values[rows.partnerEntry[q]];
    bool solvesRow = std::abs(a) >= std::abs(b);
    pivots.solvesRow[q] = solvesRow;
    pivots.pivot[q] = solvesRow ? a : b;
    pivots.other[q] = solvesRow ? b : a;
    if (pivots.pivot[q] == 0 && singular < 0) singular = q;
  }
  std::fill(reduced.begin(), reduced.end(), 0.0);
  for (int64_t j = 0; j < rows.n; ++j) {
    int32_t q = rows.pairOf[j];
    // S(:, pair) = J(:, kept) − (other / pivot) · J(:, solved for)
    bool solvedFor = q >= 0 && pivots.solvedFor(rows, q) == j;
    double factor = solvedFor && pivots.pivot[q] != 0 ? -pivots.other[q] / pivots.pivot[q] : 1.0;
    for (int64_t k = columnStarts[j]; k < columnStarts[j + 1]; ++k)
      if (int32_t t = rows.target[k]; t >= 0) reduced[t] += factor * values[k];
  }
  pivots.entryStarts.assign(1, 0);
  pivots.entryStarts.reserve(pairs + 1);
  pivots.entryRow.clear(), pivots.entryFactor.clear();
  // J's entry count bounds the lists: reserved at the first factorization (IDA's first step), so
  // that they are not copied as they grow; what is never written is never faulted in.
  pivots.entryRow.reserve(rowIndices.size()), pivots.entryFactor.reserve(rowIndices.size());
  for (int64_t q = 0; q < pairs; ++q) {
    int64_t j = pivots.solvedFor(rows, q);
    for (int64_t k = columnStarts[j]; k < columnStarts[j + 1]; ++k)
      if (int32_t r = rows.reducedIndex[rowIndices[k]]; r >= 0 && pivots.pivot[q] != 0) {
        pivots.entryRow.push_back(r);
        pivots.entryFactor.push_back(values[k] / pivots.pivot[q]);
      }
    pivots.entryStarts.push_back(static_cast<int32_t>(pivots.entryRow.size()));
  }
  return singular;
}

void reduceRightHandSide(const TwoEntryRows& rows, const PairPivots& pivots, std::span<const double> b,
                         std::span<double> reduced, std::span<double> pairRhs) {
  for (int64_t s = 0; s < rows.size(); ++s) reduced[s] = b[rows.originalIndex[s]];
  // the unknown solved for is (b_row − other · kept) / pivot: its b part moves to the other rows
  for (int64_t q = 0; q < rows.pairs(); ++q) {
    double share = pairRhs[q] = b[rows.row[q]];
    for (int32_t e = pivots.entryStarts[q]; e < pivots.entryStarts[q + 1]; ++e)
      reduced[pivots.entryRow[e]] -= pivots.entryFactor[e] * share;
  }
}

void completeSolution(const TwoEntryRows& rows, const PairPivots& pivots, std::span<const double> reducedSolution,
                      std::span<const double> pairRhs, std::span<double> x) {
  for (int64_t s = 0; s < rows.size(); ++s) x[rows.originalIndex[s]] = reducedSolution[s];
  for (int64_t q = 0; q < rows.pairs(); ++q) {
    int64_t solved = pivots.solvedFor(rows, q), kept = pivots.kept(rows, q);
    double keptValue = x[kept == rows.row[q] ? rows.partner[q] : kept];  // x[o] holds S's value for the pair
    x[kept] = keptValue;
    x[solved] = (pairRhs[q] - pivots.other[q] * keptValue) / pivots.pivot[q];
  }
}

}  // namespace qdot::rt
