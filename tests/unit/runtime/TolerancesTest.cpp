// The per-variable absolute tolerance vector: the scale rule on small hand-made vectors, what a
// session really hands to IDA, and why it matters (a variable of size 1e-8 stays accurate).
#include <gtest/gtest.h>

#include <cmath>

#include "HandModels.h"
#include "ida/IdaSession.h"
#include "ida/Tolerances.h"
#include "arkode/StartLinearization.h"
#include "sim/Simulation.h"

namespace qdot::rt::test {
namespace {

TEST(ToleranceScales, NominalWinsElseStartValueWithAFloorPerKind) {
  // differential: 2, 0, -50 (nominal 0.1 on the second); algebraic: 0, 400
  std::vector<double> y0 = {2, 0, -50, 0, 400};
  std::vector<double> nominal = {0, 0.1, 0, 0, 0};
  std::vector<int32_t> kind = {1, 1, 1, 0, 0};
  std::vector<double> s = toleranceScales(y0, nominal, kind);
  EXPECT_EQ(s[0], 2.0);         // |y0|
  EXPECT_EQ(s[1], 0.1);         // nominal
  EXPECT_EQ(s[2], 50.0);        // |y0|
  EXPECT_DOUBLE_EQ(s[3], 0.4);  // floor: 1e-3 * largest algebraic (400)
  EXPECT_EQ(s[4], 400.0);
}

TEST(ToleranceScales, ZeroKindFallsBackToAllThenToOne) {
  std::vector<int32_t> kind = {1, 0, 0};
  // algebraic all zero: floor from the largest of all (5)
  EXPECT_DOUBLE_EQ(toleranceScales(std::vector<double>{5, 0, 0}, std::vector<double>(3, 0.0), kind)[1], 5e-3);
  // algebraic values at roundoff level (1e-30 after IDACalcIC) are negligible: same fallback
  EXPECT_DOUBLE_EQ(toleranceScales(std::vector<double>{5, 1e-30, 0}, std::vector<double>(3, 0.0), kind)[1], 5e-3);
  // everything zero: unit scale
  std::vector<double> zeros(3, 0.0);
  EXPECT_EQ(toleranceScales(zeros, zeros, kind), (std::vector<double>{1, 1, 1}));
  // a NaN start counts as 0, a negative or NaN nominal as none
  std::vector<double> s = toleranceScales(std::vector<double>{NAN, 3, 0}, std::vector<double>{-1, NAN, 0}, kind);
  EXPECT_DOUBLE_EQ(s[0], 3e-3);  // its kind (differential) is all zero: 1e-3 * largest of all (3)
  EXPECT_EQ(s[1], 3.0);          // NaN nominal ignored, |y0| used
  EXPECT_DOUBLE_EQ(s[2], 3e-3);  // 1e-3 * largest algebraic (3)
}

TEST(ToleranceVector, AutomaticAtolIsRtolTimesScale) {
  std::vector<double> y0 = {1e-8, 3, 0};
  std::vector<double> nominal = {0, 0, 0};
  std::vector<int32_t> kind = {1, 1, 1};
  ToleranceVector v = buildTolerances(1e-6, std::nullopt, y0, nominal, kind);
  const double c = calibratedRtol(1e-6);  // the rtol handed to IDA, and the base of the automatic atol
  ASSERT_EQ(v.atol.size(), 3u);
  EXPECT_DOUBLE_EQ(v.atol[0], c * 3e-3);  // floor 1e-3 * 3 beats |1e-8|
  EXPECT_DOUBLE_EQ(v.atol[1], c * 3);
  EXPECT_DOUBLE_EQ(v.atol[2], c * 3e-3);
  EXPECT_FALSE(v.summary.atolGiven);
  EXPECT_EQ(v.summary.atolUser, c);
  EXPECT_EQ(v.summary.automatic, 3u);
  EXPECT_DOUBLE_EQ(summarize(v).atolMin, c * 3e-3);
  EXPECT_DOUBLE_EQ(summarize(v).atolMedian, c * 3e-3);
  EXPECT_DOUBLE_EQ(summarize(v).atolMax, c * 3);

}

// useCalibrated brings tolerances made as given (for IDACalcIC) back to what a calibrated build
// from the same y gives, bit for bit, without computing the scales again; with --atol it changes
// nothing. (The session uses it when only y' changed since the build.)
TEST(ToleranceVector, UseCalibratedEqualsACalibratedBuild) {
  std::vector<double> y0 = {1e-8, 3, 0, -0.7, 1e300};
  std::vector<double> nominal = {0, 0, 2, 0, 0};
  std::vector<int32_t> kind = {1, 1, 1, 0, 0};
  for (double rtol : {1e-3, 1e-6, 1e-9}) {
    ToleranceVector calibrated = buildTolerances(rtol, std::nullopt, y0, nominal, kind);
    ToleranceVector v = buildTolerances(rtol, std::nullopt, y0, nominal, kind);
    useAsGiven(v);
    EXPECT_EQ(v.solverRtol, rtol);
    useCalibrated(v);
    EXPECT_EQ(v.solverRtol, calibrated.solverRtol);
    EXPECT_EQ(v.atol, calibrated.atol);  // exactly
    EXPECT_EQ(summarize(v).atolMin, summarize(calibrated).atolMin);
    EXPECT_EQ(summarize(v).atolMedian, summarize(calibrated).atolMedian);
    EXPECT_EQ(summarize(v).atolMax, summarize(calibrated).atolMax);
    EXPECT_EQ(v.summary.atolUser, calibrated.summary.atolUser);
    EXPECT_EQ(v.summary.automatic, calibrated.summary.automatic);
  }
  ToleranceVector given = buildTolerances(1e-6, 1e-9, y0, nominal, kind);
  std::vector<double> before = given.atol;
  useCalibrated(given);
  EXPECT_EQ(given.atol, before);
  EXPECT_EQ(given.solverRtol, 1e-6);
}

// A given atol is absolute in each variable's units (SUNDIALS, SciPy): the start values do not
// scale it; only a nominal does.
TEST(ToleranceVector, GivenAtolIsAbsoluteExceptTimesNominal) {
  std::vector<double> y0 = {1e-8, 3, 0};
  std::vector<double> nominal = {1e-8, 0, 0};
  std::vector<int32_t> kind = {1, 1, 0};
  ToleranceVector w = buildTolerances(1e-6, 1e-4, y0, nominal, kind);
  EXPECT_DOUBLE_EQ(w.atol[0], 1e-4 * 1e-8);  // nominal
  EXPECT_EQ(w.atol[1], 1e-4);                // not 1e-4 * 3
  EXPECT_EQ(w.atol[2], 1e-4);                // not 1e-4 * 3e-3 for a zero start
  EXPECT_TRUE(w.summary.atolGiven);
  EXPECT_EQ(w.summary.automatic, 2u);
  EXPECT_DOUBLE_EQ(summarize(w).atolMin, 1e-12);
  EXPECT_DOUBLE_EQ(summarize(w).atolMedian, 1e-4);
}

// A model at rest: every start value is 0, and IDACalcIC leaves roundoff (4e-13) in an algebraic
// unknown. The floors come from the start values as written (all zero: the unit, 1), so the
// roundoff does not become a scale of 4e-16; a consistent value above the floor still raises it.
TEST(ToleranceScales, RoundoffAfterCalcICDoesNotShrinkTheFloor) {
  std::vector<double> start = {0, 0, 0}, consistent = {0, 0, 4e-13}, nominal = {0, 0, 0};
  std::vector<int32_t> kind = {1, 1, 0};
  EXPECT_EQ(toleranceScales(consistent, nominal, kind, start), (std::vector<double>{1, 1, 1}));
  EXPECT_DOUBLE_EQ(toleranceScales(consistent, nominal, kind)[2], 4e-13);  // what the floor was before
  consistent[2] = 25;
  EXPECT_EQ(toleranceScales(consistent, nominal, kind, start)[2], 25);
}

// From 65 536 unknowns the scales, floors and atol are computed in two halves on two threads: the
// largest start value, alone in the second half, still sets every zero start's floor, and the
// figures are those of the whole vector.
TEST(ToleranceVector, ALargeModelsFloorsComeFromBothHalves) {
  const size_t n = 100001;
  std::vector<double> y0(n, 0.0), nominal(n, 0.0);
  std::vector<int32_t> kind(n, 1);
  y0[n - 3] = -1000;  // differential, in the second half
  y0[7] = 2;
  kind[5] = 0, y0[5] = 5;  // the only algebraic unknown (its floor its own, 5e-3)
  nominal[9] = 0.25;
  ToleranceVector v = buildTolerances(1e-6, std::nullopt, y0, nominal, kind);
  double floor = kAutomaticScaleFloorFactor * 1000, c = calibratedRtol(1e-6);
  EXPECT_EQ(v.scale[0], floor);
  EXPECT_EQ(v.scale[n - 1], floor);
  EXPECT_EQ(v.scale[n - 3], 1000);
  EXPECT_EQ(v.scale[7], 2);
  EXPECT_EQ(v.scale[5], 5);
  EXPECT_EQ(v.scale[9], 0.25);
  for (size_t i : {size_t{0}, size_t{5}, n / 2, n / 2 + 1, n - 3, n - 1}) EXPECT_EQ(v.atol[i], c * v.scale[i]) << i;
  EXPECT_EQ(summarize(v).atolMax, c * 1000);
  EXPECT_EQ(summarize(v).atolMin, c * 0.25);
  EXPECT_EQ(summarize(v).atolMedian, c * floor);
}

TEST(ToleranceVector, MedianOfAnEvenCountIsTheMeanOfTheMiddleTwo) {
  std::vector<double> y0 = {1, 2, 4, 8};
  std::vector<int32_t> kind(4, 1);
  ToleranceVector v = buildTolerances(0.5, 1.0, y0, std::vector<double>(4, 0.0), kind);
  EXPECT_DOUBLE_EQ(summarize(v).atolMedian, 1.0);
  ToleranceVector w = buildTolerances(1.0, std::nullopt, y0, std::vector<double>(4, 0.0), kind);
  EXPECT_DOUBLE_EQ(summarize(w).atolMedian, 3.0 * calibratedRtol(1.0));
}

TEST(ToleranceVector, TheSessionUsesNominalAndConsistentValues) {
  // Bernoulli DAE: y2 starts at 0 but IDACalcIC makes it 1/2; the automatic scale follows.
  HandModel dae = bernoulliDae();
  SessionOptions o;
  o.rtol = 1e-6;
  IdaSession session(dae.abi(), {}, o);
  session.initialize(0.1);
  ASSERT_EQ(session.absoluteTolerances().size(), 2u);
  const double c = calibratedRtol(1e-6);
  EXPECT_DOUBLE_EQ(session.absoluteTolerances()[0], c);        // |y1(0)| = 1
  EXPECT_DOUBLE_EQ(session.absoluteTolerances()[1], 0.5 * c);  // |y2(0)| = 1/2 after CalcIC
  // Robertson: nominal 1e-5 on y2 gives atol 1e-5 * (calibrated) rtol there.
  HandModel rob = robertson();
  IdaSession second(rob.abi(), {}, o);
  EXPECT_DOUBLE_EQ(second.absoluteTolerances()[1], 1e-5 * 1e-6);  // before initialize: as given, for IDACalcIC
  second.initialize(0.1);
  EXPECT_DOUBLE_EQ(second.absoluteTolerances()[1], 1e-5 * c);     // the run: calibrated
  EXPECT_EQ(second.tolerances().automatic, 2u);
}

// Reference: x = 1e-8 exp(-t) (x' = -x). With one scalar atol = rtol = 1e-6 the error test would
// accept anything for a variable of size 1e-8; the scaled atol (1e-6 * 1e-8) keeps it accurate
// to a relative 1e-4.
TEST(ToleranceVector, TinyVariableStaysAccurate) {
  HandModel m;
  m.variables = {"x"};
  m.differential = {1};
  m.start = {1e-8};
  m.entries = {{0, 0}};
  m.residual = [](double, const double* y, const double* yp, const double*, double* F) {
    F[0] = yp[0] + y[0];
    return 0;
  };
  m.jacobian = [](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj + 1;
    return 0;
  };
  SimulationSettings s;
  s.stop = 5;
  s.interval = 0.5;
  MemorySink sink;
  SimulationResult r = simulate(m.abi(), s, sink);
  ASSERT_TRUE(r.success) << r.message;
  double worst = 0;
  for (std::size_t k = 0; k < sink.rows.size(); ++k) {
    double exact = 1e-8 * std::exp(-sink.times[k]);
    worst = std::max(worst, std::abs(sink.rows[k][0] - exact) / exact);
  }
  std::printf("  x = 1e-8 exp(-t), rtol 1e-6: max relative error %.3g\n", worst);
  EXPECT_LT(worst, 1e-4);
}

// Without --atol, IDA gets a tighter rtol so that the global error follows the requested one
// (docs/accuracy.md); with --atol, both tolerances go to IDA as given.
TEST(ToleranceVector, CalibratedRtolOnlyWithoutAtol) {
  EXPECT_NEAR(calibratedRtol(1e-6), 0.5 * std::pow(1e-6, 1.15), 1e-20);
  EXPECT_LT(calibratedRtol(1e-3), 1e-3);
  EXPECT_GT(calibratedRtol(1e-3), 1e-4);
  EXPECT_EQ(calibratedRtol(1e-10), 2e-11);   // never below IDA's round-off limit...
  EXPECT_EQ(calibratedRtol(1e-12), 1e-12);   // ...unless asked for directly
  std::vector<double> y0 = {1, 2};
  std::vector<int32_t> kind = {1, 1};
  EXPECT_EQ(buildTolerances(1e-6, std::nullopt, y0, std::vector<double>(2, 0.0), kind).solverRtol, calibratedRtol(1e-6));
  EXPECT_EQ(buildTolerances(1e-6, 1e-9, y0, std::vector<double>(2, 0.0), kind).solverRtol, 1e-6);
}

// A velocity der(q) is known by its name; its automatic scale is q's scale times the model's lowest
// frequency (a pendulum: 1 rad at sqrt(g/l) = 3.13/s), never below the floor of its kind, and a
// nominal still wins. Without a frequency the rule is the start-value one.
TEST(ToleranceScales, VelocityFollowsItsPositionTimesTheLowestFrequency) {
  std::vector<const char*> names = {"theta", "der(theta)", "x", "der(x)", "der(y)"};
  EXPECT_EQ(velocityPositions(names), (std::vector<int32_t>{-1, 0, -1, 2, -1}));
  std::vector<double> y0 = {1, 0, 2, 0, 0};
  std::vector<double> nominal = {0, 0, 0, 0.5, 0};
  std::vector<int32_t> kind = {1, 1, 1, 1, 1};
  TimeScale pendulum{std::sqrt(9.81), velocityPositions(names)};
  std::vector<double> s = toleranceScales(y0, nominal, kind, {}, pendulum);
  EXPECT_DOUBLE_EQ(s[1], std::sqrt(9.81));  // 1 rad x 3.13/s
  EXPECT_EQ(s[3], 0.5);                     // nominal wins
  EXPECT_DOUBLE_EQ(s[4], 2e-3);             // no position of that name: the floor, 1e-3 x largest start
  TimeScale slow{1e-6, velocityPositions(names)};
  EXPECT_DOUBLE_EQ(toleranceScales(y0, nominal, kind, {}, slow)[1], 2e-3);  // not below the floor
  EXPECT_DOUBLE_EQ(toleranceScales(y0, nominal, kind)[1], 2e-3);            // no time scale: as before
  ToleranceVector v = buildTolerances(1e-6, std::nullopt, y0, nominal, kind, {}, pendulum);
  EXPECT_EQ(v.summary.velocities, 1u);
  EXPECT_DOUBLE_EQ(v.summary.frequency, std::sqrt(9.81));
  EXPECT_DOUBLE_EQ(v.atol[1], v.solverRtol * std::sqrt(9.81));
  EXPECT_EQ(buildTolerances(1e-6, 1e-9, y0, nominal, kind, {}, pendulum).atol[1], 1e-9);  // --atol: absolute
}

// ARKODE's calibration (measured with qdot wp) replaces IDA's, on the automatic atol only.
TEST(ToleranceVector, ArkodeCalibration) {
  std::vector<double> y0 = {1, 2};
  std::vector<int32_t> kind = {1, 1};
  ToleranceVector v = buildTolerances(1e-6, std::nullopt, y0, std::vector<double>(2, 0.0), kind);
  useCalibration(v, kArkodeCalibration);
  EXPECT_NEAR(v.solverRtol, 0.03 * std::pow(1e-6, 1.2), 1e-22);
  EXPECT_DOUBLE_EQ(v.atol[1], 2 * v.solverRtol);
  EXPECT_EQ(calibratedRtol(1e-12, kArkodeCalibration), 1e-13);  // the floor
  ToleranceVector w = buildTolerances(1e-6, 1e-9, y0, std::vector<double>(2, 0.0), kind);
  useCalibration(w, kArkodeCalibration);
  EXPECT_EQ(w.solverRtol, 1e-6);
  EXPECT_EQ(w.atol[0], 1e-9);
}

// The lowest frequency of the linearization at the start, on m x'' + k x = 0 written as qdot does
// (rows m v' + k x, x' − v; unknowns x, v): ω = sqrt(k/m). A spring of negative stiffness (a
// growing mode) and none at all (a free mass: every eigenvalue zero) give no frequency.
std::optional<double> oscillatorFrequency(double m, double k) {
  auto residual = [=](const double* y, const double* yp, double* F) {
    F[0] = m * yp[1] + k * y[0];
    F[1] = yp[0] - y[1];
  };
  auto jacobian = [=](double cj, const double*, const double*, double* J) {  // column-major 2 x 2
    J[0] = k, J[1] = cj;        // d/dx
    J[2] = m * cj, J[3] = -1;   // d/dv
  };
  std::vector<double> y0 = {0.1, 0};
  return lowestStartFrequency(y0, residual, jacobian);
}

TEST(StartLinearization, LowestFrequencyOfAnOscillator) {
  ASSERT_TRUE(oscillatorFrequency(2, 50).has_value());
  EXPECT_NEAR(*oscillatorFrequency(2, 50), 5.0, 1e-12);
  EXPECT_FALSE(oscillatorFrequency(2, -50).has_value());  // saddle: released near an unstable equilibrium
  EXPECT_FALSE(oscillatorFrequency(2, 0).has_value());    // a free mass
  std::vector<std::complex<double>> modes = {{-1, 3}, {-1, -3}, {0, 1e6}, {0, -1e6}, {0, 0}};
  EXPECT_NEAR(*lowestFrequency(modes), std::sqrt(10.0), 1e-12);  // |λ|, the zero (rigid) mode left out
}

}  // namespace
}  // namespace qdot::rt::test
