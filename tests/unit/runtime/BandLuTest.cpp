// Band LU with partial pivoting (ida/BandLu.h) against Eigen's dense LU: random band matrices of
// every shape of band (none below or above the diagonal, wider below than above and the reverse),
// small diagonals that make it pivot, a zero diagonal that only pivoting can factor, and a zero
// column reported where it is.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <tuple>
#include <vector>

#include "ida/BandLu.h"

namespace qdot::rt::test {
namespace {

/// A random n × n matrix with `lower` subdiagonals and `upper` superdiagonals, written into lu and
/// returned dense. `diagonal` scales the diagonal: small values make partial pivoting swap rows.
Eigen::MatrixXd randomBand(BandLu& lu, std::mt19937& random, double diagonal) {
  std::uniform_real_distribution<double> value(-1, 1);
  int64_t n = lu.size();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  lu.clear();
  for (int64_t j = 0; j < n; ++j)
    for (int64_t i = std::max<int64_t>(0, j - lu.upper()); i <= std::min(n - 1, j + lu.lower()); ++i) {
      double a = i == j ? diagonal * value(random) : value(random);
      A(i, j) = a;
      lu.storage()[static_cast<size_t>(lu.offset(i, j))] = a;
    }
  return A;
}

TEST(BandLu, SolvesRandomBandsOfEveryShapeAsDenseLuDoes) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> value(-1, 1);
  int checked = 0;
  for (int64_t n : {1, 2, 3, 7, 60})
    for (auto [lower, upper] : std::vector<std::pair<int64_t, int64_t>>{{0, 0}, {1, 1}, {2, 0}, {0, 3}, {3, 1}, {1, 4}, {5, 5}})
      for (double diagonal : {10.0, 1.0, 1e-3}) {
        BandLu lu(n, lower, upper);
        Eigen::MatrixXd A = randomBand(lu, random, diagonal);
        Eigen::FullPivLU<Eigen::MatrixXd> dense(A);
        if (dense.rank() < n || dense.rcond() < 1e-10) continue;  // nearly singular by chance
        ASSERT_EQ(lu.factor(), -1) << "n " << n << " band " << lower << "/" << upper;
        Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(n, [&] { return value(random); });
        std::vector<double> x(b.data(), b.data() + n);
        lu.solve(x);
        Eigen::VectorXd got = Eigen::Map<Eigen::VectorXd>(x.data(), n), exact = dense.solve(b);
        EXPECT_LT((got - exact).norm(), 1e-11 * exact.norm() / dense.rcond())
            << "n " << n << " band " << lower << "/" << upper << " diagonal " << diagonal;
        EXPECT_LT((A * got - b).norm(), 1e-13 * (A.norm() * got.norm() + b.norm()));
        ++checked;
      }
  EXPECT_GT(checked, 80);  // nearly every combination was well conditioned
}

// [[0 1 0 0] [1 0 1 0] [0 1 0 1] [0 0 1 0]]-like: no LU without row interchanges exists.
TEST(BandLu, AZeroDiagonalIsFactoredByPivoting) {
  const int64_t n = 6;
  BandLu lu(n, 1, 1);
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
  for (int64_t i = 0; i + 1 < n; ++i) {
    A(i, i + 1) = 1.0 + i, A(i + 1, i) = 2.0 - 0.1 * i;
    lu.storage()[static_cast<size_t>(lu.offset(i, i + 1))] = A(i, i + 1);
    lu.storage()[static_cast<size_t>(lu.offset(i + 1, i))] = A(i + 1, i);
  }
  ASSERT_EQ(lu.factor(), -1);
  std::vector<double> x{1, -2, 3, 0.5, 0, 4};
  Eigen::VectorXd b = Eigen::Map<Eigen::VectorXd>(x.data(), n);
  lu.solve(x);
  Eigen::VectorXd got = Eigen::Map<Eigen::VectorXd>(x.data(), n);
  EXPECT_LT((A * got - b).norm(), 1e-13 * b.norm());
}

// Row operations keep a zero column zero: the factorization stops at it.
TEST(BandLu, AZeroColumnIsWhereTheFactorizationStops) {
  std::mt19937 random(8);
  for (int64_t zero : {0, 3, 9}) {
    BandLu lu(10, 2, 1);
    randomBand(lu, random, 10.0);
    for (int64_t i = std::max<int64_t>(0, zero - 1); i <= std::min<int64_t>(9, zero + 2); ++i)
      lu.storage()[static_cast<size_t>(lu.offset(i, zero))] = 0.0;
    EXPECT_EQ(lu.factor(), zero);
  }
}

// clear() makes the matrix new: a second factorization of other values is that matrix's.
TEST(BandLu, ClearedAndWrittenAgainItFactorsTheNewMatrix) {
  std::mt19937 random(13);
  BandLu lu(25, 2, 2);
  randomBand(lu, random, 1e-2);
  ASSERT_EQ(lu.factor(), -1);
  Eigen::MatrixXd A = randomBand(lu, random, 1.0);
  ASSERT_EQ(lu.factor(), -1);
  std::vector<double> x(25, 1.0);
  lu.solve(x);
  Eigen::VectorXd got = Eigen::Map<Eigen::VectorXd>(x.data(), 25);
  EXPECT_LT((A * got - Eigen::VectorXd::Ones(25)).norm(), 1e-11 * A.norm() * got.norm());
}

}  // namespace
}  // namespace qdot::rt::test
