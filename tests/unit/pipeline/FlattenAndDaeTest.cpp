// Flattening semantics (arrays, matrix products, slices, `end`, comprehensions, reductions,
// if-expressions, der() of definitions and of time) and the DAE's classification of variables,
// each checked by evaluating the flat equations at chosen values against hand-computed numbers.
#include <cmath>
#include <string>

#include "CompiledModel.h"

#include <algorithm>

namespace qdot::test {
namespace {

/// The residual of the k-th user equation (after the Euler–Lagrange and kinematic rows).
double userEquation(CompiledModel& m, size_t k) {
  size_t skip = 0;
  for (const auto& e : m.dae().equations)
    if (e.origin.kind == flat::OriginKind::EulerLagrange || e.origin.kind == flat::OriginKind::Kinematic) ++skip;
  return m.eval(m.dae().equations.at(skip + k).residual);
}

/// The value of a result column that is not an unknown: a variable an alias equation (`x = 10`,
/// `x = {1, 10, 100}`) made a known expression.
double aliasValue(CompiledModel& m, const std::string& name) {
  for (const auto& o : m.dae().outputs)
    if (o.name == name) return m.eval(o.value);
  ADD_FAILURE() << "no result column " << name;
  return std::nan("");
}

TEST(Flatten, MatrixVectorProductAndTranspose) {
  CompiledModel m("mv", R"(
model MV
  parameter Real A[2,3] = {{1, 2, 3}, {4, 5, 6}};
  Real x[3];
  Real y[2];
  Real z[3];
equation
  x = {1, 10, 100};
  y = A*x;
  z = transpose(A)*y;
end MV;)");
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m.dae().equations.size(), 5u);  // x = {1, 10, 100} is three aliases
  for (auto [n, v] : {std::pair{"A[1,1]", 1.0}, {"A[1,2]", 2.0}, {"A[1,3]", 3.0}, {"A[2,1]", 4.0}, {"A[2,2]", 5.0},
                      {"A[2,3]", 6.0}, {"y[1]", 321.0}, {"y[2]", 654.0},
                      {"z[1]", 321 + 4 * 654.0}, {"z[2]", 2 * 321 + 5 * 654.0}, {"z[3]", 3 * 321 + 6 * 654.0}})
    m.set(n, v);
  EXPECT_EQ(aliasValue(m, "x[1]"), 1.0);
  EXPECT_EQ(aliasValue(m, "x[2]"), 10.0);
  EXPECT_EQ(aliasValue(m, "x[3]"), 100.0);
  for (size_t k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(userEquation(m, k), 0.0) << "equation " << k;
}

TEST(Flatten, SlicesEndComprehensionsAndReductions) {
  CompiledModel m("sl", R"(
model Slices
  parameter Integer n = 4;
  Real v[n];
  Real a;
  Real b;
  Real c;
  Real d[2];
equation
  v = {i^2 for i in 1:n};
  a = sum(v[2:end]);
  b = product(v[i] for i in 1:2:n);
  c = max(v) - min(v[1], v[2]) + dot(v[1:2], {1, 1});
  d = v[end-1:end] + fill(1, 2);
end Slices;)");
  ASSERT_TRUE(m.ok());
  double v[] = {1, 4, 9, 16};
  for (int i = 0; i < 4; ++i) EXPECT_EQ(aliasValue(m, "v[" + std::to_string(i + 1) + "]"), v[i]);  // aliases of constants
  m.set("a", 4 + 9 + 16), m.set("b", 1 * 9), m.set("c", 16 - 1 + 5), m.set("d[1]", 10), m.set("d[2]", 17);
  for (size_t k = 0; k < 5; ++k) EXPECT_DOUBLE_EQ(userEquation(m, k), 0.0) << "equation " << k;
}

TEST(Flatten, IfExpressionsFoldOnIntegerParameters) {
  CompiledModel m("if", R"(
model Ifs
  parameter Integer n = 2;
  parameter Real p = 3;
  Real x;
  Real y;
equation
  x = if n > 1 then 10 else 20;
  y = if p > 2 then p else -p;
end Ifs;)");
  ASSERT_TRUE(m.ok());
  // Both equations give a variable by parameters: aliases, so their values are result columns.
  m.set("p", 3);
  EXPECT_EQ(aliasValue(m, "x"), 10.0);
  EXPECT_EQ(aliasValue(m, "y"), 3.0);
  m.set("p", 1);  // the run-time branch follows p
  EXPECT_EQ(aliasValue(m, "y"), -1.0);
}

TEST(Flatten, DerOfDefinitionsAndExplicitTime) {
  // x_tip = l sin(q) + A sin(w t): der(x_tip) = l cos(q) der(q) + A w cos(w t)
  CompiledModel m("dt", R"(
model Driven
  parameter Real l = 1, A = 0.1, w = 3;
  coordinate Real q;
  Real xt = l*sin(q) + A*sin(w*time);
  Real vt;
mechanics
  kinetic = 0.5*der(xt)^2;
equation
  vt = der(xt);
end Driven;)");
  ASSERT_TRUE(m.ok());
  double q = 0.4, v = -1.3, t = 0.7;
  m.set("l", 1), m.set("A", 0.1), m.set("w", 3), m.set("q", q), m.set("der(q)", v), m.set("time", t);
  m.set("vt", std::cos(q) * v + 0.1 * 3 * std::cos(3 * t));
  EXPECT_NEAR(userEquation(m, 0), 0.0, 1e-14);
  EXPECT_EQ(m.invariant("jacobi"), nullptr) << "L depends on time explicitly: no Jacobi integral";
}

// A chain a0 = a1 + 1, a1 = a2 + 1, …, aN = last, declared in the order that makes every use a
// forward reference. (Resolved by recursion, 4 500 links overflowed the stack.)
std::string chainModel(const std::string& declare, int links, const std::string& last) {
  std::string text = "model Chain\n  coordinate Real x(start = 1);\n  output Real y = a0;\n";
  for (int i = 0; i < links; ++i)
    text += "  " + declare + " a" + std::to_string(i) + " = a" + std::to_string(i + 1) + " + 1;\n";
  text += "  " + declare + " a" + std::to_string(links) + " = " + last + ";\n";
  return text + "mechanics\n  kinetic = 0.5*der(x)^2;\n  potential = 0.5*x^2;\nend Chain;\n";
}

constexpr int kChainLinks = 100000;

TEST(Flatten, ChainOfDefinitionsAsLongAsTheModel) {
  CompiledModel m("chain", chainModel("Real", kChainLinks, "x"));
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m.dae().outputs.size(), 1u);
  m.set("x", 0.25);
  EXPECT_DOUBLE_EQ(m.eval(m.dae().outputs[0].value), 0.25 + kChainLinks);
}

TEST(Flatten, ChainOfParametersAsLongAsTheModel) {
  CompiledModel m("chain", chainModel("parameter Real", kChainLinks, "2"));
  ASSERT_TRUE(m.ok());
  ASSERT_EQ(m.dae().parameters.size(), static_cast<size_t>(kChainLinks) + 1);
  // each default is over the next parameter: evaluate them from the end of the chain
  for (auto p = m.dae().parameters.rbegin(); p != m.dae().parameters.rend(); ++p) m.set(p->name, m.eval(p->value));
  EXPECT_DOUBLE_EQ(m.eval(m.dae().outputs.at(0).value), 2.0 + kChainLinks);
}

TEST(Flatten, CycleThroughALongChainIsReportedWhereItCloses) {
  driver::Compilation c;
  EXPECT_FALSE(driver::compileSource(c, "cycle", chainModel("Real", kChainLinks, "a0 + x"), "", driver::Stage::Dae));
  ASSERT_EQ(c.diags.diagnostics().size(), 1u);
  std::ostringstream os;
  DiagnosticEngine::renderOne(os, c.sources, c.diags.diagnostics()[0], false);
  // in the last link's binding, where the use of a0 closes the cycle
  EXPECT_EQ(os.str().substr(0, os.str().find('\n')),
            "cycle:" + std::to_string(kChainLinks + 4) + ":18: error[E0312]: the definition of 'a0' depends on itself");
}

// Descriptions, nominals, min and max (and units) live beside the variables (VariableAttributes): the
// elements of an array given one value share one record, whatever the array's size; elements
// given their own values get their own.
TEST(Flatten, AttributesAreSharedByTheElementsGivenTheSameValues) {
  CompiledModel m("attr", R"(
model Attr
  parameter Integer n = 50;
  coordinate Real x[n](start = {0.1*i for i in 1:n}, nominal = 2, unit = "m") "positions";
  Real y[2](nominal = {1, 5}, min = {0, -1}) "forces";
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n);
  potential = sum(0.5*x[i]^2 for i in 1:n);
equation
  y[1] = x[1]^2;
  y[2] = x[2]^2;
end Attr;)");
  ASSERT_TRUE(m.ok());
  const flat::FlatModel& f = *m.compilation().flat;
  auto variable = [&](const std::string& name) -> const flat::Variable& {
    return f.variables.at(f.variableOf(m.compilation().ctx.findSymbol(name)));
  };
  const flat::Variable& x1 = variable("x[1]");
  for (int i = 2; i <= 50; ++i) EXPECT_EQ(variable("x[" + std::to_string(i) + "]").attributes, x1.attributes);
  const flat::VariableAttributes& xa = f.attributesOf(x1);
  EXPECT_EQ(xa.description, "positions");
  EXPECT_EQ(xa.unit, "m");  // a string attribute (sema once refused it: E0213)
  ASSERT_TRUE(xa.nominal && xa.nominal->isConstant());
  EXPECT_EQ(xa.nominal->value, 2.0);
  EXPECT_EQ(xa.min, nullptr);
  EXPECT_EQ(variable("der(x[7])").attributes, 0);  // a derivative has none
  EXPECT_LT(f.attributes.size(), 10u);             // not one per element
  const flat::VariableAttributes &y1 = f.attributesOf(variable("y[1]")), &y2 = f.attributesOf(variable("y[2]"));
  EXPECT_EQ(y1.description, "forces");
  EXPECT_EQ(y2.description, "forces");
  EXPECT_EQ(y1.nominal->value, 1.0);
  EXPECT_EQ(y2.nominal->value, 5.0);
  EXPECT_EQ(y1.min->value, 0.0);
  EXPECT_EQ(y2.min->value, -1.0);
  EXPECT_EQ(f.attributesOf(variable("x[3]")).nominal, xa.nominal);
  // The DAE keeps the nominal value of each unknown.
  for (const dae::Variable& v : m.dae().variables)
    if (v.name == "y[2]") EXPECT_EQ(m.eval(v.declaration.nominal), 5.0);
    else if (v.name == "x[3]") EXPECT_EQ(m.eval(v.declaration.nominal), 2.0);
}

TEST(Dae, ClassifiesStatesAlgebraicsAndMasslessCoordinates) {
  // q1 has inertia; q2 is a massless node between two springs (algebraic); q3 is a damped massless
  // coordinate (first order: q3 a state, its velocity algebraic); x is a state, y algebraic.
  CompiledModel m("cls", R"(
model Classes
  parameter Real k = 10, c = 2, m = 1;
  coordinate Real q1(start = 1);
  coordinate Real q2;
  coordinate Real q3;
  Real x(start = 1);
  Real y;
mechanics
  kinetic = 0.5*m*der(q1)^2;
  potential = 0.5*k*(q2 - q1)^2 + 0.5*k*q2^2 + 0.5*k*q3^2;
  dissipation = 0.5*c*der(q3)^2;
equation
  der(x) = -x;
  y = 2*x;
end Classes;)");
  ASSERT_TRUE(m.ok());
  auto kindOf = [&](const std::string& name) {
    for (const auto& v : m.dae().variables)
      if (v.name == name) return v.kind == dae::VarKind::State ? std::string("state") : std::string("algebraic");
    return std::string("absent");
  };
  EXPECT_EQ(kindOf("q1"), "state");
  EXPECT_EQ(kindOf("der(q1)"), "state");
  EXPECT_EQ(kindOf("q2"), "algebraic");
  EXPECT_EQ(kindOf("der(q2)"), "absent");
  EXPECT_EQ(kindOf("q3"), "state");
  EXPECT_EQ(kindOf("der(q3)"), "algebraic");
  EXPECT_EQ(kindOf("x"), "state");
  EXPECT_EQ(kindOf("y"), "algebraic");
  EXPECT_EQ(m.dae().equations.size(), m.dae().variables.size());
}

TEST(Dae, ConstraintGetsAMultiplier) {
  // A pendulum written in Cartesian coordinates with the rod as a constraint x² + y² = l².
  CompiledModel m("con", R"(
model CartesianPendulum
  parameter Real m = 1, g = 9.81, l = 1;
  coordinate Real x(start = 1);
  coordinate Real y;
mechanics
  kinetic = 0.5*m*(der(x)^2 + der(y)^2);
  potential = m*g*y;
  constraint x^2 + y^2 = l^2;
end CartesianPendulum;)");
  ASSERT_TRUE(m.ok());
  const dae::Dae& d = m.dae();
  auto multiplier = std::find_if(d.variables.begin(), d.variables.end(), [](const dae::Variable& v) {
    return v.role == dae::UnknownRole::Multiplier;
  });
  ASSERT_NE(multiplier, d.variables.end());
  EXPECT_EQ(multiplier->name, "lambda[1]");
  // Index reduction: the constraint is differentiated twice (Pantelides), the accelerations are
  // unknowns with link rows, and two of the four links are dropped at run time: 9 rows, 7 unknowns.
  ASSERT_EQ(d.differentiatedRows.size(), 1u);
  EXPECT_EQ(d.differentiatedRows[0].size(), 3u);
  EXPECT_EQ(d.links.size(), 4u);
  EXPECT_EQ(d.equations.size(), d.variables.size() + d.dummyDerivativeCount());
  EXPECT_EQ(d.dummyDerivativeCount(), 2u);
  m.set("m", 2), m.set("g", 9.81), m.set("l", 1), m.set("x", 0.6), m.set("y", -0.8), m.set("der(x)", 0.1),
      m.set("der(y)", 0.2), m.set("der(der(x))", 1.5), m.set("der(der(y))", -0.5), m.set("lambda[1]", 3);
  // m ẍ − λ·2x = 0 and m ÿ + m g − λ·2y = 0
  EXPECT_NEAR(m.eulerLagrange("x"), 2 * 1.5 - 3 * 2 * 0.6, 1e-13);
  EXPECT_NEAR(m.eulerLagrange("y"), 2 * -0.5 + 2 * 9.81 - 3 * 2 * -0.8, 1e-13);
}

}  // namespace
}  // namespace qdot::test
