// Integrates hand-written models with the whole runtime (IdaSession + simulate) and compares every
// output row with a closed form or a published reference, named in each test. Measured errors are
// printed so the bounds can be judged against them.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "HandModels.h"
#include "sim/Simulation.h"

namespace qdot::rt::test {
namespace {

SimulationSettings settings(double stop, double interval, double rtol, std::vector<double> p) {
  SimulationSettings s;
  s.start = 0;
  s.stop = stop;
  s.interval = interval;
  s.rtol = rtol;
  s.parameters = std::move(p);
  return s;
}

TEST(HandModels, AnalyticJacobiansMatchFiniteDifferences) {
  HandModel osc = oscillator(3.0), dae = bernoulliDae(), rob = robertson(), chain = heatChain(6);
  EXPECT_LT(jacobianMismatch(osc, 0.3, {0.7, -1.1}, {0.2, 0.4}, {3.0}, 17.0), 1e-7);
  EXPECT_LT(jacobianMismatch(dae, 0.3, {0.8, 0.1}, {0.2, 0.0}, {}, 5.0), 1e-7);
  EXPECT_LT(jacobianMismatch(rob, 1.0, {0.9, 3e-5, 0.1}, {-0.01, 1e-6, 0.0}, {}, 100.0), 1e-6);
  EXPECT_LT(jacobianMismatch(chain, 0.0, {0.1, 0.5, -0.2, 0.3, 0.9, 0.4}, std::vector<double>(6, 0.0), {}, 2.0), 1e-6);
}

// Reference: x(t) = cos(omega t), v(t) = -omega sin(omega t), the closed form of x'' = -omega^2 x
// with x(0) = 1, v(0) = 0; energy E = omega^2 / 2 is conserved.
// Bound: a BDF method controls the local error to about rtol per step and the phase error of an
// undamped oscillator adds up over periods; we allow 200 rtol over 10 periods for x and v/omega
// and 400 rtol for E (measured values are printed).
TEST(Oscillator, FollowsTheCosineAtEveryOutputTime) {
  const double omega = 2 * std::numbers::pi, rtol = 1e-8;
  HandModel model = oscillator(omega);
  SimulationSettings s = settings(10.0, 0.01, rtol, {omega});
  s.invariants = true;
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), s, sink);
  ASSERT_TRUE(r.success) << r.message;
  ASSERT_EQ(sink.names, (std::vector<std::string>{"x", "v", "a", "E"}));
  ASSERT_EQ(sink.rows.size(), 1001u);
  double worstX = 0, worstV = 0, worstE = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k) {
    double t = sink.times[k];
    EXPECT_DOUBLE_EQ(t, k == 1000 ? 10.0 : 0.01 * static_cast<double>(k));
    const auto& row = sink.rows[k];
    worstX = std::max(worstX, std::abs(row[0] - std::cos(omega * t)));
    worstV = std::max(worstV, std::abs(row[1] + omega * std::sin(omega * t)) / omega);
    worstE = std::max(worstE, std::abs(row[3] - omega * omega / 2) / (omega * omega / 2));
    EXPECT_DOUBLE_EQ(row[2], -omega * omega * row[0]);  // the output column is the model's output
  }
  std::printf(
      "  oscillator (10 periods, rtol %g): max |x - cos| = %.3g, max |v/w + sin| = %.3g, max dE/E = %.3g, "
      "%ld steps\n",
      rtol, worstX, worstV, worstE, r.stats.steps);
  EXPECT_LT(worstX, 200 * rtol);
  EXPECT_LT(worstV, 200 * rtol);
  EXPECT_LT(worstE, 400 * rtol);  // E is quadratic in the state: twice the relative error
  EXPECT_EQ(r.linearSolver, LinearSolverKind::Dense);
  EXPECT_TRUE(r.computedInitialValues);  // y'(0) = 0 given, but v'(0) = -omega^2
}

// Same closed form with the parameter overridden (omega = 3 instead of the default 2 pi), so the
// parameter vector really reaches the residual and the Jacobian.
TEST(Oscillator, UsesTheGivenParameterValues) {
  HandModel model = oscillator(2 * std::numbers::pi);
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), settings(2.0, 0.5, 1e-8, {3.0}), sink);
  ASSERT_TRUE(r.success) << r.message;
  for (std::size_t k = 0; k < sink.rows.size(); ++k)
    EXPECT_NEAR(sink.rows[k][0], std::cos(3.0 * sink.times[k]), 1e-6) << "t = " << sink.times[k];
}

// Reference: y1 = 2 / (1 + e^t), y2 = y1^2 / 2 (closed form, see bernoulliDae). The start y2 = 0
// is inconsistent, so IDACalcIC must find y2(0) = 1/2 and y1'(0) = -1/2.
TEST(IndexOneDae, MatchesTheClosedFormAfterConsistentInitialisation) {
  const double rtol = 1e-8;
  HandModel model = bernoulliDae();
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), settings(5.0, 0.05, rtol, {}), sink);
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_TRUE(r.computedInitialValues);
  EXPECT_NEAR(sink.rows[0][1], 0.5, 1e-10);
  double worst = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k) {
    double y1 = 2 / (1 + std::exp(sink.times[k]));
    worst = std::max({worst, std::abs(sink.rows[k][0] - y1), std::abs(sink.rows[k][1] - y1 * y1 / 2)});
  }
  std::printf("  index-1 DAE (rtol %g): max error %.3g over %zu rows\n", rtol, worst, sink.rows.size());
  EXPECT_LT(worst, 100 * rtol);
  // y2 is free (not fixed), so changing it is no warning.
  EXPECT_TRUE(r.warnings.empty());
}

// The same DAE with y2's start marked fixed: IDACalcIC still has to change it (an algebraic
// unknown is determined by its equation), and the run says so in a warning.
TEST(IndexOneDae, ChangingAFixedAlgebraicStartIsAWarning) {
  HandModel model = bernoulliDae();
  model.fixed = {1, 1};
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), settings(1.0, 0.5, 1e-6, {}), sink);
  ASSERT_TRUE(r.success) << r.message;
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0],
            "the fixed start value of algebraic y2 (0) was changed to 0.5 to make the initial values consistent");
}

// Reference: s = sin(t) evaluated directly; a model without unknowns (only an output of time)
// needs no integrator, and still gets its rows.
TEST(NoUnknowns, OutputsOfTimeAreWrittenWithoutIda) {
  HandModel model;
  model.outputNames = {"s"};
  model.residual = [](double, const double*, const double*, const double*, double*) { return 0; };
  model.jacobian = [](double, const double*, const double*, const double*, double, JacobianValues&) { return 0; };
  model.outputs = [](double t, const double*, const double*, const double*, double* out) {
    out[0] = std::sin(t);
    return 0;
  };
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), settings(1.0, 0.25, 1e-6, {}), sink);
  ASSERT_TRUE(r.success) << r.message;
  ASSERT_EQ(sink.rows.size(), 5u);
  for (std::size_t k = 0; k < 5; ++k) EXPECT_EQ(sink.rows[k][0], std::sin(0.25 * static_cast<double>(k)));
}

// Reference: the IVP test set's Robertson (ROBER) solution at t = 1e11 (Mazzia & Magherini,
// Test Set for IVP Solvers, release 2.4): y1 = 0.2083340149701255e-7, y2 = 0.8333360770334713e-13,
// y3 = 0.9999999791665050. y1 falls by 8 decades, so, as in the literature, the absolute
// tolerance is set far below the start value's scale (--atol 1e-12, rtol 1e-8). Solved with the
// dense and the KLU solver; both must meet the reference (relative 2e-4 on y1 and y2, absolute
// 5e-12 on y3), agree with each other to 2e-4, and keep y1 + y2 + y3 = 1 (the algebraic equation).
TEST(Robertson, ReachesTheTestSetReferenceWithDenseAndKlu) {
  const double reference[3] = {0.2083340149701255e-7, 0.8333360770334713e-13, 0.9999999791665050};
  std::vector<std::vector<double>> finals;
  for (auto kind : {LinearSolverKind::Dense, LinearSolverKind::Klu}) {
    HandModel model = robertson();
    SimulationSettings s = settings(1e11, 1e10, 1e-8, {});
    s.atol = 1e-12;
    s.linearSolver = kind;
    MemorySink sink;
    SimulationResult r = simulate(model.abi(), s, sink);
    ASSERT_TRUE(r.success) << r.message;
    EXPECT_EQ(r.linearSolver, kind);
    for (const auto& row : sink.rows)
      EXPECT_NEAR(row[0] + row[1] + row[2], 1.0, 1e-12);
    const auto& y = sink.rows.back();
    double e1 = std::abs(y[0] - reference[0]) / reference[0], e2 = std::abs(y[1] - reference[1]) / reference[1];
    double e3 = std::abs(y[2] - reference[2]);
    std::printf("  Robertson %s at 1e11: rel err y1 %.3g, y2 %.3g; abs err y3 %.3g; %ld steps\n",
                std::string(linearSolverName(kind)).c_str(), e1, e2, e3, r.stats.steps);
    EXPECT_LT(e1, 2e-4);
    EXPECT_LT(e2, 2e-4);
    EXPECT_LT(e3, 5e-12);
    finals.push_back(y);
  }
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(finals[0][i], finals[1][i], 2e-4 * std::abs(finals[0][i]));
}

// Reference: x = cos(omega t), v = -omega sin(omega t) with omega = 1e6 (a stiff spring: the
// spring's time scale 1e-6 s against a run of 100 periods) over 100 periods, an output every
// 1/8 period. Positions are O(1) and velocities O(1e6): the per-variable tolerance scales keep
// both resolved. Bound: phase error adds up over the periods, 2000 rtol after 100 periods.
TEST(StiffOscillator, FollowsTheClosedFormOverManyPeriods) {
  const double omega = 1e6, rtol = 1e-9, period = 2 * std::numbers::pi / omega;
  HandModel model = oscillator(omega);
  MemorySink sink;
  SimulationResult r = simulate(model.abi(), settings(100 * period, period / 8, rtol, {omega}), sink);
  ASSERT_TRUE(r.success) << r.message;
  ASSERT_EQ(sink.rows.size(), 801u);
  double worstX = 0, worstV = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k) {
    double t = sink.times[k];
    worstX = std::max(worstX, std::abs(sink.rows[k][0] - std::cos(omega * t)));
    worstV = std::max(worstV, std::abs(sink.rows[k][1] / omega + std::sin(omega * t)));
  }
  std::printf(
      "  stiff oscillator (w = 1e6, 100 periods, rtol %g): max |x - cos| = %.3g, max |v/w + sin| = %.3g, "
      "%ld steps\n",
      rtol, worstX, worstV, r.stats.steps);
  EXPECT_LT(worstX, 2000 * rtol);
  EXPECT_LT(worstV, 2000 * rtol);
}

// Reference: y_i(t) = exp(-lambda t) sin(pi i h), the exact solution of the tridiagonal chain
// (see heatChain) with 10 000 unknowns. Auto must pick KLU (dense would need 800 MB).
TEST(HeatChain, TenThousandCellsWithKluMatchTheEigenmode) {
  const int n = 10000;
  const double rtol = 1e-7, h = 1.0 / (n + 1);
  const double lambda = 4.0 / (h * h) * std::pow(std::sin(std::numbers::pi * h / 2), 2);
  HandModel model = heatChain(n);
  MemorySink sink;
  auto begin = std::chrono::steady_clock::now();
  SimulationResult r = simulate(model.abi(), settings(0.5, 0.05, rtol, {}), sink);
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.linearSolver, LinearSolverKind::Klu);
  ASSERT_EQ(sink.rows.size(), 11u);
  double worst = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k) {
    double decay = std::exp(-lambda * sink.times[k]);
    for (int i = 0; i < n; ++i)
      worst = std::max(worst, std::abs(sink.rows[k][i] - decay * std::sin(std::numbers::pi * (i + 1) * h)));
  }
  std::printf(
      "  heat chain n = %d (KLU, rtol %g): max error %.3g (amplitude at end %.3g), %ld steps, %ld Jacobians, "
      "%.2f s\n",
      n, rtol, worst, std::exp(-lambda * 0.5), r.stats.steps, r.stats.jacobianEvaluations, seconds);
  EXPECT_LT(worst, 100 * rtol);
  EXPECT_LT(seconds, 30.0);  // a few tenths of a second on one core; generous for a loaded machine
}

}  // namespace
}  // namespace qdot::rt::test
