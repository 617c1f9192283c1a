// The initialization system (issue 10 §2) end to end: implicit initial equations, a condition on an
// acceleration, steady state and a nonlinear condition, each against its closed-form solution at
// every output time (the conditions fix the constants of the textbook solution).
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

constexpr double kRtol = 1e-8;

RunResult run(const std::string& name, double stop) {
  auto r = runQdot("tests/sim/models/" + name + ".qd", {"--rtol", num(kRtol), "--stop", num(stop), "--stats"});
  EXPECT_EQ(r.exitCode, 0) << r.log;
  EXPECT_NE(r.log.find("initialization system solved"), std::string::npos) << r.log;
  return r;
}

// |column - exact| <= 100 rtol (|exact| + scale) at every row.
void expectColumn(const RunResult& r, const std::string& name, const std::function<double(double)>& exact, double scale) {
  const auto &t = r.time(), &v = r.col(name);
  ASSERT_FALSE(v.empty());
  for (size_t i = 0; i < v.size(); ++i)
    ASSERT_NEAR(v[i], exact(t[i]), 100 * kRtol * (std::abs(exact(t[i])) + scale)) << name << " at t = " << t[i];
}

TEST(Initialization, ImplicitInitialEquation) {
  RunResult r = run("init_implicit", 2);
  expectColumn(r, "x", [](double t) { return -3 * std::exp(-2 * t); }, 3);
}

TEST(Initialization, ConditionOnTheAcceleration) {
  RunResult r = run("init_acceleration", 5);
  expectColumn(r, "x", [](double t) { return -1.25 * std::cos(2 * t); }, 1.25);
  expectColumn(r, "der(x)", [](double t) { return 2.5 * std::sin(2 * t); }, 2.5);
}

TEST(Initialization, SteadyState) {
  RunResult r = run("init_steady", 5);
  expectColumn(r, "x", [](double) { return 0.5; }, 0.5);
  expectColumn(r, "der(x)", [](double) { return 0.0; }, 0.5);
}

TEST(Initialization, NonlinearConditionFromTheStartGuess) {
  RunResult r = run("init_nonlinear", 5);
  expectColumn(r, "x", [](double t) { return 2 * std::cos(t); }, 2);
}

// A constrained model with conditions on a velocity and an acceleration: the solution satisfies the
// constraint and its two derivatives and both conditions at t0, and the energy is kept afterwards.
TEST(Initialization, ConstrainedModelWithConditionsOnDerivatives) {
  RunResult r = run("init_constrained", 1);
  const auto &x = r.col("x"), &y = r.col("y"), &vx = r.col("der(x)"), &vy = r.col("der(y)");
  const auto &ax = r.col("der(der(x))"), &ay = r.col("der(der(y))");
  ASSERT_FALSE(x.empty());
  EXPECT_NEAR(x[0] * x[0] + y[0] * y[0], 1, 1e-10);
  EXPECT_NEAR(x[0] * vx[0] + y[0] * vy[0], 0, 1e-10);
  EXPECT_NEAR(x[0] * ax[0] + y[0] * ay[0] + vx[0] * vx[0] + vy[0] * vy[0], 0, 1e-8);
  EXPECT_NEAR(vx[0], 0.4, 1e-10);
  EXPECT_NEAR(x[0] * ax[0], -2.8, 1e-8);
  double e0 = 9.81 * y[0] + 0.5 * (vx[0] * vx[0] + vy[0] * vy[0]);
  for (size_t i = 0; i < x.size(); ++i)
    ASSERT_NEAR(9.81 * y[i] + 0.5 * (vx[i] * vx[i] + vy[i] * vy[i]), e0, 1e-5) << "row " << i;
}

// Over-determined but consistent (all start positions of a constrained model fixed): accepted with a
// note naming the redundant start; inconsistent: an error naming it. The pendulum then swings as usual
// (energy g·y + v²/2 kept to the tolerance).
TEST(Initialization, RedundantConsistentStartsAreANoteInconsistentAnError) {
  auto ok = runQdot("tests/sim/models/init_redundant_pendulum.qd", {"--stop", "1", "--rtol", "1e-8"});
  ASSERT_EQ(ok.exitCode, 0) << ok.log;
  EXPECT_NE(ok.log.find("redundant with the constraints"), std::string::npos) << ok.log;
  const auto &y = ok.col("y"), &vx = ok.col("der(x)"), &vy = ok.col("der(y)");
  for (size_t i = 0; i < y.size(); ++i)
    ASSERT_NEAR(9.81 * y[i] + 0.5 * (vx[i] * vx[i] + vy[i] * vy[i]), 9.81 * -0.8, 1e-5) << "row " << i;
  auto bad = runQdot("tests/sim/models/init_redundant_pendulum.qd", {"--stop", "1", "-p", "y0=-0.7"});
  EXPECT_NE(bad.exitCode, 0);
  EXPECT_NE(bad.log.find("the initial conditions contradict each other: the start value of"), std::string::npos)
      << bad.log;
}

// Issue 10 acceptance: a singular mass matrix is reported as such, naming the unknowns, before IDA
// runs — also after index reduction, where m = 0 leaves no column empty but makes two rows parallel.
TEST(Initialization, SingularMassMatrixOfAConstrainedModelIsNamed) {
  auto r = runQdot("examples/constrained/cartesian_pendulum.qd", {"-p", "m=0", "--stop", "1"});
  EXPECT_NE(r.exitCode, 0);
  EXPECT_NE(r.log.find("at t = 0: the equations do not determine der(der("), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("mass matrix singular"), std::string::npos) << r.log;
  EXPECT_EQ(r.log.find("IDACalcIC"), std::string::npos) << r.log;
}

}  // namespace
}  // namespace qdot::simtest
