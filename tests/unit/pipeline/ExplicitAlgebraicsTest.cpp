// Explicit algebraic unknowns solved out of the DAE (dae/ExplicitAlgebraics.h), as `qdot run`
// compiles. The reduced system is checked against the system as derived, numerically: at a random
// point of the states and their rates, with the solved unknowns given the values of their outputs,
// the derived system's defining rows vanish and its other rows equal the reduced rows, in order.
// (The trajectories are compared with closed forms in tests/sim: VibrationLibrarySimTest,
// FluidLibrarySimTest, OptionsSimTest.)
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <set>

#include "driver/Pipeline.h"
#include "symbolic/Expr.h"

namespace qdot::driver {
namespace {

struct Compiled {
  std::unique_ptr<Compilation> c = std::make_unique<Compilation>();
  const dae::Dae& dae() const { return *c->dae; }
};

Compiled compile(const std::string& text, bool eliminate, std::vector<std::string> integers = {}) {
  Compiled r;
  r.c->options.eliminateAlgebraics = eliminate;
  EXPECT_TRUE(compileSource(*r.c, "explicit.qd", text, "", Stage::Check));
  EXPECT_EQ(takeStructuralParameters(*r.c, integers), "");
  EXPECT_TRUE(continueTo(*r.c, Stage::Dae));
  return r;
}

std::set<std::string> algebraicNames(const dae::Dae& d) {
  std::set<std::string> names;
  for (const auto& v : d.variables)
    if (v.kind == dae::VarKind::Algebraic) names.insert(v.name);
  return names;
}

// Symbol values by id for one Compilation: parameters at their defaults, the rest from `named`.
std::vector<double> valuesOf(const Compilation& c, const std::map<std::string, double>& named) {
  std::vector<double> values(c.ctx.symbolCount(), 0.0);
  for (const auto& p : c.dae->parameters) values[p.symbol->symbolId] = sym::evaluate(p.value, values);
  for (const auto& [name, value] : named)
    if (sym::Expr s = c.ctx.findSymbol(name)) values[s->symbolId] = value;
  return values;
}

// The check described at the top of the file, at one random point.
void expectSameSystem(const std::string& text, std::vector<std::string> integers = {}) {
  Compiled derived = compile(text, false, integers), reduced = compile(text, true, integers);
  const dae::Dae &full = derived.dae(), &small = reduced.dae();
  ASSERT_LT(small.variables.size(), full.variables.size()) << "nothing was solved out";
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::map<std::string, double> point;
  for (const auto& v : small.variables) {
    point[v.name] = uniform(random);
    if (v.yp) point[std::string(reduced.c->ctx.symbolName(v.yp))] = uniform(random);
  }
  std::vector<double> at = valuesOf(*reduced.c, point);
  for (const auto& o : small.outputs) point[o.name] = sym::evaluate(o.value, at);  // the solved unknowns among them
  std::vector<double> atFull = valuesOf(*derived.c, point);

  size_t row = 0, vanished = 0;
  for (const auto& eq : full.equations) {
    double f = sym::evaluate(eq.residual, atFull);
    double r = row < small.equations.size() ? sym::evaluate(small.equations[row].residual, at) : NAN;
    if (std::fabs(f - r) <= 1e-9 * (1 + std::fabs(f))) {
      ++row;
    } else {
      EXPECT_NEAR(f, 0, 1e-9) << "a derived row that is neither a reduced row nor a defining row";
      ++vanished;
    }
  }
  EXPECT_EQ(row, small.equations.size());
  EXPECT_EQ(vanished, full.variables.size() - small.variables.size());
}

const char* kComponentChain = R"(
model ComponentChain "masses and spring-dampers from the library, the first tied to a wall"
  import Vibration.*;
  parameter Integer n = 3;
  Fixed wall;
  SpringDamper links[n](k = {100*i for i in 1:n}, c = fill(0.5, n));
  Mass ms[n](m = {1 + i for i in 1:n}, s(start = {0.01*i for i in 1:n}));
equation
  connect(wall.a, links[1].a);
  for i in 1:n loop
    connect(links[i].b, ms[i].a);
  end for;
  for i in 2:n loop
    connect(ms[i - 1].b, links[i].a);
  end for;
end ComponentChain;
)";

TEST(ExplicitAlgebraics, TheFlowsOfAComponentChainLeaveTheSystemAsOutputs) {
  Compiled derived = compile(kComponentChain, false), reduced = compile(kComponentChain, true);
  EXPECT_EQ(algebraicNames(derived.dae()).size(), 6u);  // wall.a.f, links[i].b.f, ms[1..2].b.f
  EXPECT_TRUE(algebraicNames(reduced.dae()).empty());
  EXPECT_EQ(reduced.dae().variables.size(), 6u);  // the Lagrangian chain's states
  EXPECT_EQ(reduced.dae().equations.size(), 6u);
  std::vector<std::string> outputs;
  for (const auto& o : reduced.dae().outputs) outputs.push_back(o.name);
  // first the solved unknowns in their order, then the outputs the derived system had
  ASSERT_GE(outputs.size(), 6u);
  EXPECT_EQ(std::vector<std::string>(outputs.begin(), outputs.begin() + 6),
            (std::vector<std::string>{"wall.a.f", "links[1].b.f", "links[2].b.f", "links[3].b.f", "ms[1].b.f",
                                      "ms[2].b.f"}));
  expectSameSystem(kComponentChain);
  expectSameSystem(kComponentChain, {"n=7"});
}

TEST(ExplicitAlgebraics, ADefinitionOverAnotherIsSolvedWhateverTheOrder) {
  const char* text = R"(
model Definitions
  coordinate Real x(start = 1);
  Real a "defined by b";
  Real b "defined by x";
  Real e "energy";
mechanics
  kinetic = 0.5*der(x)^2;
  potential = 0.5*4*x^2;
equation
  a = 2*b + sin(x);
  3*b = x^2 - der(x);
  e + a = 0.5*der(x)^2 + 2*x^2 + a;
end Definitions;
)";
  Compiled reduced = compile(text, true);
  EXPECT_TRUE(algebraicNames(reduced.dae()).empty());
  for (const auto& o : reduced.dae().outputs)  // every value is over the states only
    for (sym::Expr s : reduced.c->ctx.freeSymbols(o.value)) {
      std::string name(reduced.c->ctx.symbolName(s));
      EXPECT_TRUE(name == "x" || name == "der(x)") << o.name << " contains " << name;
    }
  expectSameSystem(text);
}

TEST(ExplicitAlgebraics, NonlinearFixedAndLoopedUnknownsStay) {
  const char* text = R"(
model Stays
  coordinate Real x(start = 1);
  Real r(start = 1) "in its only row squared";
  Real z(start = 2, fixed = true) "its start is an initial condition";
  Real p "a nonlinear loop with q";
  Real q;
  Real w "solved out";
mechanics
  kinetic = 0.5*der(x)^2;
  potential = 0.5*x^2;
equation
  r^2 = 1 + x^2;
  z = 2 + 0*x + time;
  p = sin(q) + x;
  q = p^3 - 1;
  w = 3*x;
end Stays;
)";
  Compiled reduced = compile(text, true);
  // p is solved out (p = sin(q) + x); q is then in q = (sin(q) + x)^3 - 1, not affine: it stays
  EXPECT_EQ(algebraicNames(reduced.dae()), (std::set<std::string>{"r", "z", "q"}));
  expectSameSystem(text);
}

TEST(ExplicitAlgebraics, OnlyWhatRunCompiles) {
  // `qdot equations`, modes and linearize see the system as derived
  Compiled derived = compile(kComponentChain, false);
  EXPECT_EQ(derived.dae().variables.size(), 12u);
}

}  // namespace
}  // namespace qdot::driver
