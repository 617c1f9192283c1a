// Heat conduction in a rod by the method of lines (examples/heat/rod.qd), its interior one `for`
// equation compiled as one loop (docs/loops.md), simulated by `qdot run` and compared with the exact
// solution of the semi-discrete system at every output time.
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// n = 50 nodes, a = 1, T_i(0) = sin(π i/(n + 1)): the first eigenvector of the second-difference
// matrix, so T_i(t) = sin(π i/(n + 1)) e^(−λt) with its eigenvalue λ = 4a sin²(π/(2(n + 1))).
// Bound: the decaying mode has amplitude ≤ 1 and no phase to drift, and the tolerance is calibrated
// for the global error (docs/accuracy.md), so |T_i − exact| ≤ 2 rtol (measured: 0.3 rtol at 1e-6,
// 0.03 rtol at 1e-8). The continuous rod's rate a (π/(n + 1))² differs from λ by 3e-4 relative, an
// error of 1e-4 at t = 200: 50 times the bound at rtol 1e-6, so the comparison tells the discrete solution from the continuous one.
TEST(HeatRod, DecaysAsTheFirstModeOfTheSemiDiscreteSystem) {
  const int n = 50;
  const double a = 1, pi = 3.14159265358979;  // the model's π
  const double lambda = 4 * a * std::pow(std::sin(pi / (2 * (n + 1))), 2);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-8}) {
    auto r = runQdot("examples/heat/rod.qd", {"--rtol", num(rtol)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 200, 10);
    double worst = 0;
    for (int i = 1; i <= n; ++i) {
      double shape = std::sin(pi * i / (n + 1));
      auto d = compareColumn(
          r, "T[" + std::to_string(i) + "]", [&](double t) { return shape * std::exp(-lambda * t); },
          [&](double) { return 2 * rtol; });
      worst = std::max(worst, d.maxError);
    }
    EXPECT_LT(worst, previous / 10);
    previous = worst;
  }
}

// The same rod with its start profile given by an initial equation per node (a `for` loop of start
// values, tests/sim/models/rod_initial_profile.qd, whose loop ForEquationTest shows kept): the same
// exact solution, within the same bound.
TEST(HeatRod, AStartProfileByInitialEquationsDecaysAsTheFirstMode) {
  const int n = 50;
  const double a = 1, pi = 3.14159265358979, rtol = 1e-7;
  const double lambda = 4 * a * std::pow(std::sin(pi / (2 * (n + 1))), 2);
  auto r = runQdot("tests/sim/models/rod_initial_profile.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 200, 10);
  for (int i = 1; i <= n; ++i) {
    double shape = std::sin(pi * i / (n + 1));
    compareColumn(
        r, "T[" + std::to_string(i) + "]", [&](double t) { return shape * std::exp(-lambda * t); },
        [&](double) { return 2 * rtol; });
  }
}

// The same rod as an energy balance per node, C T_i' = G (…) (tests/sim/models/rod_capacities.qd,
// n = 40): rows that name their derivative with a factor stay one loop, and the decay rate is
// G/C times the rod's, λ = 4 (G/C) sin²(π/(2(n + 1))). Bound as above.
TEST(HeatRod, AnEnergyBalancePerNodeDecaysAtGOverCTimesTheRate) {
  const int n = 40;
  const double C = 4, G = 2, pi = 3.14159265358979, rtol = 1e-7;
  const double lambda = 4 * (G / C) * std::pow(std::sin(pi / (2 * (n + 1))), 2);
  auto r = runQdot("tests/sim/models/rod_capacities.qd", {"--rtol", num(rtol), "--stats"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 400, 20);
  for (int i = 1; i <= n; ++i) {
    double shape = std::sin(pi * i / (n + 1));
    compareColumn(
        r, "T[" + std::to_string(i) + "]", [&](double t) { return shape * std::exp(-lambda * t); },
        [&](double) { return 2 * rtol; });
  }
  // y' at the start from the diagonal dF/dy' = C (runtime/ida/DiagonalRates.h), not IDACalcIC.
  EXPECT_NE(r.log.find("made consistent directly"), std::string::npos) << r.log;
}

// A diffusivity of 1e300 makes ∂F/∂y so large that J(cj = 1) − J(cj = 0) cannot see the identity
// ∂F/∂y': the start check must not claim that no equation contains der(T[i]) (every row does). The
// run fails (no Newton iteration converges on eigenvalues of 1e300), saying so at t = 0.
TEST(HeatRod, AnAbsurdStiffnessIsNotReportedAsAMissingEquation) {
  auto r = runQdot("examples/heat/rod.qd", {"-p", "a=1e300", "--stop", "1"});
  EXPECT_NE(r.exitCode, 0);
  EXPECT_EQ(r.log.find("no equation contains"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("failed at t = 0"), std::string::npos) << r.log;
}

}  // namespace
}  // namespace qdot::simtest
