// qdot modes (driver/Modes.h, compiler/linear): natural frequencies, damping ratios and mode
// shapes against closed forms, to 1e-8 relative. References:
//   two masses, three equal springs: ω = √(k/m) (shape 1, 1) and √(3k/m) (1, −1);
//   damped oscillator: ω0 = √(k/m), ζ = c / (2√(km));
//   U-tube (textbook 5-2): ω = √(2g/l);
//   double pendulum, equal m and l: ω² = (g/l)(2 ∓ √2), θ2/θ1 = ±√2;
//   simple pendulum (N-link with n = 1) about θ0 (--at start): ω = √(g cos θ0 / l);
//   centrifugal governor (textbook 5-3) about its relative equilibrium cos θe = (6m1+3m2+3m3) g /
//   ((3m2+2m1) Ω² l): ω² = U''(θe) / M(θe), with the effective potential
//   U = −(4m1+2m2+2m3) g l cos θ − (2/3 m1 + m2) Ω² l² sin²θ and M = 2 (2/3 m1 + 2(m1+m3) sin²θ + m2) l²
//   (the model's T, written out by hand from its bars, balls and sleeve).
#include <gtest/gtest.h>

#include <cmath>

#include "driver/Modes.h"
#include "unit/pipeline/CompiledModel.h"

namespace qdot::driver {
namespace {

ModesResult modesOf(const std::string& example, std::vector<std::string> parameters = {},
                    linear::OperatingPoint at = linear::OperatingPoint::Equilibrium) {
  Compilation c;
  std::string error;
  EXPECT_TRUE(compileSource(c, example, test::readSource("examples/" + example), "", Stage::Check));
  EXPECT_EQ(takeStructuralParameters(c, parameters), "");
  EXPECT_TRUE(continueTo(c, Stage::Kernel));
  return computeModes(c, parameters, at);
}

void expectRelative(double got, double want, double rel = 1e-8) { EXPECT_NEAR(got, want, rel * std::fabs(want)); }

TEST(Modes, TwoMassesInPhaseAndOutOfPhase) {
  ModesResult r = modesOf("vibration/two_mass_modes.qd", {"m=2", "k=50"});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  expectRelative(r.modes[0].omega, std::sqrt(50.0 / 2));
  expectRelative(r.modes[1].omega, std::sqrt(3 * 50.0 / 2));
  EXPECT_NEAR(r.modes[0].shape[0], 1, 1e-12);
  EXPECT_NEAR(r.modes[0].shape[1], 1, 1e-12);
  EXPECT_NEAR(std::fabs(r.modes[1].shape[0]), 1, 1e-12);
  EXPECT_NEAR(r.modes[1].shape[0], -r.modes[1].shape[1], 1e-12);
  EXPECT_TRUE(r.system.equilibrium);
}

TEST(Modes, DampedOscillatorFrequencyAndDampingRatio) {
  ModesResult r = modesOf("vibration/damped_oscillator.qd", {"c=6", "k=400", "m=4"});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.modes[0].omega, std::sqrt(400.0 / 4));
  expectRelative(r.modes[0].zeta, 6 / (2 * std::sqrt(400.0 * 4)));
  ASSERT_TRUE(r.system.mechanical);
  expectRelative(r.system.mechanical->C(0, 0), 6);
  expectRelative(r.system.mechanical->K(0, 0), 400);
  expectRelative(r.system.mechanical->M(0, 0), 4);
}

TEST(Modes, OverdampedOscillatorDoesNotOscillate) {
  ModesResult r = modesOf("vibration/damped_oscillator.qd", {"c=50"});  // ζ = 2.5: λ = ω0 (−ζ ± √(ζ²−1))
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  double zeta = 2.5, w0 = 10;
  EXPECT_FALSE(r.modes[0].oscillating);
  expectRelative(r.modes[0].rate, w0 * (-zeta - std::sqrt(zeta * zeta - 1)));
  expectRelative(r.modes[1].rate, w0 * (-zeta + std::sqrt(zeta * zeta - 1)));
}

TEST(Modes, UTubeTextbookFrequency) {
  ModesResult r = modesOf("textbook/utube.qd", {"l=0.5"});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.modes[0].omega, std::sqrt(2 * 9.81 / 0.5));
}

TEST(Modes, DoublePendulumAboutTheHangingEquilibrium) {
  ModesResult r = modesOf("pendulum/double_pendulum.qd");
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  EXPECT_LT(std::fabs(r.system.point[0]) + std::fabs(r.system.point[1]), 1e-12);  // Newton found θ = 0
  double g = 9.81, l = 1;
  expectRelative(r.modes[0].omega, std::sqrt(g / l * (2 - std::sqrt(2.0))));
  expectRelative(r.modes[1].omega, std::sqrt(g / l * (2 + std::sqrt(2.0))));
  expectRelative(r.modes[0].shape[1] / r.modes[0].shape[0], std::sqrt(2.0));
  expectRelative(r.modes[1].shape[1] / r.modes[1].shape[0], -std::sqrt(2.0));
}

TEST(Modes, SimplePendulumAboutItsStartState) {
  ModesResult r = modesOf("pendulum/nlink.qd", {"n=1"}, linear::OperatingPoint::Start);
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 1u);
  EXPECT_FALSE(r.system.equilibrium);
  expectRelative(r.modes[0].omega, std::sqrt(9.81 * std::cos(0.3)));
}

TEST(Modes, GovernorAboutItsRelativeEquilibrium) {
  ModesResult r = modesOf("textbook/governor.qd", {"omega=12"});
  ASSERT_EQ(r.error, "");
  double m1 = 0.2, m2 = 1.0, m3 = 0.5, l = 0.25, W = 12, g = 9.81;
  double th = std::acos((6 * m1 + 3 * m2 + 3 * m3) * g / ((3 * m2 + 2 * m1) * W * W * l));
  double s2 = std::sin(th) * std::sin(th);
  double M = 2 * (2.0 / 3 * m1 + 2 * (m1 + m3) * s2 + m2) * l * l;
  double U2 = (4 * m1 + 2 * m2 + 2 * m3) * g * l * std::cos(th) - 2 * (2.0 / 3 * m1 + m2) * W * W * l * l * std::cos(2 * th);
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.system.point[0], th, 1e-12);
  expectRelative(r.modes[0].omega, std::sqrt(U2 / M));
}

TEST(Modes, NoEquilibriumAndBadParametersAreReported) {
  ModesResult wedge = modesOf("textbook/wedge.qd");
  EXPECT_EQ(wedge.code, ExitCode::ModelError);
  EXPECT_NE(wedge.error.find("no isolated static equilibrium"), std::string::npos) << wedge.error;
  for (const char* mass : {"m=0", "m=-1"}) {  // no kinetic energy, or a negative one
    ModesResult massless = modesOf("vibration/two_mass_modes.qd", {mass});
    EXPECT_EQ(massless.code, ExitCode::ModelError) << mass;
    EXPECT_NE(massless.error.find("mass matrix is not positive definite"), std::string::npos) << massless.error;
  }
  ModesResult bad = modesOf("vibration/two_mass_modes.qd", {"mm=3"});
  EXPECT_EQ(bad.code, ExitCode::Usage);
  EXPECT_NE(bad.error.find("did you mean 'm'"), std::string::npos) << bad.error;
}

}  // namespace
}  // namespace qdot::driver
