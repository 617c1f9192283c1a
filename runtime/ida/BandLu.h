// LU factorization with partial pivoting of a band matrix, and its solve: LAPACK's dgbtf2 and
// dgbtrs (unblocked), in C++ because the project's stack has no LAPACK. KLU factors the same
// matrices in a band ordering (ida/KluOrdering.h), but it is a general sparse LU: per column a
// depth-first search for the nonzeros, scattered L and U, row scaling and a condition estimate.
// For the reduced Newton matrix of a 10⁶-mass chain (tridiagonal) that took 0.15 s of the first
// step and 20 ms per later factorization, where a band LU needs a pass over 4n doubles.
//
// Storage (LAPACK's): column j holds rows j − upper − lower … j + lower, row i of A at position
// lower + upper + i − j; the first `lower` positions of each column take the fill that row
// interchanges bring into U (U gets lower + upper superdiagonals).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace qdot::rt {

class BandLu {
 public:
  /// An n × n matrix with `lower` subdiagonals and `upper` superdiagonals, all zero.
  BandLu(int64_t n, int64_t lower, int64_t upper);

  int64_t size() const { return n_; }
  int64_t lower() const { return lower_; }
  int64_t upper() const { return upper_; }
  /// Where entry (i, j) of A lives in storage(); j − upper ≤ i ≤ j + lower.
  int64_t offset(int64_t i, int64_t j) const { return j * stride_ + lower_ + upper_ + i - j; }
  /// The matrix (before factor()), then its factors.
  std::span<double> storage() { return values_; }
  /// Sets every entry, and the room for fill, to zero: before the matrix is written anew.
  void clear();

  /// Factors A = P L U in place. −1, or the first column whose pivot is zero (A singular; the
  /// factors are then not usable).
  int64_t factor();
  /// Solves A x = b in place (after a factor() that returned −1).
  void solve(std::span<double> b) const;

 private:
  double& at(int64_t i, int64_t j) { return values_[static_cast<size_t>(offset(i, j))]; }
  const double& at(int64_t i, int64_t j) const { return values_[static_cast<size_t>(offset(i, j))]; }

  int64_t n_, lower_, upper_, stride_;
  std::vector<double> values_;
  std::vector<int64_t> pivotRow_;  ///< per column j: the row swapped with row j
  std::vector<double> inverseDiagonal_;  ///< 1 / U(j, j): the back substitution multiplies (a division's latency is its chain's)
};

}  // namespace qdot::rt
