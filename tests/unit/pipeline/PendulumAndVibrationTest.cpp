// Derived equations of the non-textbook examples against closed forms: the N-link pendulum's known
// mass matrix and gravity vector, the double pendulum's classical equations, the damped oscillator,
// the two-mass system and the spring chain. First integrals are checked where they must (not) exist.
#include <regex>

#include "CompiledModel.h"

namespace qdot::test {
namespace {

std::string withN(const std::string& file, int n) {
  return std::regex_replace(readSource(file), std::regex("parameter Integer n = [0-9]+"),
                            "parameter Integer n = " + std::to_string(n));
}

std::string th(int i) { return "th[" + std::to_string(i) + "]"; }

// The rows are linear in the accelerations: M_ij = r_i(a = e_j) − r_i(a = 0).
void checkNLink(int n) {
  CompiledModel m("nlink", withN("examples/pendulum/nlink.qd", n));
  ASSERT_TRUE(m.ok());
  std::mt19937_64 rng(n);
  std::uniform_real_distribution<double> U(-2, 2);
  double mass = 1.3, l = 0.7, g = 9.81;
  m.set("m", mass), m.set("l", l), m.set("g", g);
  std::vector<double> q(n + 1);
  for (int i = 1; i <= n; ++i) {
    m.set(th(i), q[i] = U(rng));
    m.set("der(" + th(i) + ")", 0.0);
    m.set("der(der(" + th(i) + "))", 0.0);
  }
  for (int i = 1; i <= n; ++i)  // gravity: r_i(v = 0, a = 0) = m g l (n − i + 1) sin θ_i
    EXPECT_TRUE(closeRelative(m.eulerLagrange(th(i)), mass * g * l * (n - i + 1) * std::sin(q[i]), mass * g * l * n));
  for (int j = 1; j <= n; ++j) {
    m.set("der(der(" + th(j) + "))", 1.0);
    for (int i = 1; i <= n; ++i) {
      double gravity = mass * g * l * (n - i + 1) * std::sin(q[i]);
      double Mij = mass * l * l * (n - std::max(i, j) + 1) * std::cos(q[i] - q[j]);
      EXPECT_TRUE(closeRelative(m.eulerLagrange(th(i)) - gravity, Mij, mass * l * l * n + mass * g * l * n))
          << "M(" << i << "," << j << ") for n = " << n;
    }
    m.set("der(der(" + th(j) + "))", 0.0);
  }
}

TEST(NLinkPendulum, MassMatrixN3) { checkNLink(3); }
TEST(NLinkPendulum, MassMatrixN8) { checkNLink(8); }
TEST(NLinkPendulum, MassMatrixN16) { checkNLink(16); }

TEST(DoublePendulum, ClassicalEquations) {
  // 2 m l² θ̈1 + m l² cos(θ1−θ2) θ̈2 + m l² sin(θ1−θ2) θ̇2² + 2 m g l sin θ1 = 0
  //   m l² θ̈2 + m l² cos(θ1−θ2) θ̈1 − m l² sin(θ1−θ2) θ̇1² +   m g l sin θ2 = 0
  auto m = CompiledModel::fromFile("examples/pendulum/double_pendulum.qd");
  ASSERT_TRUE(m.ok());
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(-3, 3);
  for (int k = 0; k < 200; ++k) {
    double mass = std::fabs(U(rng)) + 0.1, l = std::fabs(U(rng)) + 0.1, g = 9.81;
    double t1 = U(rng), t2 = U(rng), v1 = U(rng), v2 = U(rng), a1 = U(rng), a2 = U(rng);
    for (auto [n, val] : {std::pair{"m", mass}, {"l", l}, {"g", g}, {"th[1]", t1}, {"th[2]", t2}, {"der(th[1])", v1},
                          {"der(th[2])", v2}, {"der(der(th[1]))", a1}, {"der(der(th[2]))", a2}})
      m.set(n, val);
    double d = t1 - t2, ml2 = mass * l * l;
    double r1 = 2 * ml2 * a1 + ml2 * std::cos(d) * a2 + ml2 * std::sin(d) * v2 * v2 + 2 * mass * g * l * std::sin(t1);
    double r2 = ml2 * a2 + ml2 * std::cos(d) * a1 - ml2 * std::sin(d) * v1 * v1 + mass * g * l * std::sin(t2);
    double scale = ml2 * 10 + mass * g * l * 3;
    EXPECT_TRUE(closeRelative(m.eulerLagrange("th[1]"), r1, scale));
    EXPECT_TRUE(closeRelative(m.eulerLagrange("th[2]"), r2, scale));
  }
  ASSERT_NE(m.invariant("jacobi"), nullptr);  // energy: h = T + V
  m.set("der(th[1])", 0.4), m.set("der(th[2])", -0.9), m.set("th[1]", 0.3), m.set("th[2]", -1.1);
  m.set("m", 1.0), m.set("l", 1.0), m.set("g", 9.81);
  double v1 = 0.4, v2 = -0.9, t1 = 0.3, t2 = -1.1;
  double T = 0.5 * (2 * v1 * v1 + v2 * v2 + 2 * v1 * v2 * std::cos(t1 - t2));
  double V = -9.81 * (2 * std::cos(t1) + std::cos(t2));
  EXPECT_NEAR(m.eval(m.invariant("jacobi")->value), T + V, 1e-12);
}

TEST(DampedOscillator, RowAndNoFirstIntegral) {  // m ẍ + c ẋ + k x = 0; D ≠ 0: no integral
  auto m = CompiledModel::fromFile("examples/vibration/damped_oscillator.qd");
  ASSERT_TRUE(m.ok());
  for (auto [n, val] : {std::pair{"m", 2.0}, {"k", 50.0}, {"c", 0.3}, {"x", 0.2}, {"der(x)", -1.5}, {"der(der(x))", 4.0}})
    m.set(n, val);
  EXPECT_NEAR(m.eulerLagrange("x"), 2.0 * 4.0 + 0.3 * -1.5 + 50.0 * 0.2, 1e-13);
  EXPECT_TRUE(m.dae().invariants.empty());
}

TEST(TwoMassThreeSpring, Rows) {
  auto m = CompiledModel::fromFile("examples/vibration/two_mass.qd");
  ASSERT_TRUE(m.ok());
  for (auto [n, val] : {std::pair{"m", 1.5}, {"k", 80.0}, {"x1", 0.1}, {"x2", -0.3}, {"der(x1)", 0.0}, {"der(x2)", 0.0},
                        {"der(der(x1))", 2.0}, {"der(der(x2))", -1.0}})
    m.set(n, val);
  EXPECT_NEAR(m.eulerLagrange("x1"), 1.5 * 2.0 + 2 * 80 * 0.1 - 80 * -0.3, 1e-12);
  EXPECT_NEAR(m.eulerLagrange("x2"), 1.5 * -1.0 + 2 * 80 * -0.3 - 80 * 0.1, 1e-12);
}

TEST(SpringChain, RowsOfAChainWithDampers) {
  CompiledModel m("chain", withN("examples/vibration/spring_chain.qd", 5));
  ASSERT_TRUE(m.ok());
  double mass = 1.2, k = 300, c = 0.7;
  m.set("m", mass), m.set("k", k), m.set("c", c);
  std::vector<double> x{0, 0.1, -0.2, 0.05, 0.3, -0.1}, v{0, 1, -2, 0.5, 0.25, 3}, a{0, 7, -3, 2, 1, -5};
  for (int i = 1; i <= 5; ++i) {
    std::string q = "x[" + std::to_string(i) + "]";
    m.set(q, x[i]), m.set("der(" + q + ")", v[i]), m.set("der(der(" + q + "))", a[i]);
  }
  for (int i = 1; i <= 5; ++i) {
    double left = i == 1 ? 0 : x[i - 1], right = i == 5 ? x[i] : x[i + 1];
    double vl = i == 1 ? 0 : v[i - 1], vr = i == 5 ? v[i] : v[i + 1];
    double expected = mass * a[i] + k * (x[i] - left) - k * (right - x[i]) + c * (v[i] - vl) - c * (vr - v[i]);
    EXPECT_NEAR(m.eulerLagrange("x[" + std::to_string(i) + "]"), expected, 1e-10) << i;
  }
  EXPECT_EQ(m.dae().variables.size(), 10u);
  EXPECT_EQ(m.dae().stateCount(), 10u);
}

}  // namespace
}  // namespace qdot::test
