// Consistent y'(t0) without IDACalcIC (ida/DiagonalRates.h): which matrices qualify, the step and
// its acceptance test, and a session taking it exactly where it is exact and falling back to
// IDACalcIC where it is not. References: the rates each model's equations give in closed form.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "HandModels.h"
#include "ida/DiagonalRates.h"
#include "ida/IdaSession.h"

namespace qdot::rt::test {
namespace {

// Two unknowns, CSC with every entry present: columns {0: rows 0, 1}, {1: rows 0, 1}.
const std::vector<int32_t> kStarts = {0, 2, 4}, kRows = {0, 1, 0, 1};

std::optional<DiagonalRates> ratesOf(std::vector<double> at0, std::vector<double> at1) {
  return diagonalRates<int32_t>(kStarts, kRows, at0, at1);
}

TEST(DiagonalRates, AreFoundUpToTheOrderOfTheRows) {
  // dF/dy' = diag(2, 3): J(1) - J(0) on the diagonal only.
  auto plain = ratesOf({5, 1, -1, 0}, {7, 1, -1, 3});
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->rowOf, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(plain->d, (std::vector<double>{2, 3}));
  // Rows the other way round (a kinematic row after the dynamic one): column 0 in row 1.
  auto swapped = ratesOf({0, 4, 1, 0}, {0, 8, 3, 0});
  ASSERT_TRUE(swapped);
  EXPECT_EQ(swapped->rowOf, (std::vector<uint32_t>{1, 0}));
  EXPECT_EQ(swapped->d, (std::vector<double>{4, 2}));
}

// A large matrix (from 65 536 columns) is searched in two halves on two threads: the same rates,
// and a problem in either half still refuses it. Tridiagonal pattern, dF/dy' = diag(c + 1) placed
// in row n − 1 − c (rows reversed, as a kinematic row after its dynamic one would put it).
TEST(DiagonalRates, ALargeMatrixIsSearchedInTwoHalves) {
  const int32_t n = 100001;
  std::vector<int32_t> starts{0}, rows;
  for (int32_t c = 0; c < n; ++c) {
    for (int32_t r : {n - 2 - c, n - 1 - c, n - c})
      if (r >= 0 && r < n) rows.push_back(r);
    starts.push_back(static_cast<int32_t>(rows.size()));
  }
  std::vector<double> at0(rows.size()), at1;
  for (size_t k = 0; k < at0.size(); ++k) at0[k] = std::sin(0.1 * static_cast<double>(k));
  at1 = at0;
  std::vector<size_t> diagonal(n);
  for (int32_t c = 0; c < n; ++c)
    for (int32_t k = starts[c]; k < starts[c + 1]; ++k)
      if (rows[k] == n - 1 - c) diagonal[c] = static_cast<size_t>(k), at1[k] += c + 1;
  auto rates = diagonalRates<int32_t>(starts, rows, at0, at1);
  ASSERT_TRUE(rates);
  for (int32_t c = 0; c < n; ++c) {
    ASSERT_EQ(rates->rowOf[c], static_cast<uint32_t>(n - 1 - c)) << c;
    ASSERT_EQ(rates->d[c], (at0[diagonal[c]] + (c + 1)) - at0[diagonal[c]]) << c;
  }
  for (int32_t c : {10, n - 10}) {  // a second entry in a column of the first, then of the second half
    std::vector<double> coupled = at1;
    coupled[diagonal[c] + 1] += 1;
    EXPECT_FALSE(diagonalRates<int32_t>(starts, rows, at0, coupled)) << c;
    std::vector<double> missing = at1;  // a column without its entry
    missing[diagonal[c]] = at0[diagonal[c]];
    EXPECT_FALSE(diagonalRates<int32_t>(starts, rows, at0, missing)) << c;
  }
  // Two columns with their entries in the same row (checked after the halves): each row is one column's.
  std::vector<double> shared = at1;
  shared[diagonal[n - 10]] = at0[diagonal[n - 10]];
  size_t other = diagonal[n - 10] == static_cast<size_t>(starts[n - 10]) ? diagonal[n - 10] + 1 : diagonal[n - 10] - 1;
  shared[other] += 1;  // column n − 10's entry now in row 8, column n − 9's
  EXPECT_FALSE(diagonalRates<int32_t>(starts, rows, at0, shared));
}

TEST(DiagonalRates, AreRefusedForAnyOtherMatrix) {
  EXPECT_FALSE(ratesOf({0, 0, 0, 0}, {1, 1, 0, 1}));  // two entries in column 0 (a coupled mass matrix)
  EXPECT_FALSE(ratesOf({0, 0, 0, 0}, {1, 0, 1, 0}));  // two in row 0, none in row 1
  EXPECT_FALSE(ratesOf({0, 0, 1, 0}, {1, 0, 1, 0}));  // column 1 has no y' (an algebraic unknown)
  // |dF/dy| = 1e300 hides whatever dF/dy' adds there: not known to be diagonal.
  EXPECT_FALSE(ratesOf({1e300, 0, 0, 0}, {1e300, 0, 0, 1}));
  EXPECT_FALSE(ratesOf({0, 0, 0, 0}, {INFINITY, 0, 0, 1}));
}

TEST(DiagonalRates, TheStepAndItsTestAreIdaCalcIcs) {
  DiagonalRates r{{1, 0}, {4, 2}};
  std::vector<double> yp = {1, 1};
  stepRates(r, std::vector<double>{6, 8}, yp);  // yp[0] -= F[1]/4, yp[1] -= F[0]/2
  EXPECT_EQ(yp, (std::vector<double>{-1, -2}));
  std::vector<double> y = {1, 1}, atol = {1e-6, 1e-6};
  // Corrections F/d times the span 0.1 in weights 1/(1e-6 * 1 + 1e-6): 0.0033 is the limit.
  double limit = 0.0033 * 2e-6 / 0.1;
  EXPECT_TRUE(ratesConverged(r, std::vector<double>{0.9 * limit * 2, 0.9 * limit * 4}, y, 1e-6, atol, 0.1));
  EXPECT_FALSE(ratesConverged(r, std::vector<double>{1.1 * limit * 2, 1.1 * limit * 4}, y, 1e-6, atol, 0.1));
}

// x'' = -omega^2 x from x = 1, v = 0: v'(0) = -omega^2, by the division alone.
TEST(DiagonalRates, TheSessionTakesThemWhereTheyAreExact) {
  HandModel osc = oscillator(3.0);
  IdaSession session(osc.abi(), {3.0}, {});
  session.initialize(0.1);
  EXPECT_EQ(session.initialValueMethod(), InitialValueMethod::DiagonalRates);
  EXPECT_EQ(session.yp()[0], 0.0);
  EXPECT_EQ(session.yp()[1], -9.0);
}

// F = y'^3 + y' - 2 (y' = 1 is its only real root): the division from y' = 0 gives y' = 2, where
// F = 8 is far from 0, so IDACalcIC runs from the start values and finds y' = 1.
HandModel cubicRate() {
  HandModel m;
  m.name = "cubic";
  m.variables = {"x"};
  m.differential = {1};
  m.start = {0.5};
  m.entries = {{0, 0}};
  m.residual = [](double, const double*, const double* yp, const double*, double* F) {
    F[0] = yp[0] * yp[0] * yp[0] + yp[0] - 2;
    return 0;
  };
  m.jacobian = [](double, const double*, const double* yp, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj * (3 * yp[0] * yp[0] + 1);
    return 0;
  };
  return m;
}

TEST(DiagonalRates, ANonLinearRateFallsBackToIdaCalcIC) {
  HandModel m = cubicRate();
  IdaSession session(m.abi(), {}, {});
  session.initialize(0.1);
  EXPECT_EQ(session.initialValueMethod(), InitialValueMethod::CalcIC);
  EXPECT_NEAR(session.yp()[0], 1.0, 1e-6);
  EXPECT_EQ(session.y()[0], 0.5);
  session.advanceTo(1.0);
  EXPECT_NEAR(session.y()[0], 1.5, 1e-5);  // x = 0.5 + t
}

// A coupled mass matrix: x' + v' = 1, x' - v' = 0 give x' = v' = 1/2 (IDACalcIC's job).
TEST(DiagonalRates, ACoupledMassMatrixFallsBackToIdaCalcIC) {
  HandModel m;
  m.name = "coupled";
  m.variables = {"x", "v"};
  m.differential = {1, 1};
  m.start = {0.0, 0.0};
  m.entries = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  m.residual = [](double, const double*, const double* yp, const double*, double* F) {
    F[0] = yp[0] + yp[1] - 1;
    F[1] = yp[0] - yp[1];
    return 0;
  };
  m.jacobian = [](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj, J(0, 1) = cj, J(1, 0) = cj, J(1, 1) = -cj;
    return 0;
  };
  IdaSession session(m.abi(), {}, {});
  session.initialize(0.1);
  EXPECT_EQ(session.initialValueMethod(), InitialValueMethod::CalcIC);
  EXPECT_NEAR(session.yp()[0], 0.5, 1e-9);
  EXPECT_NEAR(session.yp()[1], 0.5, 1e-9);
}

}  // namespace
}  // namespace qdot::rt::test
