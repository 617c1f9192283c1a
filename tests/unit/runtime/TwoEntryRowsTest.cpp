// Two-entry rows eliminated before KLU (ida/TwoEntryRows.h, ida/ReducedKlu.h): which rows qualify,
// the reduced pattern of a mechanics model (a chain's 2n × 2n Newton matrix becomes n × n
// tridiagonal), reduced solves equal to dense LU of the whole matrix (Eigen) whichever entry of a
// pair row is the pivot, the SUNDIALS solver through setup, refactorization and a singular row,
// and a session on a spring chain that follows its closed-form normal mode.
#include <gtest/gtest.h>

#include <nvector/nvector_serial.h>
#include <sundials/sundials_context.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "HandModels.h"
#include "ida/ReducedKlu.h"
#include "ida/TwoEntryRows.h"
#include "sim/Simulation.h"

namespace qdot::rt::test {
namespace {

/// A square matrix given by (row, column, value) entries, in CSC form (rows sorted per column).
struct Sparse {
  int64_t n;
  std::vector<int64_t> starts, rows;
  std::vector<double> values;
  Sparse(int64_t size, std::vector<std::tuple<int64_t, int64_t, double>> entries) : n(size), starts(size + 1, 0) {
    std::sort(entries.begin(), entries.end(), [](auto a, auto b) {
      return std::pair(std::get<1>(a), std::get<0>(a)) < std::pair(std::get<1>(b), std::get<0>(b));
    });
    for (auto [r, c, v] : entries) ++starts[c + 1], rows.push_back(r), values.push_back(v);
    for (int64_t c = 0; c < n; ++c) starts[c + 1] += starts[c];
  }
  CscPattern csc() const { return {starts, rows}; }
  Eigen::MatrixXd dense() const {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(n, n);
    for (int64_t c = 0; c < n; ++c)
      for (int64_t k = starts[c]; k < starts[c + 1]; ++k) A(rows[k], c) += values[k];
    return A;
  }
};

/// The Newton matrix of a chain of n masses (m, springs k, dampers d, first one tied to a wall) as
/// qdot lays it out: unknowns x[0..n), v[n..2n); rows i: cj x_i − v_i (kinematic), rows n + i: the
/// equation of motion m v'_i + forces.
Sparse chainMatrix(int64_t n, double cj, double m = 1, double k = 1000, double d = 0.5) {
  std::vector<std::tuple<int64_t, int64_t, double>> e;
  for (int64_t i = 0; i < n; ++i) {
    e.emplace_back(i, i, cj);
    e.emplace_back(i, n + i, -1.0);
    double own = i + 1 < n ? 2 : 1;  // the last mass has one spring
    e.emplace_back(n + i, i, own * k);
    e.emplace_back(n + i, n + i, m * cj + own * d);
    if (i > 0) e.emplace_back(n + i, i - 1, -k), e.emplace_back(n + i, n + i - 1, -d);
    if (i + 1 < n) e.emplace_back(n + i, i + 1, -k), e.emplace_back(n + i, n + i + 1, -d);
  }
  return Sparse(2 * n, e);
}

/// x from the reduced system (S solved densely) for J x = b.
Eigen::VectorXd reducedSolve(const TwoEntryRows& rows, const Sparse& J, const Eigen::VectorXd& b, PairPivots& pivots) {
  std::vector<double> S(rows.rowIndices.size());
  EXPECT_EQ(reduceMatrix(rows, J.starts, J.rows, J.values, S, pivots), -1);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(rows.size(), rows.size());
  for (int64_t c = 0; c < rows.size(); ++c)
    for (int64_t k = rows.columnStarts[c]; k < rows.columnStarts[c + 1]; ++k) dense(rows.rowIndices[k], c) = S[k];
  std::vector<double> rhs(rows.size()), pairRhs(rows.pairs()), bv(b.data(), b.data() + b.size());
  reduceRightHandSide(rows, pivots, bv, rhs, pairRhs);
  Eigen::VectorXd s = dense.partialPivLu().solve(Eigen::Map<Eigen::VectorXd>(rhs.data(), rows.size()));
  std::vector<double> x(J.n);
  completeSolution(rows, pivots, {s.data(), static_cast<size_t>(s.size())}, pairRhs, x);
  return Eigen::Map<Eigen::VectorXd>(x.data(), J.n);
}

TEST(TwoEntryRows, AChainsKinematicRowsLeaveItsTridiagonalMatrix) {
  const int64_t n = 6;
  Sparse J = chainMatrix(n, 100.0);
  std::optional<TwoEntryRows> rows = findTwoEntryRows(J.csc());
  ASSERT_TRUE(rows);
  ASSERT_EQ(rows->pairs(), n);
  EXPECT_EQ(rows->size(), n);
  for (int64_t q = 0; q < n; ++q) {
    EXPECT_EQ(rows->row[q], q);  // der(x_i) − v_i, eliminated with its diagonal x_i
    EXPECT_EQ(rows->partner[q], n + q);
    EXPECT_EQ(rows->reducedIndex[n + q], q);  // S's index q is v_q, standing for x_q as well
    EXPECT_EQ(rows->reducedColumn(q), q);
  }
  // S = m cj + d + k/cj ... : tridiagonal, 3n − 2 entries, its diagonal zero-free
  EXPECT_EQ(static_cast<int64_t>(rows->rowIndices.size()), 3 * n - 2);
  EXPECT_EQ(naturalBandwidth(rows->reducedPattern()), 1);
  EXPECT_TRUE(zeroFreeDiagonal(rows->reducedPattern()));
  // the kinematic rows' entries go nowhere in S; every other entry does
  for (int64_t c = 0; c < J.n; ++c)
    for (int64_t k = J.starts[c]; k < J.starts[c + 1]; ++k) EXPECT_EQ(rows->target[k] < 0, J.rows[k] < n) << k;
}

TEST(TwoEntryRows, OnlyRowsWithTheirDiagonalAndAFreePartnerQualify) {
  // row 0: (0,0), (0,3) → a pair; row 1: (1,2), (1,3): no diagonal; row 2: (2,2), (2,3): 3 is
  // taken by pair 0; row 3: one entry; row 4: (4,4), (4,5) → a pair; row 5: three entries.
  Sparse J(6, {{0, 0, 1.}, {0, 3, 2.}, {1, 2, 1.}, {1, 3, 1.}, {2, 2, 1.}, {2, 3, 1.}, {3, 3, 1.}, {4, 4, 3.},
               {4, 5, 1.}, {5, 1, 1.}, {5, 4, 1.}, {5, 5, 1.}});
  std::optional<TwoEntryRows> rows = findTwoEntryRows(J.csc());
  ASSERT_TRUE(rows);
  EXPECT_EQ(rows->row, (std::vector<int32_t>{0, 4}));
  EXPECT_EQ(rows->partner, (std::vector<int32_t>{3, 5}));
  EXPECT_EQ(rows->size(), 4);
  EXPECT_EQ(rows->originalIndex, (std::vector<int32_t>{1, 2, 3, 5}));
  // a pattern without any such row: none (KLU takes the whole matrix)
  EXPECT_FALSE(findTwoEntryRows(Sparse(3, {{0, 0, 1.}, {1, 1, 1.}, {2, 2, 1.}, {0, 1, 1.}, {0, 2, 1.}}).csc()));
  // a diagonal given twice is one column, not two
  EXPECT_FALSE(findTwoEntryRows(Sparse(2, {{0, 0, 1.}, {0, 0, 1.}, {1, 1, 1.}}).csc()));
}

// Large cj (small steps): each kinematic row is solved for its x (pivot cj); small cj (long steps
// of a stiff run): for its v (pivot −1). Either way the solution is J⁻¹ b to rounding.
TEST(TwoEntryRows, TheReducedSolveIsTheWholeMatrixSolveWhicheverThePivot) {
  std::mt19937 random(3);
  std::uniform_real_distribution<double> value(-1, 1);
  for (double cj : {1e6, 10.0, 0.3, 1e-4}) {
    Sparse J = chainMatrix(40, cj);
    std::optional<TwoEntryRows> rows = findTwoEntryRows(J.csc());
    ASSERT_TRUE(rows);
    Eigen::VectorXd b(J.n);
    for (int64_t i = 0; i < J.n; ++i) b[i] = value(random);
    PairPivots pivots;
    Eigen::VectorXd x = reducedSolve(*rows, J, b, pivots);
    Eigen::VectorXd exact = J.dense().partialPivLu().solve(b);
    EXPECT_LT((x - exact).norm(), 1e-9 * exact.norm()) << "cj = " << cj;
    EXPECT_EQ(pivots.solvesRow[0], cj >= 1 ? 1 : 0) << "cj = " << cj;
  }
}

// Random unsymmetric matrices with pair rows scattered through them (diagonally dominant, so that
// the whole matrix is well conditioned), and pair rows whose partner comes before them.
TEST(TwoEntryRows, RandomMatricesWithScatteredPairRowsSolveAsAWhole) {
  std::mt19937 random(11);
  std::uniform_real_distribution<double> value(-1, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const int64_t n = 30;
    std::vector<std::tuple<int64_t, int64_t, double>> e;
    std::set<int64_t> used;
    for (int64_t i = 0; i < n; ++i) {
      int64_t partner = std::uniform_int_distribution<int64_t>(0, n - 1)(random);
      if (partner != i && !used.count(i) && !used.count(partner) && value(random) > 0) {
        used.insert(i), used.insert(partner);
        e.emplace_back(i, i, 3 * value(random));  // either entry may be the larger
        e.emplace_back(i, partner, 3 * value(random));
        continue;
      }
      e.emplace_back(i, i, 10 + value(random));
      for (int extra = 0; extra < 4; ++extra) {
        int64_t j = std::uniform_int_distribution<int64_t>(0, n - 1)(random);
        if (j != i) e.emplace_back(i, j, value(random));
      }
    }
    Sparse J(n, e);
    std::optional<TwoEntryRows> rows = findTwoEntryRows(J.csc());
    if (!rows) continue;
    Eigen::MatrixXd A = J.dense();
    if (std::abs(A.determinant()) < 1e-8) continue;
    Eigen::VectorXd b = Eigen::VectorXd::NullaryExpr(n, [&] { return value(random); });
    PairPivots pivots;
    Eigen::VectorXd x = reducedSolve(*rows, J, b, pivots);
    EXPECT_LT((A * x - b).norm(), 1e-10 * (A.norm() * x.norm() + b.norm())) << "trial " << trial;
  }
}

TEST(TwoEntryRows, AZeroPairRowIsReportedAsSingular) {
  Sparse J(3, {{0, 0, 0.}, {0, 2, 0.}, {1, 1, 1.}, {2, 2, 1.}, {2, 0, 1.}});
  std::optional<TwoEntryRows> rows = findTwoEntryRows(J.csc());
  ASSERT_TRUE(rows);
  std::vector<double> S(rows->rowIndices.size());
  PairPivots pivots;
  EXPECT_EQ(reduceMatrix(*rows, J.starts, J.rows, J.values, S, pivots), 0);
}

/// The chain matrix with its masses numbered in the order `mass` (x of mass i at mass[i], v at
/// n + mass[i]): the same pair rows, but S is a band only in another order than its own.
Sparse scrambledChain(int64_t n, double cj, const std::vector<int64_t>& mass, double m = 1, double k = 1000,
                      double d = 0.5) {
  Sparse J = chainMatrix(n, cj, m, k, d);
  auto at = [&](int64_t i) { return i < n ? mass[i] : n + mass[i - n]; };
  std::vector<std::tuple<int64_t, int64_t, double>> e;
  for (int64_t c = 0; c < J.n; ++c)
    for (int64_t k2 = J.starts[c]; k2 < J.starts[c + 1]; ++k2) e.emplace_back(at(J.rows[k2]), at(c), J.values[k2]);
  return Sparse(J.n, e);
}

enum class ReducedFactor { OwnBand, PermutedBand, Klu };

/// The SUNDIALS solver on a chain matrix: first setup, then new values (KLU: refactorization),
/// each solve against Eigen's dense LU of the whole matrix; then a singular matrix. S is factored
/// as a band in its own order, as a band in RCM's order, or (the band taken from the plan) by KLU.
void solveThroughSetups(ReducedFactor how) {
  SUNContext context = nullptr;
  ASSERT_EQ(SUNContext_Create(nullptr, &context), 0);
  const int64_t n = 50;
  std::vector<int64_t> mass(n);
  for (int64_t i = 0; i < n; ++i) mass[i] = how == ReducedFactor::PermutedBand ? (17 * i) % n : i;  // 17 and 50 coprime
  auto matrix = [&](double cj, double m = 1, double k = 1000, double d = 0.5) { return scrambledChain(n, cj, mass, m, k, d); };
  Sparse J = matrix(1e3);
  std::optional<ReducedKluPlan> plan = planReducedKlu(J.csc());
  ASSERT_TRUE(plan);
  ASSERT_TRUE(plan->band);  // S is tridiagonal: in its own order (no search) or RCM's, bandwidth 1
  EXPECT_EQ(plan->band->bandwidth, 1);
  bool own = std::is_sorted(plan->band->order.begin(), plan->band->order.end());
  EXPECT_EQ(own, how != ReducedFactor::PermutedBand);
  if (how == ReducedFactor::Klu) plan->band.reset();
  SUNMatrix A = SUNSparseMatrix(J.n, J.n, static_cast<sunindextype>(J.rows.size()), CSC_MAT, context);
  std::copy(J.starts.begin(), J.starts.end(), SUNSparseMatrix_IndexPointers(A));
  std::copy(J.rows.begin(), J.rows.end(), SUNSparseMatrix_IndexValues(A));
  SUNLinearSolver solver = reducedKluSolver(std::move(*plan), context);
  ASSERT_NE(solver, nullptr);
  ASSERT_EQ(SUNLinSolInitialize(solver), 0);
  N_Vector x = N_VNew_Serial(J.n, context), b = N_VNew_Serial(J.n, context);
  for (double cj : {1e3, 2e3, 0.5}) {
    Sparse now = matrix(cj);
    std::copy(now.values.begin(), now.values.end(), SUNSparseMatrix_Data(A));
    ASSERT_EQ(SUNLinSolSetup(solver, A), 0) << "cj = " << cj;
    Eigen::VectorXd rhs(J.n);
    for (int64_t i = 0; i < J.n; ++i) rhs[i] = N_VGetArrayPointer(b)[i] = std::sin(0.7 * i) + 0.1;
    ASSERT_EQ(SUNLinSolSolve(solver, A, x, b, 0.0), 0);
    Eigen::VectorXd exact = now.dense().partialPivLu().solve(rhs);
    Eigen::VectorXd got = Eigen::Map<Eigen::VectorXd>(N_VGetArrayPointer(x), J.n);
    EXPECT_LT((got - exact).norm(), 1e-10 * exact.norm()) << "cj = " << cj;
  }
  // a singular matrix: the two masses' rows dependent (a zero stiffness and mass, no damper)
  Sparse singular = matrix(0.0, 0.0, 0.0, 0.0);
  std::copy(singular.values.begin(), singular.values.end(), SUNSparseMatrix_Data(A));
  EXPECT_NE(SUNLinSolSetup(solver, A), 0);
  int64_t column = reducedKluSingularColumn(solver);
  EXPECT_GE(column, 0);
  EXPECT_LT(column, J.n);
  N_VDestroy(x), N_VDestroy(b);
  SUNLinSolFree(solver);
  SUNMatDestroy(A);
  SUNContext_Free(&context);
}

TEST(ReducedKlu, SolvesThroughSetupsWithSAsABandInItsOwnOrder) { solveThroughSetups(ReducedFactor::OwnBand); }
TEST(ReducedKlu, SolvesThroughSetupsWithSAsABandInAnotherOrder) { solveThroughSetups(ReducedFactor::PermutedBand); }
TEST(ReducedKlu, SolvesThroughSetupsAndRefactorizationsWithKlu) { solveThroughSetups(ReducedFactor::Klu); }

// The singular column named is an unknown whose column of J is zero in the reduced system: a
// chain whose masses 0..n-1 have zero mass, stiffness and damping has S = 0 (every column). A band
// factorization stops at its first column; that column stands for x or v of the mass there.
TEST(ReducedKlu, TheSingularColumnOfABandIsAnUnknownOfItsMass) {
  SUNContext context = nullptr;
  ASSERT_EQ(SUNContext_Create(nullptr, &context), 0);
  const int64_t n = 8;
  Sparse J = chainMatrix(n, 1.0, 0.0, 0.0, 0.0);
  std::optional<ReducedKluPlan> plan = planReducedKlu(J.csc());
  ASSERT_TRUE(plan && plan->band);
  SUNMatrix A = SUNSparseMatrix(J.n, J.n, static_cast<sunindextype>(J.rows.size()), CSC_MAT, context);
  std::copy(J.starts.begin(), J.starts.end(), SUNSparseMatrix_IndexPointers(A));
  std::copy(J.rows.begin(), J.rows.end(), SUNSparseMatrix_IndexValues(A));
  std::copy(J.values.begin(), J.values.end(), SUNSparseMatrix_Data(A));
  SUNLinearSolver solver = reducedKluSolver(std::move(*plan), context);
  ASSERT_EQ(SUNLinSolInitialize(solver), 0);
  EXPECT_NE(SUNLinSolSetup(solver, A), 0);
  int64_t column = reducedKluSingularColumn(solver);
  EXPECT_TRUE(column == 0 || column == n) << column;  // x or v of the first mass
  SUNLinSolFree(solver);
  SUNMatDestroy(A);
  SUNContext_Free(&context);
}

/// n masses (m, springs k, the first tied to a wall, no damping) as qdot's DAE: x' − v = 0,
/// m v' + K x = 0. Started in normal mode j at rest: x_i(t) = cos(ω t) sin(θ i), θ = (2j − 1)π/(2n + 1),
/// ω = 2 √(k/m) sin(θ/2) (the fixed–free chain; examples/vibration/spring_chain.qd).
HandModel springChain(int n, int mode, double m, double k) {
  HandModel model;
  model.name = "spring chain";
  double theta = (2 * mode - 1) * std::numbers::pi / (2 * n + 1);
  for (int i = 0; i < n; ++i) model.variables.push_back("x[" + std::to_string(i + 1) + "]");
  for (int i = 0; i < n; ++i) model.variables.push_back("v[" + std::to_string(i + 1) + "]");
  model.differential.assign(2 * n, 1);
  model.start.assign(2 * n, 0.0);
  for (int i = 0; i < n; ++i) model.start[i] = std::sin(theta * (i + 1));
  for (int i = 0; i < n; ++i) {
    model.entries.emplace_back(i, i), model.entries.emplace_back(i, n + i);
    model.entries.emplace_back(n + i, n + i);
    for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j) model.entries.emplace_back(n + i, j);
  }
  auto force = [n, k](const double* x, int i) {
    double left = i > 0 ? x[i - 1] : 0, right = i + 1 < n ? x[i + 1] - x[i] : 0;
    return k * (x[i] - left) - k * right;
  };
  model.residual = [n, m, force](double, const double* y, const double* yp, const double*, double* F) {
    for (int i = 0; i < n; ++i) F[i] = yp[i] - y[n + i], F[n + i] = m * yp[n + i] + force(y, i);
    return 0;
  };
  model.jacobian = [n, m, k](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    for (int i = 0; i < n; ++i) {
      J(i, i) = cj, J(i, n + i) = -1, J(n + i, n + i) = m * cj;
      J(n + i, i) = i + 1 < n ? 2 * k : k;
      if (i > 0) J(n + i, i - 1) = -k;
      if (i + 1 < n) J(n + i, i + 1) = -k;
    }
    return 0;
  };
  return model;
}

/// A chain of n masses (x first, then v) run on KLU to `stop`, with or without its kinematic rows
/// eliminated (every one of them when they are); the largest |x_i − exact(t, i)| over the rows.
struct ChainRun {
  SimulationResult result;
  double worst = 0;
  std::vector<double> last;  ///< the last row
};
ChainRun runChainOnKlu(HandModel model, int n, double stop, double interval, double rtol, bool eliminate,
                       const std::function<double(double, int)>& exact) {
  SimulationSettings s;
  s.stop = stop, s.interval = interval, s.rtol = rtol;
  s.linearSolver = LinearSolverKind::Klu;
  s.eliminateTwoEntryRows = eliminate;
  MemorySink sink;
  ChainRun run{simulate(model.abi(), s, sink)};
  EXPECT_TRUE(run.result.success) << run.result.message;
  EXPECT_EQ(run.result.eliminatedRows, eliminate ? n : 0);
  for (std::size_t row = 0; row < sink.rows.size(); ++row)
    for (int i = 0; i < n; ++i) run.worst = std::max(run.worst, std::abs(sink.rows[row][i] - exact(sink.times[row], i)));
  if (!sink.rows.empty()) run.last = sink.rows.back();
  return run;
}

TEST(ReducedKlu, ASpringChainSessionFollowsItsNormalMode) {
  const int n = 400, mode = 3;
  const double m = 2, k = 500, rtol = 1e-8;
  double theta = (2 * mode - 1) * std::numbers::pi / (2 * n + 1), omega = 2 * std::sqrt(k / m) * std::sin(theta / 2);
  std::vector<std::vector<double>> runs;
  for (bool eliminate : {true, false}) {
    ChainRun run = runChainOnKlu(springChain(n, mode, m, k), n, 2, 0.5, rtol, eliminate, [&](double t, int i) {
      return std::cos(omega * t) * std::sin(theta * (i + 1));
    });
    ASSERT_TRUE(run.result.success);
    std::printf("  [measured] spring chain n = %d, mode %d, rows eliminated: %s: max |x − exact| %.3g\n", n, mode,
                eliminate ? "yes" : "no", run.worst);
    EXPECT_LT(run.worst, 1000 * rtol);
    runs.push_back(run.last);
  }
  for (int i = 0; i < n; ++i) EXPECT_NEAR(runs[0][i], runs[1][i], 100 * rtol) << i;
}

/// springChain with a damper c on every mass against the ground: m v' + c v + K x = 0.
HandModel dampedChain(int n, int mode, double m, double k, double c) {
  HandModel model = springChain(n, mode, m, k);
  auto spring = model.residual;
  model.residual = [n, c, spring](double t, const double* y, const double* yp, const double* p, double* F) {
    spring(t, y, yp, p, F);
    for (int i = 0; i < n; ++i) F[n + i] += c * y[n + i];
    return 0;
  };
  auto springJ = model.jacobian;
  model.jacobian = [n, m, c, springJ](double t, const double* y, const double* yp, const double* p, double cj,
                                      JacobianValues& J) {
    springJ(t, y, yp, p, cj, J);
    for (int i = 0; i < n; ++i) J(n + i, n + i) = m * cj + c;
    return 0;
  };
  return model;
}

// Stiff and long: every mode of the chain is overdamped, the slowest decays with e^(−λt), λ the
// slower root of m s² + c s + k_j = 0 (k_j = m ω_j²), so that the steps grow to hundreds of seconds
// and the kinematic rows' pivot passes from cj to −1. Started in mode 1 the chain stays in it:
// x_i(t) = a(t) sin(θ i), a'' m + a' c + a k_1 = 0, a(0) = 1, a'(0) = 0.
TEST(ReducedKlu, AStiffOverdampedChainOverALongHorizonFollowsItsSlowestMode) {
  const int n = 300;
  const double m = 1, k = 1e4, c = 1e4, rtol = 1e-7;
  double theta = std::numbers::pi / (2 * n + 1), omega2 = 4 * k / m * std::pow(std::sin(theta / 2), 2);
  // roots of m s² + c s + m ω² = 0, both negative: a(t) = (s2 e^(s1 t) − s1 e^(s2 t)) / (s2 − s1)
  double disc = std::sqrt(c * c - 4 * m * m * omega2);
  double s1 = (-c + disc) / (2 * m), s2 = (-c - disc) / (2 * m);
  auto amplitude = [&](double t) { return (s2 * std::exp(s1 * t) - s1 * std::exp(s2 * t)) / (s2 - s1); };
  std::vector<double> last;
  for (bool eliminate : {true, false}) {
    ChainRun run = runChainOnKlu(dampedChain(n, 1, m, k, c), n, 4000, 500, rtol, eliminate, [&](double t, int i) {
      return amplitude(t) * std::sin(theta * (i + 1));
    });
    ASSERT_TRUE(run.result.success);
    const SimulationResult& r = run.result;
    EXPECT_GT(r.stats.lastStep, 10.0);  // long steps: cj < 0.1, the −1 entries are the pivots
    std::printf("  [measured] overdamped chain n = %d to t = 4000 s, rows eliminated: %s: max |x − exact| %.3g, last "
                "step %.3g s, %ld steps\n",
                n, eliminate ? "yes" : "no", run.worst, r.stats.lastStep, r.stats.steps);
    EXPECT_LT(run.worst, 10 * rtol);  // a(4000) ≈ 0.9 (the slow mode barely decays; the fast ones are gone)
    if (eliminate) last = run.last;
    else
      for (int i = 0; i < n; ++i) EXPECT_NEAR(last[i], run.last[i], rtol) << i;
  }
}

}  // namespace
}  // namespace qdot::rt::test
