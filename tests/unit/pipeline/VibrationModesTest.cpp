// qdot modes on the component examples of examples/vibration (stdlib/Vibration parts), against
// closed forms to 1e-8 relative (issue 9 §4). References:
//   two_dof: M = diag(m1, m2), K = [[k1+k2, −k2], [−k2, k2+k3]]: ω² are the roots of
//     m1 m2 ω⁴ − (m1 (k2+k3) + m2 (k1+k2)) ω² + (k1+k2)(k2+k3) − k2² = 0, shape x2/x1 = (k1+k2 − m1 ω²)/k2;
//   string (n lumped masses, fixed ends): ω_k = 2 √(T/(rhoL h²)) sin(kπ/(2(n+1))), h = L/(n+1), and
//     the continuous string's k π/L √(T/rhoL) as n grows;
//   pendulum_absorber (cart M on a spring k carrying a pendulum m, l): M = [[M+m, m l], [m l, m l²]],
//     K = diag(k, m g l);
//   damped_vibration: four independent oscillators ω0 = √(k/m), ζ = c/(2√(km)) (ζ = 1, 2 do not oscillate);
//   free_vibration: ω = √(k/m) and the disk's √(kt/J);
//   coupled_pendulums (examples/pendulum): the free–free chain of pendulums, below.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "driver/Modes.h"
#include "unit/pipeline/CompiledModel.h"

namespace qdot::driver {
namespace {

ModesResult modesOf(const std::string& example, std::vector<std::string> parameters = {}) {
  Compilation c;
  EXPECT_TRUE(compileFile(c, std::string(QDOT_SOURCE_DIR) + "/examples/" + example, "", Stage::Check));
  EXPECT_EQ(takeStructuralParameters(c, parameters), "");
  EXPECT_TRUE(continueTo(c, Stage::Kernel)) << example;
  return computeModes(c, parameters, linear::OperatingPoint::Equilibrium);
}

void expectRelative(double got, double want, double rel = 1e-8) { EXPECT_NEAR(got, want, rel * std::fabs(want)); }

// The roots ω² of det(K − ω² M) = 0 for 2×2 M, K, ascending.
std::pair<double, double> twoByTwoSquares(double m11, double m12, double m22, double k11, double k12, double k22) {
  double a = m11 * m22 - m12 * m12;
  double b = -(m11 * k22 + m22 * k11 - 2 * m12 * k12);
  double c = k11 * k22 - k12 * k12;
  double d = std::sqrt(b * b - 4 * a * c);
  return {(-b - d) / (2 * a), (-b + d) / (2 * a)};
}

TEST(VibrationModes, TwoDegreesOfFreedomFrequenciesAndShapes) {
  ModesResult r = modesOf("vibration/two_dof.qd");
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  const double m1 = 1, m2 = 2, k1 = 100, k2 = 50, k3 = 100;
  auto [w1, w2] = twoByTwoSquares(m1, 0, m2, k1 + k2, -k2, k2 + k3);
  expectRelative(r.modes[0].omega, std::sqrt(w1));
  expectRelative(r.modes[1].omega, std::sqrt(w2));
  for (int k = 0; k < 2; ++k) {
    double ratio = (k1 + k2 - m1 * (k == 0 ? w1 : w2)) / k2;  // x2/x1
    expectRelative(r.modes[k].shape[1] / r.modes[k].shape[0], ratio);
    EXPECT_DOUBLE_EQ(r.modes[k].zeta, 0);
  }
}

// A model whose Integer parameter n sizes the library String it holds (`-p n=…` applies it).
ModesResult stringModes(int n) {
  Compilation c;
  std::string text = "model S\n  import Vibration.*;\n  parameter Integer n = 3;\n"
                     "  String str(n = n, T = 100, rhoL = 0.01, L = 1);\nend S;\n";
  EXPECT_TRUE(compileSource(c, "string_n.qd", text, "", Stage::Check));
  std::vector<std::string> parameters{"n=" + std::to_string(n)};
  EXPECT_EQ(takeStructuralParameters(c, parameters), "");
  EXPECT_TRUE(continueTo(c, Stage::Kernel));
  return computeModes(c, parameters, linear::OperatingPoint::Equilibrium);
}

TEST(VibrationModes, LumpedStringMatchesItsExactModesAndApproachesTheContinuousString) {
  const double T = 100, rhoL = 0.01, L = 1;
  double previousError = 1;
  for (int n : {5, 20, 80}) {
    ModesResult r = stringModes(n);
    ASSERT_EQ(r.error, "");
    ASSERT_EQ(r.modes.size(), static_cast<size_t>(n));
    double h = L / (n + 1);
    for (int k = 1; k <= 3; ++k)
      expectRelative(r.modes[k - 1].omega, 2 * std::sqrt(T / (rhoL * h * h)) * std::sin(k * std::numbers::pi / (2 * (n + 1))));
    double continuous = std::numbers::pi / L * std::sqrt(T / rhoL);
    double error = std::fabs(r.modes[0].omega - continuous) / continuous;
    EXPECT_LT(error, previousError / 4) << "second order in h: the error shrinks with (n+1)²";
    previousError = error;
  }
}

// examples/pendulum/coupled_pendulums.qd: n pendulums (m, l) with springs k between neighbouring
// bobs; linearized, M = m l² I and K = m g l I + k l² L (L the free–free Laplacian), so
// ω_j² = g/l + 4 (k/m) sin²((j − 1) π / (2 n)). Its potential holds sin² of every angle: the scalar
// derivation goes through the simplifier's Pythagorean rewrites for each of the n arguments.
TEST(VibrationModes, CoupledPendulumsMatchTheFreeChainsModes) {
  const int n = 120;
  const double m = 1, l = 1, g = 9.81, k = 2;
  ModesResult r = modesOf("pendulum/coupled_pendulums.qd", {"n=" + std::to_string(n)});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), static_cast<size_t>(n));
  for (int j = 1; j <= n; ++j) {
    double s = std::sin((j - 1) * std::numbers::pi / (2 * n));
    expectRelative(r.modes[j - 1].omega, std::sqrt(g / l + 4 * (k / m) * s * s));
  }
  for (int i = 1; i < n; ++i) expectRelative(r.modes[0].shape[i], r.modes[0].shape[0]);  // all swing together
}

TEST(VibrationModes, PendulumAbsorberTwoModes) {
  ModesResult r = modesOf("vibration/pendulum_absorber.qd");
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  const double M = 1, m = 0.1, l = 0.2, k = 49.05, g = 9.81;
  auto [w1, w2] = twoByTwoSquares(M + m, m * l, m * l * l, k, 0, m * g * l);
  expectRelative(r.modes[0].omega, std::sqrt(w1));
  expectRelative(r.modes[1].omega, std::sqrt(w2));
}

TEST(VibrationModes, DampedOscillatorsDampingRatios) {
  ModesResult r = modesOf("vibration/damped_vibration.qd");
  ASSERT_EQ(r.error, "");
  std::vector<double> zetas;
  for (const auto& mode : r.modes)
    if (mode.oscillating) {
      expectRelative(mode.omega, 10);  // ω0 = √(100/1) for every one
      zetas.push_back(mode.zeta);
    }
  std::sort(zetas.begin(), zetas.end());
  ASSERT_EQ(zetas.size(), 2u);  // ζ = 0.05 and 0.5; ζ = 1 and 2 are not oscillations
  expectRelative(zetas[0], 1 / (2 * std::sqrt(100.0)));
  expectRelative(zetas[1], 10 / (2 * std::sqrt(100.0)));
}

TEST(VibrationModes, FreeMassAndTorsionalDisk) {
  ModesResult r = modesOf("vibration/free_vibration.qd");
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 2u);
  expectRelative(r.modes[0].omega, std::sqrt(200.0 / 2));
  expectRelative(r.modes[1].omega, std::sqrt(8 / 0.02));
}

}  // namespace
}  // namespace qdot::driver
