// `--solver arkode` and `--solver auto` (issue 11, section 3) on examples with closed forms: the
// L-stable ESDIRK method of runtime/arkode/ against the same references as IDA, the same CSV
// columns, and the refusal of a model that is not an ODE in its derivatives.
#include <cmath>
#include <regex>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// Damped free vibration (examples/vibration/damped_oscillator.qd: m = 1, k = 100, c = 2, x0 = 0.1).
// Reference: x = x0 e^(−ζω0 t)(cos ωd t + ζ/√(1−ζ²) sin ωd t). Bound: oscillationBound (QdotRun.h),
// the same as IDA's test (VibrationSimTest.cpp), and the error falls 10× from rtol 1e-6 to 1e-9.
TEST(Arkode, DampedOscillatorClosedForm) {
  const double m = 1, k = 100, c = 2, x0 = 0.1;
  const double w0 = std::sqrt(k / m), z = c / (2 * std::sqrt(k * m)), wd = w0 * std::sqrt(1 - z * z);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/vibration/damped_oscillator.qd", {"--solver", "arkode", "--rtol", num(rtol)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 5, 0.005);
    auto d = compareColumn(
        r, "x",
        [&](double t) {
          return x0 * std::exp(-z * w0 * t) * (std::cos(wd * t) + z / std::sqrt(1 - z * z) * std::sin(wd * t));
        },
        [&](double t) { return oscillationBound(rtol, x0, 2 * M_PI / wd, t); });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
  }
}

// The pendulum in its angle (tests/stability/models/pendulum.qd, l = 1, g = 9.81, θ0 = 1 rad) on
// both solvers. Reference: the period P = 4 √(l/g) K(sin(θ0/2)), K by the arithmetic–geometric mean;
// the mean spacing of upward zero crossings over 10 periods matches P within 1e-6 relative at rtol
// 1e-8, the energy (invariant column `jacobi`) stays within 100·rtol·m g l per period, and both
// solvers write the same columns.
TEST(Arkode, PendulumPeriodAndEnergyMatchIda) {
  const double g = 9.81, l = 1, theta0 = 1, rtol = 1e-8;
  double a = 1, b = std::cos(theta0 / 2);  // AGM(1, k'), k' = √(1 − k²) = cos(θ0/2)
  for (int i = 0; i < 40; ++i) std::tie(a, b) = std::pair(0.5 * (a + b), std::sqrt(a * b));
  const double period = 4 * std::sqrt(l / g) * M_PI / (2 * a);
  std::vector<std::string> header;
  for (const char* solver : {"ida", "arkode"}) {
    auto r = runQdot("tests/stability/models/pendulum.qd", {"--solver", solver, "--rtol", num(rtol), "--stop",
                                                            num(10 * period + 1), "--invariants"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    if (header.empty()) header = r.header;
    EXPECT_EQ(r.header, header) << solver;
    std::vector<double> crossings = upwardZeroCrossings(r, "theta", "der(theta)");
    ASSERT_EQ(crossings.size(), 10u) << solver;
    EXPECT_NEAR((crossings.back() - crossings.front()) / 9, period, 1e-6 * period) << solver;
    const double mgl = g * l;
    compareColumn(
        r, "jacobi", [&](double) { return -mgl * std::cos(theta0); },
        [&](double time) { return oscillationBound(rtol, mgl, period, time); });
  }
}

// A model with algebraic unknowns (the Cartesian pendulum: a Lagrange multiplier, index reduced) is
// refused by --solver arkode with the reason and the alternative, exit code 3, header written.
TEST(Arkode, RefusesAModelThatIsNotAnOde) {
  auto r = runQdot("examples/constrained/cartesian_pendulum.qd", {"--solver", "arkode"});
  EXPECT_EQ(r.exitCode, 3) << r.log;
  EXPECT_NE(r.log.find("integrates models that are ODEs in their derivatives"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("use --solver ida"), std::string::npos) << r.log;
  EXPECT_EQ(r.rows, 0u);
  EXPECT_FALSE(r.header.empty());
}

// --solver auto says what it picked and why: ARKODE for the stiff forced oscillator (eigenvalues
// −1e5 ± 9.95e5 i at the start), IDA for the mildly damped oscillator (|Re λ|·span = 5) and for a
// model with algebraic unknowns.
TEST(Arkode, AutoSaysWhatItPickedAndWhy) {
  auto stiff = runQdot("examples/benchmarks/stiff_forced_oscillator.qd", {"--solver", "auto", "--stop", "0.1"});
  ASSERT_EQ(stiff.exitCode, 0) << stiff.log;
  EXPECT_NE(stiff.log.find("note: --solver auto chose arkode: the linearization at the start has eigenvalues -1e+05 ± "
                           "9.95e+05i"),
            std::string::npos)
      << stiff.log;
  auto mild = runQdot("examples/vibration/damped_oscillator.qd", {"--solver", "auto"});
  ASSERT_EQ(mild.exitCode, 0) << mild.log;
  EXPECT_NE(mild.log.find("note: --solver auto chose ida: "), std::string::npos) << mild.log;
  auto dae = runQdot("examples/constrained/cartesian_pendulum.qd", {"--solver", "auto", "--stop", "0.1"});
  ASSERT_EQ(dae.exitCode, 0) << dae.log;
  EXPECT_NE(dae.log.find("chose ida: its index was reduced"), std::string::npos) << dae.log;
}

// A failure keeps the rows and says when and why, as on IDA (tests/sim/models/ode_leaves_domain.qd:
// x'' = −√x from x = 1 at rest). Reference: x reaches 0, where the force stops existing, at
// t* = ∫₀¹ dx / √((4/3)(1 − x^(3/2))) (energy ½ẋ² + (2/3) x^(3/2) = 2/3), computed here with the
// substitution x = (1 − u²)^(2/3) (1 − x^(3/2) = u², |dx| = (4/3) u (1 − u²)^(−1/3) du), which
// removes the 1/√ singularity: t* = √(4/3) ∫₀¹ (1 − u²)^(−1/3) du = 1.49365 s, by the midpoint rule
// on 10⁶ panels (the remaining (1 − u)^(−1/3) singularity costs below 1e-4).
// Both solvers stop within 2e-3 s of t*, with the model's message, and keep the same rows.
TEST(Arkode, FailureKeepsTheRowsAndNamesTheTime) {
  double integral = 0;
  const int panels = 1000000;
  for (int i = 0; i < panels; ++i) {
    const double u = (i + 0.5) / panels;
    integral += std::pow(1 - u * u, -1.0 / 3) / panels;
  }
  const double exact = std::sqrt(4.0 / 3) * integral;
  std::vector<std::size_t> rows;
  for (const char* solver : {"ida", "arkode"}) {
    auto r = runQdot("tests/sim/models/ode_leaves_domain.qd", {"--solver", solver});
    EXPECT_EQ(r.exitCode, 3) << r.log;
    EXPECT_NE(r.log.find("sqrt of a negative number"), std::string::npos) << r.log;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.log, m, std::regex("failed at t = ([0-9.e+-]+)"))) << r.log;
    std::cout << "[measured] " << solver << " stops at " << m[1] << " s; x reaches 0 at " << num(exact) << " s\n";
    EXPECT_NEAR(std::stod(m[1]), exact, 2e-3) << solver;
    EXPECT_NE(r.log.find("rows up to t = "), std::string::npos) << r.log;
    rows.push_back(r.rows);
  }
  EXPECT_EQ(rows[0], rows[1]);
  EXPECT_GE(rows[0], 100u);
}

}  // namespace
}  // namespace qdot::simtest

namespace qdot::simtest {
namespace {

// The sparse path (KLU for I − γ dg/dy, Eigen's SparseLU for the mass matrix) against the dense one
// on the 60-mass spring chain (examples/vibration/spring_chain.qd): the same steps and the same
// trajectory within 100·rtol·scale (the linear algebra differs only by round-off). Reference: the
// dense run; and the chain's slowest mode keeps every displacement within its start range.
TEST(Arkode, KluMatchesDenseOnASpringChain) {
  const double rtol = 1e-8;
  std::vector<RunResult> runs;
  for (const char* solver : {"dense", "klu"}) {
    runs.push_back(runQdot("examples/vibration/spring_chain.qd",
                           {"-p", "n=60", "--solver", "arkode", "--linear-solver", solver, "--rtol", num(rtol)}));
    ASSERT_EQ(runs.back().exitCode, 0) << runs.back().log;
  }
  ASSERT_EQ(runs[0].header, runs[1].header);
  for (const std::string& name : {std::string("x[1]"), std::string("x[30]"), std::string("x[60]")}) {
    const auto &a = runs[0].col(name), &b = runs[1].col(name);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 100 * rtol * 0.6) << name << " row " << i;
  }
}

}  // namespace
}  // namespace qdot::simtest
