// Band LU with partial pivoting (BandLu.h): LAPACK's dgbtf2 and dgbtrs, 0-based.
#include "ida/BandLu.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace qdot::rt {

BandLu::BandLu(int64_t n, int64_t lower, int64_t upper)
    : n_(n),
      lower_(lower),
      upper_(upper),
      stride_(2 * lower + upper + 1),
      values_(static_cast<size_t>(n * stride_), 0.0),
      pivotRow_(static_cast<size_t>(n), 0),
      inverseDiagonal_(static_cast<size_t>(n), 0.0) {}

void BandLu::clear() { std::fill(values_.begin(), values_.end(), 0.0); }

// Column by column: the pivot is the largest entry on or below the diagonal (at most `lower` rows
// down); swapping it up carries its row's entries up to column j + upper + (its distance) into U,
// which is what the extra `lower` superdiagonals hold; then the rank-one update of the rows below
// over the columns U reaches so far (ju).
int64_t BandLu::factor() {
  int64_t ju = 0;
  for (int64_t j = 0; j < n_; ++j) {
    int64_t below = std::min(lower_, n_ - 1 - j), jp = 0;
    double largest = std::abs(at(j, j));
    for (int64_t i = 1; i <= below; ++i)
      if (double a = std::abs(at(j + i, j)); a > largest) largest = a, jp = i;
    pivotRow_[static_cast<size_t>(j)] = j + jp;
    if (largest == 0.0) return j;
    ju = std::max(ju, std::min(j + upper_ + jp, n_ - 1));
    if (jp != 0)
      for (int64_t c = j; c <= ju; ++c) std::swap(at(j + jp, c), at(j, c));
    double inverse = inverseDiagonal_[static_cast<size_t>(j)] = 1.0 / at(j, j);
    if (below == 0) continue;
    double* multipliers = &at(j + 1, j);  // rows j + 1 … j + below of column j are contiguous
    for (int64_t i = 0; i < below; ++i) multipliers[i] *= inverse;
    for (int64_t c = j + 1; c <= ju; ++c) {
      double u = at(j, c);
      if (u == 0.0) continue;
      double* column = &at(j + 1, c);
      for (int64_t i = 0; i < below; ++i) column[i] -= multipliers[i] * u;
    }
  }
  return -1;
}

void BandLu::solve(std::span<double> b) const {
  const int64_t kv = lower_ + upper_;
  if (lower_ > 0) {
    for (int64_t j = 0; j + 1 < n_; ++j) {
      int64_t below = std::min(lower_, n_ - 1 - j);
      if (int64_t l = pivotRow_[static_cast<size_t>(j)]; l != j) std::swap(b[static_cast<size_t>(l)], b[static_cast<size_t>(j)]);
      double bj = b[static_cast<size_t>(j)];
      if (bj == 0.0) continue;
      const double* multipliers = &at(j + 1, j);
      for (int64_t i = 0; i < below; ++i) b[static_cast<size_t>(j + 1 + i)] -= multipliers[i] * bj;
    }
  }
  for (int64_t j = n_ - 1; j >= 0; --j) {
    double& bj = b[static_cast<size_t>(j)];
    if (bj == 0.0) continue;
    bj *= inverseDiagonal_[static_cast<size_t>(j)];
    int64_t first = std::max<int64_t>(0, j - kv);
    const double* column = &at(first, j);  // rows first … j − 1 of column j are contiguous
    for (int64_t i = 0; i < j - first; ++i) b[static_cast<size_t>(first + i)] -= column[i] * bj;
  }
}

}  // namespace qdot::rt
