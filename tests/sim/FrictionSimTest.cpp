// Smoothed dry friction written as a dissipation function D = c ε log(cosh(ẋ/ε)) (issue 14): its
// derivative must be the overflow-free c tanh(ẋ/ε), so the run goes to the end (cosh(ẋ/ε)
// overflows once |ẋ| > 710 ε) and gives the same trajectory as the force written with tanh. Physics:
// Coulomb damping takes 2c/k off the amplitude every half period (x0 = 0.3 → −0.26 → 0.22).
#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// The extremum of x between times a and b (the smallest if `minimum`).
double extremum(const RunResult& r, double a, double b, bool minimum) {
  double best = minimum ? INFINITY : -INFINITY;
  for (size_t i = 0; i < r.rows; ++i)
    if (r.time()[i] >= a && r.time()[i] <= b) best = minimum ? std::min(best, r.col("x")[i]) : std::max(best, r.col("x")[i]);
  return best;
}

TEST(LogCoshFriction, RunsToTheEndLikeTheTanhForce) {
  auto logcosh = runQdot("tests/sim/models/logcosh_friction.qd", {"--rtol", "1e-8"});
  ASSERT_EQ(logcosh.exitCode, 0) << logcosh.log;
  expectGrid(logcosh, 0, 2, 0.01);
  auto tanh = runQdot("tests/sim/models/tanh_friction.qd", {"--rtol", "1e-8"});
  ASSERT_EQ(tanh.exitCode, 0) << tanh.log;
  ASSERT_EQ(logcosh.rows, tanh.rows);
  for (size_t i = 0; i < logcosh.rows; ++i) EXPECT_NEAR(logcosh.col("x")[i], tanh.col("x")[i], 1e-6);
  const double halfPeriod = M_PI / 10, step = 2 * 2.0 / 100;  // ω = sqrt(k/m) = 10; 2c/k
  EXPECT_NEAR(extremum(logcosh, 0.5 * halfPeriod, 1.5 * halfPeriod, true), -(0.3 - step), 2e-3);
  EXPECT_NEAR(extremum(logcosh, 1.5 * halfPeriod, 2.5 * halfPeriod, false), 0.3 - 2 * step, 2e-3);
}

}  // namespace
}  // namespace qdot::simtest
