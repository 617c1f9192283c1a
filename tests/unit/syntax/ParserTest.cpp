// Parser tests for declarations, classes, sections and statements: each checks the tree through
// the AST fields (kinds, names, prefixes, ranges), not just the absence of errors.
#include "SyntaxTestUtil.h"

namespace qdot::testing {
namespace {

using namespace ast;

std::unique_ptr<Parsed> ok(const std::string& text) {
  auto p = parseText(text);
  EXPECT_FALSE(p->diags.hasErrors()) << p->rendered();
  return p;
}

TEST(Parser, MinimalModel) {
  auto p = ok("model M\nend M;\n");
  ASSERT_EQ(p->def->classes.size(), 1u);
  const ClassDef& m = p->cls();
  EXPECT_EQ(m.kind, ClassKind::Model);
  EXPECT_EQ(m.name, "M");
  EXPECT_EQ(p->where(m.nameRange), "1:7");
  EXPECT_EQ(p->sm.slice(m.range), "model M\nend M;");
  EXPECT_TRUE(m.declarations.empty());
}

TEST(Parser, ClassKindsAndDescription) {
  auto p = ok("connector C \"port\" end C; package P end P; record R end R; block B end B;\n"
              "function F end F; type T end T; model M \"a\" + \"b\" end M;");
  ASSERT_EQ(p->def->classes.size(), 7u);
  ClassKind kinds[] = {ClassKind::Connector, ClassKind::Package, ClassKind::Record, ClassKind::Block,
                       ClassKind::Function, ClassKind::Type, ClassKind::Model};
  for (size_t i = 0; i < 7; ++i) EXPECT_EQ(p->cls(i).kind, kinds[i]);
  EXPECT_EQ(p->cls(0).description, "port");
  EXPECT_EQ(p->cls(6).description, "ab");
}

TEST(Parser, DeclarationPrefixesAndTypes) {
  auto p = ok(R"(model M
  parameter Real k = 100 "spring";
  constant Real c = 3;
  parameter Integer n = 8;
  coordinate Real q(start = 0.1, fixed = true);
  input Real u;
  output Real y = 2*u;
  flow Real f;
  Boolean on;
  output parameter Real z;
  Vibration.Mass m1(m = 2);
end M;)");
  const auto& d = p->cls().declarations;
  ASSERT_EQ(d.size(), 10u);
  EXPECT_EQ(d[0].name, "k");
  EXPECT_EQ(d[0].variability, Variability::Parameter);
  EXPECT_EQ(d[0].typeName, std::vector<std::string>{"Real"});
  EXPECT_EQ(sexpr(d[0].binding.get()), "100");
  EXPECT_EQ(d[0].description, "spring");
  EXPECT_EQ(p->sm.slice(d[0].range), "k = 100 \"spring\"");
  EXPECT_EQ(p->where(d[0].typeRange), "2:13");
  EXPECT_EQ(d[1].variability, Variability::Constant);
  EXPECT_EQ(d[2].typeName, std::vector<std::string>{"Integer"});
  EXPECT_TRUE(d[3].isCoordinate);
  EXPECT_EQ(d[3].variability, Variability::Continuous);
  ASSERT_EQ(d[3].mods.size(), 2u);
  EXPECT_EQ(d[3].mods[0].name, "start");
  EXPECT_EQ(sexpr(d[3].mods[0].value.get()), "0.1");
  EXPECT_EQ(d[3].mods[1].name, "fixed");
  EXPECT_EQ(sexpr(d[3].mods[1].value.get()), "true");
  EXPECT_EQ(d[4].causality, Causality::Input);
  EXPECT_EQ(d[5].causality, Causality::Output);
  EXPECT_EQ(sexpr(d[5].binding.get()), "(* 2 u)");
  EXPECT_TRUE(d[6].isFlow);
  EXPECT_EQ(d[7].typeName, std::vector<std::string>{"Boolean"});
  EXPECT_EQ(d[8].causality, Causality::Output);  // prefixes in any order
  EXPECT_EQ(d[8].variability, Variability::Parameter);
  EXPECT_EQ(d[9].typeName, (std::vector<std::string>{"Vibration", "Mass"}));
  EXPECT_EQ(p->sm.slice(d[9].typeRange), "Vibration.Mass");
  EXPECT_EQ(d[9].mods[0].name, "m");
}

TEST(Parser, SeveralDeclaratorsShareThePrefixes) {
  auto p = ok("model M\n  parameter Real m = 1 \"mass\", l = 1, g = 9.81;\n  Flange a, b;\nend M;");
  const auto& d = p->cls().declarations;
  ASSERT_EQ(d.size(), 5u);
  EXPECT_EQ(d[0].name, "m");
  EXPECT_EQ(d[0].description, "mass");
  EXPECT_EQ(d[1].name, "l");
  EXPECT_EQ(d[2].name, "g");
  EXPECT_EQ(sexpr(d[2].binding.get()), "9.81");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(d[i].variability, Variability::Parameter);
  EXPECT_EQ(d[3].typeName, std::vector<std::string>{"Flange"});
  EXPECT_EQ(d[4].name, "b");
  EXPECT_EQ(p->where(d[4].nameRange), "3:13");
}

TEST(Parser, ArrayDeclarations) {
  auto p = ok(R"(model M
  parameter Integer n = 3;
  Real x[n];
  coordinate Real th[2](start = {0.5, 0.5});
  parameter Real m[3] = {1, 2, 3};
  Real M[2, 2];
  Real[3] v, w;
  Real y[:] = {1, 2};
end M;)");
  const auto& d = p->cls().declarations;
  ASSERT_EQ(d.size(), 8u);
  ASSERT_EQ(d[1].dims.size(), 1u);
  EXPECT_EQ(sexpr(d[1].dims[0].get()), "n");
  EXPECT_EQ(sexpr(d[2].dims[0].get()), "2");
  EXPECT_EQ(sexpr(d[2].mods[0].value.get()), "(array 0.5 0.5)");
  EXPECT_EQ(sexpr(d[3].binding.get()), "(array 1 2 3)");
  ASSERT_EQ(d[4].dims.size(), 2u);
  EXPECT_EQ(d[5].typeDims.size(), 1u);
  EXPECT_EQ(d[6].typeDims.size(), 1u);  // cloned for each declarator
  EXPECT_EQ(sexpr(d[6].typeDims[0].get()), "3");
  EXPECT_TRUE(d[5].dims.empty());
  EXPECT_EQ(sexpr(d[7].dims[0].get()), "(:)");
}

TEST(Parser, ComponentsWithModifiers) {
  auto p = ok(R"(model System
  parameter Integer n = 4;
  Mass m1(m = 2);
  Mass ms[n](m = fill(1, n));
  Spring s(c(start = 1, fixed = false) = 5, each final d.e = 2) "desc" annotation(Placement(x = 1));
end System;)");
  const auto& d = p->cls().declarations;
  ASSERT_EQ(d.size(), 4u);
  EXPECT_EQ(d[1].name, "m1");
  EXPECT_EQ(d[2].name, "ms");
  EXPECT_EQ(sexpr(d[2].dims[0].get()), "n");
  EXPECT_EQ(sexpr(d[2].mods[0].value.get()), "(call fill 1 n)");
  const Modification& c = d[3].mods[0];
  EXPECT_EQ(c.name, "c");
  ASSERT_EQ(c.nested.size(), 2u);
  EXPECT_EQ(c.nested[0].name, "start");
  EXPECT_EQ(sexpr(c.value.get()), "5");
  EXPECT_EQ(p->sm.slice(c.range), "c(start = 1, fixed = false) = 5");
  EXPECT_EQ(d[3].mods[1].name, "d.e");  // each/final accepted and ignored
  EXPECT_EQ(p->sm.slice(d[3].mods[1].nameRange), "d.e");
  EXPECT_EQ(d[3].description, "desc");
  ASSERT_TRUE(d[3].annotation.has_value());
  EXPECT_EQ(d[3].annotation->mods[0].name, "Placement");
}

TEST(Parser, ConnectorsAndFlow) {
  auto p = ok(R"(connector Flange "1-D translational port"
  Real s "position [m]";
  flow Real f "force on the component through this port [N]";
end Flange;)");
  const ClassDef& c = p->cls();
  EXPECT_EQ(c.kind, ClassKind::Connector);
  ASSERT_EQ(c.declarations.size(), 2u);
  EXPECT_FALSE(c.declarations[0].isFlow);
  EXPECT_TRUE(c.declarations[1].isFlow);
}

TEST(Parser, ExtendsAndImports) {
  auto p = ok(R"(model M
  import Vibration.*;
  import Vibration.Mass;
  import V = Vibration.Components;
  extends Base(k = 1, x(start = 2));
  extends Lib.Other;
end M;)");
  const ClassDef& m = p->cls();
  ASSERT_EQ(m.imports.size(), 3u);
  EXPECT_EQ(m.imports[0].path, std::vector<std::string>{"Vibration"});
  EXPECT_TRUE(m.imports[0].wildcard);
  EXPECT_EQ(m.imports[1].path, (std::vector<std::string>{"Vibration", "Mass"}));
  EXPECT_FALSE(m.imports[1].wildcard);
  EXPECT_EQ(m.imports[2].alias, "V");
  EXPECT_EQ(m.imports[2].path, (std::vector<std::string>{"Vibration", "Components"}));
  EXPECT_EQ(p->sm.slice(m.imports[2].range), "import V = Vibration.Components");
  ASSERT_EQ(m.extends.size(), 2u);
  EXPECT_EQ(m.extends[0].baseName, std::vector<std::string>{"Base"});
  ASSERT_EQ(m.extends[0].mods.size(), 2u);
  EXPECT_EQ(m.extends[0].mods[1].nested[0].name, "start");
  EXPECT_EQ(m.extends[1].baseName, (std::vector<std::string>{"Lib", "Other"}));
}

TEST(Parser, PackagesNestClassesAndWithin) {
  auto p = ok(R"(within Lib.Sub;
package Vibration "components"
  model Mass
    parameter Real m = 1;
  end Mass;
  package Inner
    connector Port Real s; end Port;
  end Inner;
  constant Real g = 9.81;
end Vibration;)");
  EXPECT_EQ(p->def->within, (std::vector<std::string>{"Lib", "Sub"}));
  const ClassDef& pkg = p->cls();
  EXPECT_EQ(pkg.kind, ClassKind::Package);
  ASSERT_EQ(pkg.classes.size(), 2u);
  EXPECT_EQ(pkg.classes[0]->name, "Mass");
  EXPECT_EQ(pkg.classes[0]->declarations[0].name, "m");
  EXPECT_EQ(pkg.classes[1]->classes[0]->kind, ClassKind::Connector);
  EXPECT_EQ(pkg.declarations[0].name, "g");
}

TEST(Parser, ShortClassDefinitionBecomesExtends) {
  auto p = ok("type Length = Real(unit = \"m\", min = 0) \"a length\";\nconnector Pin = Lib.Pin;");
  const ClassDef& t = p->cls(0);
  EXPECT_EQ(t.kind, ClassKind::Type);
  EXPECT_EQ(t.name, "Length");
  EXPECT_EQ(t.description, "a length");
  ASSERT_EQ(t.extends.size(), 1u);
  EXPECT_EQ(t.extends[0].baseName, std::vector<std::string>{"Real"});
  EXPECT_EQ(t.extends[0].mods[0].name, "unit");
  EXPECT_EQ(sexpr(t.extends[0].mods[0].value.get()), "\"m\"");
  EXPECT_EQ(p->cls(1).extends[0].baseName, (std::vector<std::string>{"Lib", "Pin"}));
}

TEST(Parser, SectionsInAnyOrderAndRepeated) {
  auto p = ok(R"(model M
  Real x, y;
equation
  x = 1;
mechanics
  kinetic = 1;
initial equation
  y = 2;
equation
  y = x;
mechanics
  potential = 2;
end M;)");
  const ClassDef& m = p->cls();
  EXPECT_EQ(m.equations.size(), 2u);
  EXPECT_EQ(m.initialEquations.size(), 1u);
  ASSERT_EQ(m.mechanics.size(), 2u);
  EXPECT_EQ(m.mechanics[1].kind, MechanicsKind::Potential);
}

TEST(Parser, SimpleEquations) {
  auto p = ok("model M\nequation\n  der(x) = -k*x \"decay\";\n  E = 0.5*m*v^2;\n  0 = a.b[2].c - time;\nend M;");
  const auto& eqs = p->cls().equations;
  ASSERT_EQ(eqs.size(), 3u);
  EXPECT_EQ(eqs[0].kind, EquationKind::Simple);
  EXPECT_EQ(sexpr(eqs[0].lhs.get()), "(call der x)");
  EXPECT_EQ(sexpr(eqs[0].rhs.get()), "(neg (* k x))");
  EXPECT_EQ(p->sm.slice(eqs[0].range), "der(x) = -k*x \"decay\"");
  EXPECT_EQ(sexpr(eqs[2].rhs.get()), "(- (. (index a.b 2) c) time)");
}

TEST(Parser, ForEquations) {
  auto p = ok("model M\nequation\n  for i in 1:n, j in 1:2 loop\n    x[i, j] = i;\n    for k in r loop y[k] = 0; end for;\n  end for;\nend M;");
  const Equation& f = p->cls().equations.at(0);
  EXPECT_EQ(f.kind, EquationKind::For);
  ASSERT_EQ(f.iterators.size(), 2u);
  EXPECT_EQ(f.iterators[0].name, "i");
  EXPECT_EQ(sexpr(f.iterators[0].range.get()), "(: 1 n)");
  EXPECT_EQ(p->where(f.iterators[1].nameRange), "3:17");
  ASSERT_EQ(f.body.size(), 2u);
  EXPECT_EQ(sexpr(f.body[0].lhs.get()), "(index x i j)");
  EXPECT_EQ(f.body[1].kind, EquationKind::For);
  EXPECT_EQ(f.body[1].body.size(), 1u);
}

TEST(Parser, ConnectEquations) {
  auto p = ok("model M\nequation\n  connect(a, b);\n  connect(ms[i].b, ms[i + 1].a) \"chain\";\nend M;");
  const auto& eqs = p->cls().equations;
  ASSERT_EQ(eqs.size(), 2u);
  EXPECT_EQ(eqs[0].kind, EquationKind::Connect);
  EXPECT_EQ(sexpr(eqs[0].lhs.get()), "a");
  EXPECT_EQ(sexpr(eqs[0].rhs.get()), "b");
  EXPECT_EQ(sexpr(eqs[1].lhs.get()), "(. (index ms i) b)");
  EXPECT_EQ(sexpr(eqs[1].rhs.get()), "(. (index ms (+ i 1)) a)");
}

TEST(Parser, WhenEquationsWithReinitAndPre) {
  auto p = ok(R"(model Ball
equation
  when h < 0 then
    reinit(v, -e*pre(v));
  elsewhen initial() then
    reinit(h, 1);
    z = 2;
  end when;
end Ball;)");
  const Equation& w = p->cls().equations.at(0);
  EXPECT_EQ(w.kind, EquationKind::When);
  ASSERT_EQ(w.conditions.size(), 2u);
  ASSERT_EQ(w.branches.size(), 2u);
  EXPECT_EQ(sexpr(w.conditions[0].get()), "(< h 0)");
  EXPECT_EQ(sexpr(w.conditions[1].get()), "(call initial)");
  const Equation& r = w.branches[0].at(0);
  EXPECT_EQ(r.kind, EquationKind::Simple);
  EXPECT_EQ(sexpr(r.lhs.get()), "(call reinit v (neg (* e (call pre v))))");
  EXPECT_EQ(r.rhs, nullptr);
  EXPECT_EQ(w.branches[1].size(), 2u);
  EXPECT_TRUE(w.elseBranch.empty());
}

TEST(Parser, IfEquations) {
  auto p = ok(R"(model M
equation
  if a > 1 then
    x = 1;
  elseif b then
    x = 2;
    y = 1;
  else
    x = 3;
  end if;
  if c then z = 1; end if;
end M;)");
  const Equation& e = p->cls().equations.at(0);
  EXPECT_EQ(e.kind, EquationKind::If);
  ASSERT_EQ(e.conditions.size(), 2u);
  EXPECT_EQ(e.branches[0].size(), 1u);
  EXPECT_EQ(e.branches[1].size(), 2u);
  ASSERT_EQ(e.elseBranch.size(), 1u);
  EXPECT_EQ(sexpr(e.elseBranch[0].rhs.get()), "3");
  EXPECT_TRUE(p->cls().equations.at(1).elseBranch.empty());
}

TEST(Parser, InitialEquations) {
  auto p = ok("model M\ninitial equation\n  der(x) = 0.5;\n  x = 2*y;\nend M;");
  ASSERT_EQ(p->cls().initialEquations.size(), 2u);
  EXPECT_TRUE(p->cls().equations.empty());
}

TEST(Parser, MechanicsStatements) {
  auto p = ok(R"(model M
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = m*g*x "gravity";
  dissipation = 0.5*c*der(x)^2;
  force(q) = -d*der(q);
  force(th[i]) = u;
  constraint x^2 + y^2 = l^2;
  for i in 1:n loop
    kinetic = 0.5*m[i]*der(q[i])^2;
    force(q[i]) = f[i];
  end for;
end M;)");
  const auto& s = p->cls().mechanics;
  ASSERT_EQ(s.size(), 7u);
  EXPECT_EQ(s[0].kind, MechanicsKind::Kinetic);
  EXPECT_EQ(sexpr(s[0].value.get()), "(* (* 0.5 m) (^ (call der x) 2))");
  EXPECT_EQ(p->sm.slice(s[0].keywordRange), "kinetic");
  EXPECT_EQ(p->sm.slice(s[0].range), "kinetic = 0.5*m*der(x)^2");
  EXPECT_EQ(s[1].kind, MechanicsKind::Potential);
  EXPECT_EQ(s[2].kind, MechanicsKind::Dissipation);
  EXPECT_EQ(s[3].kind, MechanicsKind::Force);
  EXPECT_EQ(sexpr(s[3].target.get()), "q");
  EXPECT_EQ(sexpr(s[3].value.get()), "(neg (* d (call der q)))");
  EXPECT_EQ(sexpr(s[4].target.get()), "(index th i)");
  EXPECT_EQ(s[5].kind, MechanicsKind::Constraint);
  EXPECT_EQ(sexpr(s[5].value.get()), "(+ (^ x 2) (^ y 2))");
  EXPECT_EQ(sexpr(s[5].rhs.get()), "(^ l 2)");
  EXPECT_EQ(s[6].kind, MechanicsKind::For);
  EXPECT_EQ(s[6].iterators[0].name, "i");
  ASSERT_EQ(s[6].body.size(), 2u);
  EXPECT_EQ(s[6].body[1].kind, MechanicsKind::Force);
}

TEST(Parser, MechanicsWordsAreOrdinaryNamesElsewhere) {
  auto p = ok("model M\n  Real kinetic, force;\nequation\n  kinetic = force;\nend M;");
  EXPECT_EQ(p->cls().declarations[1].name, "force");
  EXPECT_EQ(sexpr(p->cls().equations[0].rhs.get()), "force");
}

TEST(Parser, AnnotationsGoToTheClass) {
  auto p = ok(R"(model M
  annotation(Documentation(info = "x"));
  Real x;
mechanics
  annotation(a = 1);
  kinetic = 1;
equation
  x = 1;
  annotation(experiment(StartTime = 0, StopTime = 10, Interval = 0.01, Tolerance = 1e-6));
end M;)");
  const auto& a = p->cls().annotations;
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a[0].mods[0].name, "Documentation");
  EXPECT_EQ(a[2].mods[0].name, "experiment");
  ASSERT_EQ(a[2].mods[0].nested.size(), 4u);
  EXPECT_EQ(a[2].mods[0].nested[1].name, "StopTime");
  EXPECT_EQ(sexpr(a[2].mods[0].nested[3].value.get()), "0.000001");
  EXPECT_EQ(p->where(a[2].range), "9:3");
}

TEST(Parser, RangesCoverStatements) {
  auto p = ok("model M\nequation\n  for i in 1:2 loop\n    x[i] = 0;\n  end for;\nend M;");
  const Equation& f = p->cls().equations[0];
  EXPECT_EQ(p->sm.slice(f.range), "for i in 1:2 loop\n    x[i] = 0;\n  end for");
}

TEST(Parser, EmptyStoredDefinitionFieldsOnFile) {
  auto p = ok("model A end A; model B end B;");
  EXPECT_EQ(p->def->file, p->file);
  EXPECT_TRUE(p->def->within.empty());
  EXPECT_EQ(p->cls(1).name, "B");
}

}  // namespace
}  // namespace qdot::testing
