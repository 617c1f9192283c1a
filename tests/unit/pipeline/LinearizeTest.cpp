// qdot linearize and qdot modes on DAEs with algebraic unknowns (driver/Modes.h, compiler/linear),
// against closed forms to 1e-8 relative:
//   a force given by an equation, F = −k x − c ẋ: ω = √(k/m), ζ = c / (2√(km)); output F: C = [−k, −c];
//   a massless node x2 between springs k1 (to the mass) and k2 (to the wall): ω² = k1 k2 / ((k1 + k2) m);
//   a spring acting through a lever, r F = −k x: ω² = k / (r m); with r = 0 nothing determines F
//   (index > 1: refused);
//   a forced mass–spring–damper, input u: A = [[0, 1], [−k/m, −c/m]], B = [[0], [1/m]];
//   a second mass m2 riding rigidly on x1 through a flow f2 (a row beyond the coordinates' own, as a
//   coordinate eliminated as an alias leaves): M = m1 + m2, ω² = k / (m1 + m2);
//   two free masses joined by a spring through flows f1 + f2 = 0: M = diag(m1, m2),
//   K = k [[1, −1], [−1, 1]], ω² = k (m1 + m2) / (m1 m2) and a rigid-body mode (about the start state);
//   component models (connectors, flows, aliased potentials): a mass on a spring and a damper to a
//   wall, ω = √(k/m), ζ = c/(2√(km)); two masses between three springs, √(k/m) and √(3k/m); a mass
//   on two springs in series (a massless junction), ω² = k1 k2 / ((k1 + k2) m); a mass pushed by an
//   input through a connector: A and B as for the flat forced mass; a spring and a damper in
//   parallel without a mass, pushed by u (the coordinate first-order): c ẋ + k x = u, A = −k/c, B = 1/c;
//   the same mass driven through a first-order lag τ ḟ = u − f (not a mechanical system: the modes
//   are the eigenvalues of A): ω = √(k/m) and the real rate −1/τ.
#include <gtest/gtest.h>

#include <cmath>

#include "driver/Modes.h"

namespace qdot::driver {
namespace {

constexpr const char* algebraicForce = R"(
model AlgebraicForce
  parameter Real m = 2, k = 50, c = 3;
  coordinate Real x(start = 0.1);
  Real F;
  output Real Fo = F;
mechanics
  kinetic = 0.5*m*der(x)^2;
  force(x) = F;
equation
  F = -k*x - c*der(x);
end AlgebraicForce;
)";

constexpr const char* masslessNode = R"(
model MasslessNode
  parameter Real m = 2, k1 = 30, k2 = 60;
  coordinate Real x1(start = 0.1), x2;
mechanics
  kinetic = 0.5*m*der(x1)^2;
  potential = 0.5*k1*(x1 - x2)^2 + 0.5*k2*x2^2;
end MasslessNode;
)";

constexpr const char* lever = R"(
model Lever
  parameter Real m = 1.5, k = 10, r = 0.5;
  coordinate Real x(start = 0.1);
  Real F;
mechanics
  kinetic = 0.5*m*der(x)^2;
  force(x) = F;
equation
  r*F = -k*x;
end Lever;
)";

constexpr const char* riding = R"(
model Riding
  parameter Real m1 = 1, m2 = 2, k = 54;
  coordinate Real x1(start = 0.1);
  Real f2;
mechanics
  kinetic = 0.5*m1*der(x1)^2;
  potential = 0.5*k*x1^2;
  force(x1) = -f2;
equation
  m2*der(der(x1)) = f2;
end Riding;
)";

constexpr const char* freeFree = R"(
model FreeFree
  parameter Real m1 = 1, m2 = 2, k = 50;
  coordinate Real x1(start = 0.1), x2;
  Real f1, f2;
mechanics
  kinetic = 0.5*m1*der(x1)^2 + 0.5*m2*der(x2)^2;
  force(x1) = f1;
  force(x2) = f2;
equation
  f1 = -k*(x1 - x2);
  f1 + f2 = 0;
end FreeFree;
)";

constexpr const char* forced = R"(
model ForcedMSD
  parameter Real m = 2, k = 50, c = 3;
  input Real u;
  coordinate Real x(start = 0);
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
  dissipation = 0.5*c*der(x)^2;
  force(x) = u;
end ForcedMSD;
)";

constexpr const char* lag = R"(
model Lag
  parameter Real m = 2, k = 50, tau = 0.25;
  input Real u;
  coordinate Real x(start = 0);
  Real f(start = 0);
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
  force(x) = f;
equation
  tau*der(f) = u - f;
end Lag;
)";

// A small translational library: the potential s is the position, the flow f the force on the
// component through the port.
constexpr const char* library = R"(
connector Flange
  Real s;
  flow Real f;
end Flange;
model Fixed
  parameter Real s0 = 0;
  Flange a;
equation
  a.s = s0;
end Fixed;
model Mass
  parameter Real m = 1;
  Flange a, b;
mechanics
  kinetic = 0.5*m*der(a.s)^2;
equation
  b.s = a.s;
end Mass;
model Spring
  parameter Real k = 1;
  Flange a, b;
mechanics
  potential = 0.5*k*(b.s - a.s)^2;
end Spring;
model Damper
  parameter Real c = 1;
  Flange a, b;
mechanics
  dissipation = 0.5*c*(der(b.s) - der(a.s))^2;
end Damper;
model Push "applies the force u to what it is connected to"
  Flange a;
  Real u;
equation
  a.f = -u;
end Push;
)";

constexpr const char* componentOscillator = R"(
model Oscillator
  Fixed wall;
  Spring sp(k = 50);
  Damper d(c = 3);
  Mass m1(m = 2);
equation
  connect(wall.a, sp.a);
  connect(sp.b, m1.a);
  connect(wall.a, d.a);
  connect(d.b, m1.a);
end Oscillator;
)";

constexpr const char* componentTwoMasses = R"(
model TwoMasses
  Fixed wall, wall2;
  Spring s1(k = 50), s2(k = 50), s3(k = 50);
  Mass m1(m = 2), m2(m = 2);
equation
  connect(wall.a, s1.a);
  connect(s1.b, m1.a);
  connect(m1.b, s2.a);
  connect(s2.b, m2.a);
  connect(m2.b, s3.a);
  connect(s3.b, wall2.a);
end TwoMasses;
)";

constexpr const char* componentSeriesSprings = R"(
model SeriesSprings
  Fixed wall;
  Spring s1(k = 30), s2(k = 60);
  Mass m1(m = 2);
equation
  connect(wall.a, s2.a);
  connect(s2.b, s1.a);
  connect(s1.b, m1.a);
end SeriesSprings;
)";

constexpr const char* componentCreep = R"(
model Creep
  input Real u;
  Fixed wall;
  Spring sp(k = 50);
  Damper d(c = 5);
  Push p;
equation
  connect(wall.a, sp.a);
  connect(wall.a, d.a);
  connect(sp.b, d.b);
  connect(sp.b, p.a);
  p.u = u;
end Creep;
)";

constexpr const char* componentPushed = R"(
model Pushed
  input Real u;
  Fixed wall;
  Spring sp(k = 50);
  Mass m1(m = 2);
  Push p;
equation
  connect(wall.a, sp.a);
  connect(sp.b, m1.a);
  connect(m1.b, p.a);
  p.u = u;
end Pushed;
)";

// Compiles `source` and linearizes it with the run-time values `parameters`.
template <class Result, class Compute>
Result compiled(const char* source, const std::vector<std::string>& parameters, linear::OperatingPoint at,
                Compute compute) {
  Compilation c;
  EXPECT_TRUE(compileSource(c, "test.qd", source, "", Stage::Kernel));
  return compute(c, parameters, at);
}

LinearizeResult linearized(const char* source, std::vector<std::string> parameters = {},
                           linear::OperatingPoint at = linear::OperatingPoint::Equilibrium) {
  return compiled<LinearizeResult>(source, parameters, at, linearizeModel);
}

ModesResult modesOf(const char* source, std::vector<std::string> parameters = {},
                    linear::OperatingPoint at = linear::OperatingPoint::Equilibrium) {
  return compiled<ModesResult>(source, parameters, at, computeModes);
}

void expectRelative(double got, double want, double rel = 1e-8) { EXPECT_NEAR(got, want, rel * std::fabs(want)); }

void expectMatrix(const Eigen::MatrixXd& got, const Eigen::MatrixXd& want) {
  ASSERT_EQ(got.rows(), want.rows());
  ASSERT_EQ(got.cols(), want.cols());
  for (Eigen::Index i = 0; i < want.rows(); ++i)
    for (Eigen::Index j = 0; j < want.cols(); ++j)
      EXPECT_NEAR(got(i, j), want(i, j), 1e-12 * std::max(1.0, std::fabs(want(i, j)))) << "(" << i << ", " << j << ")";
}

TEST(Linearize, ForceFromAnEquationGivesTheOscillatorsModes) {
  for (auto at : {linear::OperatingPoint::Equilibrium, linear::OperatingPoint::Start}) {
    ModesResult r = modesOf(algebraicForce, {"m=2", "k=50", "c=3"}, at);
    ASSERT_EQ(r.error, "");
    ASSERT_EQ(r.modes.size(), 1u);
    expectRelative(r.modes[0].omega, std::sqrt(50.0 / 2));
    expectRelative(r.modes[0].zeta, 3 / (2 * std::sqrt(50.0 * 2)));
    ASSERT_TRUE(r.system.mechanical);  // F eliminated from the row m ẍ − F = 0
    expectRelative(r.system.mechanical->M(0, 0), 2);
    expectRelative(r.system.mechanical->C(0, 0), 3);
    expectRelative(r.system.mechanical->K(0, 0), 50);
    EXPECT_EQ(r.system.coordinates, std::vector<std::string>{"x"});
  }
}

TEST(Linearize, OutputThroughAnAlgebraicUnknown) {
  LinearizeResult r = linearized(algebraicForce, {"k=40", "c=5"});
  ASSERT_EQ(r.error, "");
  const linear::StateSpace& s = r.model.stateSpace;
  EXPECT_EQ(s.states, (std::vector<std::string>{"x", "der(x)"}));
  EXPECT_EQ(s.outputs, std::vector<std::string>{"Fo"});
  expectMatrix(s.C, Eigen::RowVector2d(-40, -5));
  EXPECT_EQ(s.D.rows(), 1);
  EXPECT_EQ(s.D.cols(), 0);
}

TEST(Linearize, MasslessNodeBetweenTwoSprings) {
  ModesResult r = modesOf(masslessNode, {"m=2", "k1=30", "k2=60"});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.modes[0].omega, std::sqrt(30.0 * 60 / (90 * 2)));
  EXPECT_EQ(r.system.coordinates, std::vector<std::string>{"x1"});  // x2 is algebraic: not a state
  ASSERT_TRUE(r.system.mechanical);
  expectRelative(r.system.mechanical->K(0, 0), 30.0 * 60 / 90);
}

TEST(Linearize, RowBeyondTheCoordinatesAddsItsMass) {
  ModesResult r = modesOf(riding, {"m1=1", "m2=2", "k=54"});
  ASSERT_EQ(r.error, "");
  ASSERT_TRUE(r.system.mechanical);
  expectRelative(r.system.mechanical->M(0, 0), 3);
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.modes[0].omega, std::sqrt(54.0 / 3));
}

TEST(Linearize, FreeMassesJoinedThroughFlows) {
  double m1 = 1, m2 = 2, k = 50;
  ModesResult r = modesOf(freeFree, {"m1=1", "m2=2", "k=50"}, linear::OperatingPoint::Start);
  ASSERT_EQ(r.error, "");
  ASSERT_TRUE(r.system.mechanical);
  expectMatrix(r.system.mechanical->M, Eigen::Vector2d(m1, m2).asDiagonal().toDenseMatrix());
  expectMatrix(r.system.mechanical->K, (Eigen::Matrix2d() << k, -k, -k, k).finished());
  ASSERT_EQ(r.modes.size(), 2u);
  expectRelative(r.modes[0].omega, std::sqrt(k * (m1 + m2) / (m1 * m2)));
  expectRelative(r.modes[0].shape[1] / r.modes[0].shape[0], -m1 / m2);  // momentum stays zero
  EXPECT_FALSE(r.modes[1].oscillating);                                 // the rigid-body motion
  EXPECT_NEAR(r.modes[1].shape[0], r.modes[1].shape[1], 1e-12);
  // No isolated equilibrium: the pair can sit anywhere.
  ModesResult anywhere = modesOf(freeFree);
  EXPECT_NE(anywhere.error.find("no isolated static equilibrium"), std::string::npos) << anywhere.error;
}

std::string component(const char* model) { return std::string(library) + model; }

TEST(Linearize, ComponentModelsModes) {
  ModesResult oscillator = modesOf(component(componentOscillator).c_str());
  ASSERT_EQ(oscillator.error, "");
  ASSERT_TRUE(oscillator.system.mechanical);  // the flows eliminated from the rows
  expectRelative(oscillator.system.mechanical->M(0, 0), 2);
  expectRelative(oscillator.system.mechanical->C(0, 0), 3);
  expectRelative(oscillator.system.mechanical->K(0, 0), 50);
  ASSERT_EQ(oscillator.modes.size(), 1u);
  expectRelative(oscillator.modes[0].omega, std::sqrt(50.0 / 2));
  expectRelative(oscillator.modes[0].zeta, 3 / (2 * std::sqrt(50.0 * 2)));

  ModesResult two = modesOf(component(componentTwoMasses).c_str());
  ASSERT_EQ(two.error, "");
  ASSERT_TRUE(two.system.mechanical);
  expectMatrix(two.system.mechanical->M, (Eigen::Matrix2d() << 2, 0, 0, 2).finished());
  expectMatrix(two.system.mechanical->K, (Eigen::Matrix2d() << 100, -50, -50, 100).finished());
  ASSERT_EQ(two.modes.size(), 2u);
  expectRelative(two.modes[0].omega, std::sqrt(50.0 / 2));
  expectRelative(two.modes[1].omega, std::sqrt(3 * 50.0 / 2));
  EXPECT_NEAR(two.modes[1].shape[0], -two.modes[1].shape[1], 1e-12);

  ModesResult series = modesOf(component(componentSeriesSprings).c_str());
  ASSERT_EQ(series.error, "");
  ASSERT_EQ(series.modes.size(), 1u);
  EXPECT_EQ(series.system.coordinates.size(), 1u);  // the junction is algebraic
  expectRelative(series.modes[0].omega, std::sqrt(30.0 * 60 / (90 * 2)));
}

TEST(Linearize, ComponentModelWithAnInput) {
  LinearizeResult r = linearized(component(componentPushed).c_str(), {"u=5"});
  ASSERT_EQ(r.error, "");
  const linear::StateSpace& s = r.model.stateSpace;
  EXPECT_EQ(s.inputs, std::vector<std::string>{"u"});
  expectMatrix(s.A, (Eigen::Matrix2d() << 0, 1, -25, 0).finished());
  expectMatrix(s.B, Eigen::Vector2d(0, 0.5));
  expectRelative(r.model.point[0], 5.0 / 50, 1e-12);  // pushed out by u/k

  ModesResult creep = modesOf(component(componentCreep).c_str());
  ASSERT_EQ(creep.error, "");
  EXPECT_FALSE(creep.system.mechanical);  // its velocity is algebraic: a first-order coordinate
  expectMatrix(creep.system.stateSpace.A, Eigen::Matrix<double, 1, 1>(-50.0 / 5));
  expectMatrix(creep.system.stateSpace.B, Eigen::Matrix<double, 1, 1>(1 / 5.0));
  ASSERT_EQ(creep.modes.size(), 1u);
  EXPECT_FALSE(creep.modes[0].oscillating);
  expectRelative(creep.modes[0].rate, -10);
}

TEST(Linearize, ForcedMassSpringDamperStateSpace) {
  double m = 2, k = 50, c = 3;
  LinearizeResult r = linearized(forced, {"m=2", "k=50", "c=3"});
  ASSERT_EQ(r.error, "");
  const linear::StateSpace& s = r.model.stateSpace;
  EXPECT_EQ(s.states, (std::vector<std::string>{"x", "der(x)"}));
  EXPECT_EQ(s.inputs, std::vector<std::string>{"u"});
  expectMatrix(s.A, (Eigen::Matrix2d() << 0, 1, -k / m, -c / m).finished());
  expectMatrix(s.B, Eigen::Vector2d(0, 1 / m));
  // A constant input moves the equilibrium to u/k; the matrices stay.
  LinearizeResult pushed = linearized(forced, {"m=2", "k=50", "c=3", "u=5"});
  ASSERT_EQ(pushed.error, "");
  expectRelative(pushed.model.point[0], 5 / k, 1e-12);
  expectMatrix(pushed.model.stateSpace.A, s.A);
}

TEST(Linearize, FirstOrderLagUsesTheStateSpaceEigenvalues) {
  double m = 2, k = 50, tau = 0.25;
  ModesResult r = modesOf(lag, {"m=2", "k=50", "tau=0.25"});
  ASSERT_EQ(r.error, "");
  EXPECT_FALSE(r.system.mechanical);  // f is a first-order state
  expectMatrix(r.system.stateSpace.B, Eigen::Vector3d(0, 0, 1 / tau));
  ASSERT_EQ(r.modes.size(), 2u);
  expectRelative(r.modes[0].omega, std::sqrt(k / m));
  EXPECT_NEAR(r.modes[0].zeta, 0, 1e-12);
  EXPECT_FALSE(r.modes[1].oscillating);
  expectRelative(r.modes[1].rate, -1 / tau);
}

TEST(Linearize, LeverAndItsIndexTwoLimit) {
  ModesResult r = modesOf(lever, {"m=1.5", "k=10", "r=0.5"});
  ASSERT_EQ(r.error, "");
  ASSERT_EQ(r.modes.size(), 1u);
  expectRelative(r.modes[0].omega, std::sqrt(10 / (0.5 * 1.5)));
  for (auto at : {linear::OperatingPoint::Equilibrium, linear::OperatingPoint::Start}) {
    LinearizeResult singular = linearized(lever, {"r=0"}, at);
    EXPECT_EQ(singular.code, ExitCode::ModelError);
    EXPECT_NE(singular.error.find("not of index 1"), std::string::npos) << singular.error;
    EXPECT_NE(singular.error.find("not determined: der(der(x)), F"), std::string::npos) << singular.error;
  }
}

TEST(Linearize, FlatModelsKeepTheirMassDampingAndStiffness) {
  // The flat damped oscillator: the state-space A is [[0, 1], [−k/m, −c/m]] and M, C, K its rows'.
  Compilation c;
  ASSERT_TRUE(compileSource(c, "damped", R"(
model Damped
  parameter Real m = 4, k = 400, c = 6;
  coordinate Real x(start = 0.1);
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
  dissipation = 0.5*c*der(x)^2;
end Damped;
)",
                            "", Stage::Kernel));
  LinearizeResult r = linearizeModel(c, {}, linear::OperatingPoint::Equilibrium);
  ASSERT_EQ(r.error, "");
  expectMatrix(r.model.stateSpace.A, (Eigen::Matrix2d() << 0, 1, -100, -1.5).finished());
  EXPECT_EQ(r.model.stateSpace.B.cols(), 0);
  ASSERT_TRUE(r.model.mechanical);
  EXPECT_EQ(r.model.mechanical->M(0, 0), 4);
  EXPECT_EQ(r.model.mechanical->C(0, 0), 6);
  EXPECT_EQ(r.model.mechanical->K(0, 0), 400);
}

}  // namespace
}  // namespace qdot::driver
