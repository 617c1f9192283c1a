// The models of the language specification (shared/spec/language.md §1, §5, §7) parse without
// errors into the expected trees; plus a small printAST golden test.
#include "SyntaxTestUtil.h"

namespace qdot::testing {
namespace {

using namespace ast;

const char* kUTube = R"(model UTube "Liquid column oscillating in a U-tube"
  parameter Real rho = 1000 "density [kg/m3]";
  parameter Real A = 1e-4 "bore [m2]";
  parameter Real l = 1.0 "length of the liquid column [m]";
  parameter Real g = 9.81;
  parameter Real h = 0.1 "initial level difference [m]";
  coordinate Real x(start = h/2) "offset of the free surface [m]";
  Real E "total energy [J]";
mechanics
  kinetic   = 0.5*rho*A*l*der(x)^2;
  potential = rho*A*g*x^2;
equation
  E = 0.5*rho*A*l*der(x)^2 + rho*A*g*x^2;
  annotation(experiment(StopTime = 10, Interval = 0.01, Tolerance = 1e-6));
end UTube;
)";

const char* kDoublePendulum = R"(model DoublePendulum
  parameter Real m = 1, l = 1, g = 9.81;
  coordinate Real th[2](start = {0.5, 0.5});
  Real x[2] = {l*sin(th[1]), l*sin(th[1]) + l*sin(th[2])};
  Real y[2] = {-l*cos(th[1]), -l*cos(th[1]) - l*cos(th[2])};
mechanics
  kinetic   = sum(0.5*m*(der(x[i])^2 + der(y[i])^2) for i in 1:2);
  potential = sum(m*g*y[i] for i in 1:2);
end DoublePendulum;
)";

const char* kComponents = R"(connector Flange "1-D translational port"
  Real s "position [m]";
  flow Real f "force on the component through this port [N]";
end Flange;

model Mass
  parameter Real m = 1;
  Flange a, b;
mechanics
  kinetic = 0.5*m*der(a.s)^2;
equation
  b.s = a.s;
end Mass;

model Spring
  parameter Real c = 100, s0 = 0;
  Flange a, b;
mechanics
  potential = 0.5*c*(b.s - a.s - s0)^2;
end Spring;
)";

const char* kPackage = R"(package Vibration
  import Vibration.*;
  model Chain
    parameter Integer n = 3;
    Mass m1(m = 2);
    Mass ms[n](m = fill(1, n));
    Vibration.Spring s(c = 50);
    extends Base(k = 1);
  equation
    connect(m1.b, s.a);
    for i in 1:n - 1 loop
      connect(ms[i].b, ms[i + 1].a);
    end for;
  initial equation
    der(m1.a.s) = 0.5;
  end Chain;
  model Ball
    parameter Real e = 0.8;
    Real h(start = 1), v;
  equation
    der(h) = v;
    der(v) = -9.81;
    when h < 0 then
      reinit(v, -e*pre(v));
    end when;
  end Ball;
end Vibration;
)";

std::unique_ptr<Parsed> parseClean(const char* text) {
  auto p = parseText(text);
  EXPECT_FALSE(p->diags.hasErrors()) << p->rendered();
  EXPECT_TRUE(p->diags.diagnostics().empty());
  return p;
}

TEST(SpecModels, UTube) {
  auto p = parseClean(kUTube);
  const ClassDef& m = p->cls();
  EXPECT_EQ(m.name, "UTube");
  EXPECT_EQ(m.description, "Liquid column oscillating in a U-tube");
  ASSERT_EQ(m.declarations.size(), 7u);
  EXPECT_TRUE(m.declarations[5].isCoordinate);
  EXPECT_EQ(sexpr(m.declarations[5].mods[0].value.get()), "(/ h 2)");
  EXPECT_EQ(m.declarations[1].description, "bore [m2]");
  ASSERT_EQ(m.mechanics.size(), 2u);
  EXPECT_EQ(sexpr(m.mechanics[1].value.get()), "(* (* (* rho A) g) (^ x 2))");
  ASSERT_EQ(m.equations.size(), 1u);
  ASSERT_EQ(m.annotations.size(), 1u);
  const Modification& exp = m.annotations[0].mods[0];
  EXPECT_EQ(exp.name, "experiment");
  ASSERT_EQ(exp.nested.size(), 3u);
  EXPECT_EQ(exp.nested[2].name, "Tolerance");
}

TEST(SpecModels, DoublePendulum) {
  auto p = parseClean(kDoublePendulum);
  const ClassDef& m = p->cls();
  ASSERT_EQ(m.declarations.size(), 6u);
  EXPECT_EQ(m.declarations[3].name, "th");
  EXPECT_EQ(sexpr(m.declarations[3].dims[0].get()), "2");
  EXPECT_EQ(sexpr(m.declarations[5].binding.get()),
            "(array (neg (* l (call cos (index th 1)))) (- (neg (* l (call cos (index th 1)))) (* l (call cos (index th 2)))))");
  ASSERT_EQ(m.mechanics.size(), 2u);
  auto* sum = dyn_cast<CallExpr>(m.mechanics[0].value.get());
  ASSERT_NE(sum, nullptr);
  EXPECT_EQ(sum->callee->dotted(), "sum");
  ASSERT_EQ(sum->args.size(), 1u);
  EXPECT_TRUE(isa<ComprehensionExpr>(sum->args[0].get()));
}

TEST(SpecModels, ConnectorsAndComponents) {
  auto p = parseClean(kComponents);
  ASSERT_EQ(p->def->classes.size(), 3u);
  EXPECT_EQ(p->cls(0).kind, ClassKind::Connector);
  EXPECT_TRUE(p->cls(0).declarations[1].isFlow);
  const ClassDef& mass = p->cls(1);
  EXPECT_EQ(mass.declarations[1].typeName, std::vector<std::string>{"Flange"});
  EXPECT_EQ(sexpr(mass.mechanics[0].value.get()), "(* (* 0.5 m) (^ (call der a.s) 2))");
  EXPECT_EQ(sexpr(mass.equations[0].lhs.get()), "b.s");
  EXPECT_EQ(sexpr(p->cls(2).mechanics[0].value.get()), "(* (* 0.5 c) (^ (- (- b.s a.s) s0) 2))");
}

TEST(SpecModels, PackagesComponentsAndEvents) {
  auto p = parseClean(kPackage);
  const ClassDef& pkg = p->cls();
  ASSERT_EQ(pkg.classes.size(), 2u);
  const ClassDef& chain = *pkg.classes[0];
  EXPECT_EQ(chain.declarations[3].typeName, (std::vector<std::string>{"Vibration", "Spring"}));
  EXPECT_EQ(chain.extends.size(), 1u);
  ASSERT_EQ(chain.equations.size(), 2u);
  EXPECT_EQ(chain.equations[1].kind, EquationKind::For);
  EXPECT_EQ(sexpr(chain.equations[1].iterators[0].range.get()), "(: 1 (- n 1))");
  EXPECT_EQ(chain.initialEquations.size(), 1u);
  const ClassDef& ball = *pkg.classes[1];
  EXPECT_EQ(ball.equations[2].kind, EquationKind::When);
}

TEST(SpecModels, AllTogetherInOneFile) {
  std::string all = std::string(kUTube) + kDoublePendulum + kComponents + kPackage;
  auto p = parseClean(all.c_str());
  EXPECT_EQ(p->def->classes.size(), 6u);
}

TEST(Printer, GoldenDump) {
  auto p = parseClean(R"(within Lib;
model M "demo"
  parameter Real k[2] = {1, 2.5} "gains";
  coordinate Real q(start = 0.1);
mechanics
  force(q) = -k[1]*der(q);
equation
  for i in 1:2 loop
    connect(a[i], b);
  end for;
  if q > 0 then x = 1; else x = -1; end if;
end M;
)");
  std::ostringstream os;
  ast::printAST(os, *p->def, p->sm);
  EXPECT_EQ(os.str(), R"(StoredDefinition within Lib
  Class model M "demo" @2:1
    Declaration k : parameter Real "gains" @3:18
      dim: Number 2 int @3:20
      binding: Array @3:25
        Number 1 int @3:26
        Number 2.5 @3:29
    Declaration q : coordinate Real @4:19
      Modification start @4:21
        value: Number 0.1 @4:29
    Mechanics force @6:3
      target: Name q @6:9
      value: Unary - @6:14
        Binary * @6:15
          Index @6:15
            base: Name k @6:15
            sub: Number 1 int @6:17
          Call der @6:20
            Name q @6:24
    Equations
      Equation for @8:3
        Iterator i @8:7
          in: Range @8:12
            start: Number 1 int @8:12
            stop: Number 2 int @8:14
        Equation connect @9:5
          lhs: Index @9:13
            base: Name a @9:13
            sub: Name i @9:15
          rhs: Name b @9:19
      Equation if @11:3
        branch
          condition: Binary > @11:6
            Name q @11:6
            Number 0 int @11:10
          Equation simple @11:17
            lhs: Name x @11:17
            rhs: Number 1 int @11:21
        else
          Equation simple @11:29
            lhs: Name x @11:29
            rhs: Unary - @11:33
              Number 1 int @11:34
)");
}

TEST(Printer, PartialTreesPrintNullChildren) {
  auto p = parseText("model M\n  Real a = );\nmechanics\n  kinetic = ;\nend M;\n");
  std::ostringstream os;
  ast::printAST(os, *p->def, p->sm);
  EXPECT_NE(os.str().find("value: <null>"), std::string::npos) << os.str();
}

}  // namespace
}  // namespace qdot::testing
