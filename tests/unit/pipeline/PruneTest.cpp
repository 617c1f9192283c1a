// --outputs: the DAE keeps only what the requested results need (dae/Prune.h). Checked on the
// structure the kernels then get: which unknowns and equations remain, and that what remains is
// the requested subsystem whole (its trajectories are compared in tests/sim/OptionsSimTest.cpp).
#include <gtest/gtest.h>

#include <algorithm>

#include "driver/Pipeline.h"

namespace qdot::driver {
namespace {

const char* kTwoSubsystems = R"(
model TwoSubsystems "a pendulum and an unrelated oscillator"
  parameter Real g = 9.81, l = 1, k = 100, m = 1;
  coordinate Real th(start = 0.5);
  coordinate Real x(start = 0.1);
  Real E;
  output Real height = -l*cos(th);
mechanics
  kinetic = 0.5*m*l^2*der(th)^2 + 0.5*m*der(x)^2;
  potential = -m*g*l*cos(th) + 0.5*k*x^2;
equation
  E = 0.5*m*der(x)^2 + 0.5*k*x^2;
end TwoSubsystems;
)";

std::vector<std::string> keptNames(const std::string& text, std::vector<std::string> results,
                                   dae::PruneReport* report = nullptr, Stage until = Stage::Kernel) {
  Compilation c;
  c.options.results = std::move(results);
  EXPECT_TRUE(compileSource(c, "prune.qd", text, "", until));
  std::vector<std::string> names;
  for (const auto& v : c.dae->variables) names.push_back(v.name);
  for (const auto& o : c.dae->outputs) names.push_back("output " + o.name);
  if (report) *report = c.pruned;
  return names;
}

using Names = std::vector<std::string>;

TEST(Prune, AnUncoupledSubsystemIsLeftOut) {
  dae::PruneReport r;
  EXPECT_EQ(keptNames(kTwoSubsystems, {"x"}, &r), (Names{"x", "der(x)"}));
  EXPECT_EQ(r.variablesBefore, 5u);
  EXPECT_EQ(r.equationsKept, 2u);
}

TEST(Prune, AnAlgebraicResultNeedsWhatItsEquationContains) {
  EXPECT_EQ(keptNames(kTwoSubsystems, {"E"}), (Names{"x", "der(x)", "E"}));
}

TEST(Prune, AnOutputNeedsTheVariablesOfItsExpression) {
  EXPECT_EQ(keptNames(kTwoSubsystems, {"height"}), (Names{"th", "der(th)", "output height"}));
}

TEST(Prune, AVelocityNamedByItsColumnKeepsItsCoordinate) {
  EXPECT_EQ(keptNames(kTwoSubsystems, {"der(th)"}), (Names{"th", "der(th)"}));
}

// (To the DAE only: the kernels take initial equations over parameters alone until the
// initialization system of the structural issue; the DAE already holds this one.)
TEST(Prune, AnInitialEquationTiesTheSubsystemsItJoins) {
  std::string text = kTwoSubsystems;
  text.replace(text.find("end TwoSubsystems;"), 0, "initial equation\n  x = 0.2*th;\n");
  text.replace(text.find("coordinate Real x(start = 0.1)"), 30, "coordinate Real x(fixed = false)");
  Names kept = keptNames(text, {"x"}, nullptr, Stage::Dae);
  EXPECT_NE(std::find(kept.begin(), kept.end(), "th"), kept.end()) << "x's start comes from th's";
}

TEST(Prune, CoupledComponentsAreKeptTogether) {
  const char* chain = R"(
import Vibration.*;
model Chain
  Fixed wall;
  Spring k1(k = 100), k2(k = 100);
  Mass m1(s(start = 0.1)), m2;
  Mass lonely(s(start = 1));
  Spring k3;
  Fixed other;
equation
  connect(wall.a, k1.a); connect(k1.b, m1.a); connect(m1.b, k2.a); connect(k2.b, m2.a);
  connect(other.a, k3.a); connect(k3.b, lonely.a);
end Chain;
)";
  Names kept = keptNames(chain, {"m2.s"});
  for (const char* name : {"m1.s", "m2.s", "der(m1.s)", "der(m2.s)"})
    EXPECT_NE(std::find(kept.begin(), kept.end(), name), kept.end()) << name;
  for (const auto& name : kept) EXPECT_EQ(name.find("lonely"), std::string::npos) << name;
  for (const auto& name : kept) EXPECT_EQ(name.find("k3"), std::string::npos) << name;
}

TEST(Prune, AnUnknownNameLeavesTheModelWhole) {
  dae::PruneReport r;
  EXPECT_EQ(keptNames(kTwoSubsystems, {"x", "nope"}, &r).size(), 6u);  // 5 unknowns and the output
  EXPECT_EQ(r.unknownNames, (Names{"nope"}));
}

}  // namespace
}  // namespace qdot::driver
