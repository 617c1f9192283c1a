// `qdot run` option behaviour as a user meets it (runtime/README.md, "How a run goes"): exit codes
// (0 success, 2 bad options, 3 solver failure), the "did you mean" hint, --outputs choosing columns.
#include "QdotRun.h"

namespace qdot::simtest {
namespace {

const char* kGovernor = "examples/textbook/governor.qd";

// Reference: runtime/README.md — an unknown parameter is a UsageError (exit 2) naming the closest
// parameter ("did you mean 'omega'?"); no result rows are written.
TEST(RunOptions, BadParameterNameExits2AndNamesTheClosest) {
  auto r = runQdot(kGovernor, {"-p", "omgea=5", "--stop", "0.1"});
  EXPECT_EQ(r.exitCode, 2) << r.log;
  EXPECT_NE(r.log.find("omgea"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("did you mean 'omega'"), std::string::npos) << r.log;
  EXPECT_EQ(r.rows, 0u);

  auto r2 = runQdot("examples/textbook/utube.qd", {"-p", "rh=900"});
  EXPECT_EQ(r2.exitCode, 2) << r2.log;
  EXPECT_NE(r2.log.find("did you mean 'rho'"), std::string::npos) << r2.log;
}

// Reference: runtime/README.md — stop ≤ start is a UsageError (exit 2).
TEST(RunOptions, StopBeforeStartExits2) {
  auto r = runQdot(kGovernor, {"--start", "2", "--stop", "1"});
  EXPECT_EQ(r.exitCode, 2) << r.log;
  EXPECT_NE(r.log.find("stop"), std::string::npos) << r.log;
  EXPECT_EQ(r.rows, 0u);

  auto equal = runQdot(kGovernor, {"--start", "1", "--stop", "1"});
  EXPECT_EQ(equal.exitCode, 2) << equal.log;
}

// Reference: runtime/README.md — with --outputs a,b exactly those columns, in that order, after
// `time`; the values are those of the full run (same solver path: the same options otherwise).
TEST(RunOptions, OutputsSelectsColumnsInOrder) {
  const std::vector<std::string> common = {"--stop", "0.5", "--interval", "0.05", "--invariants"};
  auto full = runQdot(kGovernor, common);
  ASSERT_EQ(full.exitCode, 0) << full.log;
  EXPECT_EQ(full.header, (std::vector<std::string>{"time", "theta", "der(theta)", "jacobi"}));

  auto args = common;
  args.insert(args.end(), {"--outputs", "jacobi,theta"});
  auto some = runQdot(kGovernor, args);
  ASSERT_EQ(some.exitCode, 0) << some.log;
  ASSERT_EQ(some.header, (std::vector<std::string>{"time", "jacobi", "theta"}));
  ASSERT_EQ(some.rows, full.rows);
  EXPECT_EQ(some.rows, 11u);
  for (const char* name : {"time", "jacobi", "theta"}) EXPECT_EQ(some.col(name), full.col(name)) << name;

  auto bad = runQdot(kGovernor, {"--stop", "0.5", "--outputs", "thet"});
  EXPECT_EQ(bad.exitCode, 2) << bad.log;
  EXPECT_NE(bad.log.find("did you mean 'theta'"), std::string::npos) << bad.log;
}

// Reference: issue 10 §4 — --outputs compiles only what the requested columns need. The model has
// a pendulum and an unrelated oscillator (m ẍ + k x = 0, x(0) = 0.1: x = 0.1 cos 10t); asked for x,
// the run integrates the oscillator alone and x still follows the closed form.
TEST(RunOptions, OutputsComputeOnlyWhatTheyNeed) {
  const char* model = "tests/sim/models/two_subsystems.qd";
  auto some = runQdot(model, {"--stop", "2", "--interval", "0.01", "--rtol", "1e-8", "--outputs", "x", "--stats"});
  ASSERT_EQ(some.exitCode, 0) << some.log;
  EXPECT_EQ(some.header, (std::vector<std::string>{"time", "x"}));
  EXPECT_NE(some.log.find("of 2 scales"), std::string::npos) << "not the 2 unknowns of the oscillator alone:\n" << some.log;
  Deviation d = compareColumn(some, "x", [](double t) { return 0.1 * std::cos(10 * t); },
                              [](double t) { return oscillationBound(1e-8, 0.1, 2 * M_PI / 10, t); });
  EXPECT_LE(d.maxRatio, 1);
  auto height = runQdot(model, {"--stop", "2", "--interval", "0.01", "--rtol", "1e-8", "--outputs", "height"});
  auto full = runQdot(model, {"--stop", "2", "--interval", "0.01", "--rtol", "1e-8"});
  ASSERT_EQ(height.exitCode, 0) << height.log;
  ASSERT_EQ(full.exitCode, 0) << full.log;
  ASSERT_EQ(height.rows, full.rows);
  for (size_t i = 0; i < full.rows; ++i) EXPECT_NEAR(height.col("height")[i], full.col("height")[i], 1e-5);
}

// Reference: docs/language.md, "Reading the results" — --csv-names=identifier renames the header
// only (der(theta) -> der_theta); every value is the same as with the default Modelica names.
TEST(RunOptions, CsvNamesIdentifierRenamesTheHeaderOnly) {
  const std::vector<std::string> common = {"--stop", "0.5", "--interval", "0.05", "--invariants"};
  auto modelica = runQdot(kGovernor, common);
  auto args = common;
  args.push_back("--csv-names=identifier");
  auto identifier = runQdot(kGovernor, args);
  ASSERT_EQ(identifier.exitCode, 0) << identifier.log;
  EXPECT_EQ(identifier.header, (std::vector<std::string>{"time", "theta", "der_theta", "jacobi"}));
  ASSERT_EQ(identifier.rows, modelica.rows);
  EXPECT_EQ(identifier.col("der_theta"), modelica.col("der(theta)"));
  EXPECT_EQ(identifier.col("jacobi"), modelica.col("jacobi"));
}

// Reference: the closed form x = cos t of tests/sim/models/leaves_domain.qd (ẍ + x = 0, x(0) = 1) and
// runtime/README.md — a model that leaves its domain (s = sqrt(x) once x = cos t < 0, i.e. after
// t = π/2) fails the run with exit 3, naming the time, and the rows computed before stay written.
// s is defined explicitly by its equation, so `qdot run` solves it out of the system
// (dae/ExplicitAlgebraics.h) and computes it with the results: the run fails at the first output
// time past π/2, 1.58, where s cannot be computed (a failure inside the solver says the same; see
// ArkodeSimTest's ode_leaves_domain and the stability suite).
// Bounds: x at every written row by oscillationBound (A = 1, P = 2π, rtol 1e-6); s = √x by
// 10·rtol·(|s| + 1) (algebraic: Newton's error test, atol = rtol × its start scale 1) while x ≥ 0.01.
TEST(RunOptions, SolverFailureExits3AndKeepsTheRowsBefore) {
  const double rtol = 1e-6;
  auto r = runQdot("tests/sim/models/leaves_domain.qd", {});
  EXPECT_EQ(r.exitCode, 3) << r.log;
  EXPECT_NE(r.log.find("at t = 1.58: the model's outputs could not be evaluated"), std::string::npos)
      << "the first output time past π/2:\n" << r.log;
  EXPECT_NE(r.log.find("sqrt of a negative number"), std::string::npos) << r.log;
  ASSERT_GT(r.rows, 100u);
  const auto& t = r.time();
  EXPECT_LE(t.back(), M_PI / 2);
  EXPECT_GE(t.back(), M_PI / 2 - 0.01) << "every output time before π/2 is written";
  compareColumn(
      r, "x", [](double tt) { return std::cos(tt); }, [&](double tt) { return oscillationBound(rtol, 1, 2 * M_PI, tt); });
  const auto &x = r.col("x"), &s = r.col("s");
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (x[i] >= 0.01) {
      EXPECT_NEAR(s[i], std::sqrt(x[i]), 10 * rtol * (std::fabs(s[i]) + 1)) << "t = " << t[i];
    }
  }
}

// Integer parameters are structural (they size arrays): `-p n=...` is applied before flattening.
// Reference: with n = 1 the N-link pendulum is the simple pendulum, whose period from rest at θ0 is
// T = 4 K(sin(θ0/2)) / √(g/l) (K: the complete elliptic integral of the first kind, computed here
// by the arithmetic-geometric mean, independently of qdot). At T/2 it is at −θ0, at T back at θ0.
TEST(RunOptions, IntegerParameterSizesTheModel) {
  const double theta0 = 0.3, omega = std::sqrt(9.81);
  double a = 1, b = std::cos(theta0 / 2);  // AGM(1, √(1 − k²)) with k = sin(θ0/2)
  for (int i = 0; i < 30; ++i) std::tie(a, b) = std::make_pair((a + b) / 2, std::sqrt(a * b));
  const double period = 4 * (M_PI / (2 * a)) / omega;
  auto r = runQdot("examples/pendulum/nlink.qd",
                   {"-p", "n=1", "--stop", num(period), "--interval", num(period / 2), "--rtol", "1e-10"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  EXPECT_EQ(r.header, (std::vector<std::string>{"time", "th[1]", "der(th[1])"}));
  ASSERT_EQ(r.rows, 3u);
  EXPECT_NEAR(r.col("th[1]")[1], -theta0, 1e-7);
  EXPECT_NEAR(r.col("th[1]")[2], theta0, 1e-7);

  auto three = runQdot("examples/pendulum/nlink.qd", {"-p", "n=3", "-p", "m=2", "--stop", "0.1"});
  ASSERT_EQ(three.exitCode, 0) << three.log;
  EXPECT_EQ(three.header.size(), 7u);  // time, 3 angles, 3 velocities

  auto fractional = runQdot("examples/pendulum/nlink.qd", {"-p", "n=2.5"});
  EXPECT_EQ(fractional.exitCode, 2) << fractional.log;
  EXPECT_NE(fractional.log.find("'n' is an Integer parameter"), std::string::npos) << fractional.log;
}

}  // namespace
}  // namespace qdot::simtest
