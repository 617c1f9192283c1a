// The four worked examples of the textbook chapter (Dynamics II, §5-1/5-2): qdot's derived
// Euler–Lagrange residuals, evaluated at random states and parameters, equal the equations the
// textbook derives by hand (up to the factor stated in each test). Tolerance: 1e-12 relative to
// the magnitude of the summed terms (rounding only: both sides are the same polynomial).
#include "CompiledModel.h"

namespace qdot::test {
namespace {

constexpr int kPoints = 200;

struct Random {
  std::mt19937_64 rng{12345};
  double operator()(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
};

TEST(TextbookExamples, UTubeIsLxddotPlus2gx) {  // example 5-2: l ẍ + 2 g x = 0
  auto m = CompiledModel::fromFile("examples/textbook/utube.qd");
  ASSERT_TRUE(m.ok());
  Random r;
  for (int i = 0; i < kPoints; ++i) {
    double rho = r(500, 2000), A = r(1e-5, 1e-3), l = r(0.1, 3), g = r(1, 20);
    double x = r(-1, 1), v = r(-2, 2), a = r(-50, 50);
    for (auto [n, val] : {std::pair{"rho", rho}, {"A", A}, {"l", l}, {"g", g}, {"h", 0.1}, {"x", x}, {"der(x)", v},
                          {"der(der(x))", a}})
      m.set(n, val);
    // qdot differentiates ρA-scaled energies, so its row is ρA (l ẍ + 2 g x).
    double textbook = rho * A * (l * a + 2 * g * x);
    EXPECT_TRUE(closeRelative(m.eulerLagrange("x"), textbook, rho * A * (std::fabs(l * a) + std::fabs(2 * g * x))));
  }
}

TEST(TextbookExamples, EllipsographIs3mPlus4m1) {  // example 5-1: (3m + 4m1) l² θ̈ = M_O
  auto m = CompiledModel::fromFile("examples/textbook/ellipsograph.qd");
  ASSERT_TRUE(m.ok());
  Random r;
  for (int i = 0; i < kPoints; ++i) {
    double mm = r(0.1, 5), m1 = r(0.1, 5), l = r(0.1, 2), MO = r(-10, 10), th = r(-6, 6), w = r(-5, 5), a = r(-20, 20);
    for (auto [n, val] : {std::pair{"m", mm}, {"m1", m1}, {"l", l}, {"M_O", MO}, {"theta", th}, {"der(theta)", w},
                          {"der(der(theta))", a}})
      m.set(n, val);
    double textbook = (3 * mm + 4 * m1) * l * l * a - MO;
    EXPECT_TRUE(closeRelative(m.eulerLagrange("theta"), textbook, std::fabs((3 * mm + 4 * m1) * l * l * a) + std::fabs(MO) +
                                                                     (mm + m1) * l * l * w * w));
  }
}

// Example 5-3. The printed θ̈ coefficient [4/3 m1 + 4(m1+m3) sin²θ + m2] l² misprints 2 m2 as m2:
// differentiating the textbook's own T (which has m2 l² θ̇²) gives 2 m2. We compare with the
// corrected equation and check the textbook's relative equilibrium separately.
double governorTextbook(double m1, double m2, double m3, double l, double w, double g, double th, double v, double a) {
  double s = std::sin(th);
  return (4.0 / 3 * m1 + 4 * (m1 + m3) * s * s + 2 * m2) * l * l * a + 2 * (m1 + m3) * l * l * std::sin(2 * th) * v * v -
         (m2 + 2.0 / 3 * m1) * w * w * l * l * std::sin(2 * th) + (4 * m1 + 2 * m2 + 2 * m3) * g * l * s;
}

void setGovernor(CompiledModel& m, double m1, double m2, double m3, double l, double w, double g, double th, double v,
                 double a) {
  for (auto [n, val] : {std::pair{"m1", m1}, {"m2", m2}, {"m3", m3}, {"l", l}, {"omega", w}, {"g", g}, {"theta", th},
                        {"der(theta)", v}, {"der(der(theta))", a}})
    m.set(n, val);
}

TEST(TextbookExamples, CentrifugalGovernor) {
  auto m = CompiledModel::fromFile("examples/textbook/governor.qd");
  ASSERT_TRUE(m.ok());
  Random r;
  for (int i = 0; i < kPoints; ++i) {
    double m1 = r(0.1, 2), m2 = r(0.1, 2), m3 = r(0.1, 2), l = r(0.1, 1), w = r(0, 20), g = r(1, 20);
    double th = r(-3, 3), v = r(-5, 5), a = r(-20, 20);
    setGovernor(m, m1, m2, m3, l, w, g, th, v, a);
    double scale = (m1 + m2 + m3) * l * l * (std::fabs(a) + v * v + w * w) + (m1 + m2 + m3) * g * l;
    EXPECT_TRUE(closeRelative(m.eulerLagrange("theta"), governorTextbook(m1, m2, m3, l, w, g, th, v, a), scale));
  }
}

TEST(TextbookExamples, CentrifugalGovernorRelativeEquilibrium) {
  // cos θ = (6m1 + 3m2 + 3m3) g / ((3m2 + 2m1) ω² l) makes the row vanish at rest.
  auto m = CompiledModel::fromFile("examples/textbook/governor.qd");
  ASSERT_TRUE(m.ok());
  double m1 = 0.2, m2 = 1, m3 = 0.5, l = 0.25, w = 10, g = 9.81;
  double th = std::acos((6 * m1 + 3 * m2 + 3 * m3) * g / ((3 * m2 + 2 * m1) * w * w * l));
  setGovernor(m, m1, m2, m3, l, w, g, th, 0, 0);
  EXPECT_NEAR(m.eulerLagrange("theta"), 0.0, 1e-13);
  setGovernor(m, m1, m2, m3, l, w, g, th + 0.01, 0, 0);  // and not slightly away from it
  EXPECT_GT(std::fabs(m.eulerLagrange("theta")), 1e-3);
  EXPECT_NE(m.invariant("jacobi"), nullptr) << "L has no explicit time: the Jacobi integral exists";
}

TEST(TextbookExamples, FreeGovernorHasCyclicAngle) {  // §5-3: φ cyclic, p_φ conserved
  auto m = CompiledModel::fromFile("examples/textbook/governor_free.qd");
  ASSERT_TRUE(m.ok());
  const dae::Invariant* p = m.invariant("p(phi)");
  ASSERT_NE(p, nullptr);
  ASSERT_NE(m.invariant("jacobi"), nullptr);
  Random r;
  for (int i = 0; i < 50; ++i) {
    double m1 = r(0.1, 2), m2 = r(0.1, 2), m3 = r(0.1, 2), l = r(0.1, 1), g = 9.81, th = r(-3, 3), wphi = r(-20, 20);
    for (auto [n, val] : {std::pair{"m1", m1}, {"m2", m2}, {"m3", m3}, {"l", l}, {"g", g}, {"theta", th},
                          {"der(theta)", r(-5, 5)}, {"phi", r(-5, 5)}, {"der(phi)", wphi}})
      m.set(n, val);
    double expected = (4.0 / 3 * m1 + 2 * m2) * l * l * std::sin(th) * std::sin(th) * wphi;
    EXPECT_TRUE(closeRelative(m.eval(p->value), expected, std::fabs(expected) + 1e-12));
  }
}

TEST(TextbookExamples, WedgeCylinderBlock) {  // example 5-4: the three printed equations
  auto m = CompiledModel::fromFile("examples/textbook/wedge.qd");
  ASSERT_TRUE(m.ok());
  Random r;
  for (int i = 0; i < kPoints; ++i) {
    double mA = r(0.1, 10), mB = r(0.1, 10), mD = r(0.1, 10), rr = r(0.01, 1), al = r(0.05, 1.5), g = r(1, 20);
    double aA = r(-10, 10), aB = r(-10, 10), aD = r(-10, 10);
    for (auto [n, val] : {std::pair{"mA", mA}, {"mB", mB}, {"mD", mD}, {"r", rr}, {"alpha", al}, {"g", g},
                          {"xA", r(-1, 1)}, {"xB", r(-1, 1)}, {"yD", r(-1, 1)}, {"der(xA)", r(-3, 3)},
                          {"der(xB)", r(-3, 3)}, {"der(yD)", r(-3, 3)}, {"der(der(xA))", aA}, {"der(der(xB))", aB},
                          {"der(der(yD))", aD}})
      m.set(n, val);
    double c = std::cos(al), s = std::sin(al);
    double scale = (mA + mB + mD) * (std::fabs(aA) + std::fabs(aB) + std::fabs(aD) + g);
    EXPECT_TRUE(closeRelative(m.eulerLagrange("xA"), (mA + mB + mD) * aA + mB * c * aB, scale));
    EXPECT_TRUE(closeRelative(m.eulerLagrange("xB"), mB * c * aA + 1.5 * mB * aB + 0.5 * mB * aD - mB * g * s, scale));
    EXPECT_TRUE(closeRelative(m.eulerLagrange("yD"), 0.5 * (mB + 2 * mD) * aD + 0.5 * mB * aB - mD * g, scale));
  }
  // xA does not occur in L and nothing forces it: its momentum is a first integral.
  const dae::Invariant* p = m.invariant("p(xA)");
  ASSERT_NE(p, nullptr);
  m.set("der(xA)", 0.7);
  m.set("der(xB)", -0.3);
  double expected = (4 + 2 + 1) * 0.7 + 2 * std::cos(0.5235987755982988) * -0.3;
  for (auto [n, val] : {std::pair{"mA", 4.0}, {"mB", 2.0}, {"mD", 1.0}, {"alpha", 0.5235987755982988}}) m.set(n, val);
  EXPECT_NEAR(m.eval(p->value), expected, 1e-14);
}

}  // namespace
}  // namespace qdot::test
