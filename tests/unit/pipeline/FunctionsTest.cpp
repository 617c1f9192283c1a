// User-defined functions (docs/language.md#functions) from .qd text through the front end: each
// call is inlined at flatten time, so the flat equations and the Euler–Lagrange rows are plain
// expressions of the caller's variables. Checked by evaluating them at chosen values against the
// hand-expanded formula: positional and named arguments, defaults, protected locals in any order,
// nested calls, lookup through packages and imports, time and der() as arguments. The located
// errors are in the diagnostics corpus (function_*.qd).
#include <cmath>
#include <string>

#include "CompiledModel.h"
#include "ast/AST.h"
#include "syntax/Parser.h"

namespace qdot::test {
namespace {

/// The residual of the k-th user equation (after the Euler–Lagrange and kinematic rows).
double userEquation(CompiledModel& m, size_t k) {
  size_t skip = 0;
  for (const auto& e : m.dae().equations)
    if (e.origin.kind == flat::OriginKind::EulerLagrange || e.origin.kind == flat::OriginKind::Kinematic) ++skip;
  return m.eval(m.dae().equations.at(skip + k).residual);
}

const char* kHydro = R"(
package Hydro
  function gateForce "F = rho g w (d2^2 - d1^2)/2"
    input Real width;
    input Real depthTop;
    input Real depthBottom;
    input Real rho = 1000;
    input Real g = 9.81;
    output Real F = rho*g*width*span*mean;
  protected
    Real mean = (depthBottom + depthTop)/2;
    Real span = depthBottom - depthTop;
  end gateForce;
  function twice
    input Real x;
    output Real y = 2*x;
  end twice;
end Hydro;
)";

double gateForce(double w, double d1, double d2, double rho = 1000, double g = 9.81) {
  return rho * g * w * (d2 * d2 - d1 * d1) / 2;
}

TEST(Functions, PositionalNamedAndDefaultArgumentsInline) {
  CompiledModel m("f", std::string(kHydro) + R"(
model Gate
  import Hydro.*;
  parameter Real w = 2;
  Real h;
  Real a;
  Real b;
  Real c;
equation
  der(h) = -0.1*h;
  a = gateForce(w, 0.5, h);
  b = Hydro.gateForce(w, 0.5, h, rho = 1025);
  c = gateForce(depthBottom = h, g = 9.80665, width = twice(w), depthTop = Hydro.twice(0.25));
end Gate;)");
  ASSERT_TRUE(m.ok());
  const double w = 2, h = 3.7;
  m.set("w", w);
  m.set("h", h);
  m.set("der(h)", -0.1 * h);
  m.set("a", gateForce(w, 0.5, h));
  m.set("b", gateForce(w, 0.5, h, 1025));
  m.set("c", gateForce(2 * w, 0.5, h, 1000, 9.80665));
  for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(userEquation(m, k), 0.0, 1e-9) << "equation " << k;
  m.set("b", gateForce(w, 0.5, h));  // the default rho would not satisfy b's equation
  EXPECT_GT(std::fabs(userEquation(m, 2)), 1.0);
}

// An energy written with a function: the Euler–Lagrange row is differentiated through the inlined
// body, m q'' + k q = F(t) with V = k q²/2 from the call and the force a call of time and der(q).
TEST(Functions, CallsInEnergiesAndForcesAreDifferentiated) {
  CompiledModel m("f", R"(
function springEnergy
  input Real x;
  input Real k = 40;
  output Real V = k*x^2/2;
end springEnergy;
function drag
  input Real v;
  input Real c;
  output Real F = -c*v;
end drag;
model Oscillator
  parameter Real m = 2;
  coordinate Real q(start = 0.1);
mechanics
  kinetic = 0.5*m*der(q)^2;
  potential = springEnergy(q);
  force(q) = drag(der(q), c = 0.3) + springEnergy(time, k = 2);
end Oscillator;)");
  ASSERT_TRUE(m.ok());
  const double mass = 2, q = 0.3, v = -0.7, a = 1.9, t = 1.5;
  m.set("m", mass);
  m.set("q", q);
  m.set("der(q)", v);
  m.set("der(der(q))", a);
  m.set("time", t);
  EXPECT_NEAR(m.eulerLagrange("q"), mass * a + 40 * q - (-0.3 * v + t * t), 1e-12);
}

TEST(Functions, ParserMarksProtectedLocalsOnlyInFunctions) {
  SourceManager sm;
  DiagnosticEngine diags;
  uint32_t file = sm.addBuffer("p.qd", R"(
function f
  input Real x;
  output Real y = t;
protected
  Real t = x;
public
  input Real z;
end f;)");
  auto def = syntax::parse(sm, file, diags);
  ASSERT_FALSE(diags.hasErrors());
  const ast::ClassDef& f = *def->classes.at(0);
  EXPECT_EQ(f.kind, ast::ClassKind::Function);
  ASSERT_EQ(f.declarations.size(), 4u);
  EXPECT_FALSE(f.declarations[1].isProtected);
  EXPECT_TRUE(f.declarations[2].isProtected);
  EXPECT_FALSE(f.declarations[3].isProtected);
  uint32_t model = sm.addBuffer("m.qd", "model M\nprotected\n  Real x;\nend M;");
  syntax::parse(sm, model, diags);
  EXPECT_TRUE(diags.hasErrors());  // E0119: 'protected' belongs to functions
}

}  // namespace
}  // namespace qdot::test
