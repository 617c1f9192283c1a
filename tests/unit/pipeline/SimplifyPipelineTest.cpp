// Simplification in the pipeline (--simplify): the textbook cases of issue 14 — the bead on a
// rotating hoop and the spherical pendulum written with Cartesian positions get the textbook
// equation (by length) and their first integrals — and, for every example, the simplified
// Euler–Lagrange rows are the same functions as the unsimplified ones (evaluated at random points).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>

#include "driver/Pipeline.h"

namespace qdot::test {
namespace {

using driver::Compilation;
using driver::Stage;

const char* kHoop = R"(model BeadOnHoop
  parameter Real m = 0.1;
  parameter Real R = 0.5;
  parameter Real Omega = 5;
  parameter Real g = 9.81;
  coordinate Real theta(start = 0.5);
  Real x = R*sin(theta)*cos(Omega*time);
  Real y = R*sin(theta)*sin(Omega*time);
  Real z = -R*cos(theta);
mechanics
  kinetic = 0.5*m*(der(x)^2 + der(y)^2 + der(z)^2);
  potential = m*g*z;
end BeadOnHoop;
)";

const char* kSpherical = R"(model SphericalPendulum
  parameter Real m = 1;
  parameter Real l = 1;
  parameter Real g = 9.81;
  coordinate Real theta(start = 0.8);
  coordinate Real phi(start = 0);
  Real x = l*sin(theta)*cos(phi);
  Real y = l*sin(theta)*sin(phi);
  Real z = -l*cos(theta);
mechanics
  kinetic = 0.5*m*(der(x)^2 + der(y)^2 + der(z)^2);
  potential = m*g*z;
end SphericalPendulum;
)";

std::vector<std::string> integralNames(const Compilation& c) {
  std::vector<std::string> names;
  for (const auto& fi : c.eom->integrals) names.push_back(fi.name);
  return names;
}

TEST(SimplifyPipeline, BeadOnHoopPrintsTheTextbookEquation) {
  Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "hoop.qd", kHoop, "", Stage::Derive));
  std::string row = sym::toString(c.ctx, c.eom->rows[0].residual);
  // m R² θ̈ − m R² Ω² sin θ cos θ + m g R sin θ = 0, spelled in qdot's syntax:
  std::string textbook = "m*R^2*der(der(theta)) - m*R^2*Omega^2*sin(theta)*cos(theta) + m*g*R*sin(theta)";
  EXPECT_LE(row.size(), 3 * textbook.size()) << row;
  EXPECT_EQ(row, "m*R*(R*der(der(theta)) - R*Omega^2*sin(theta)*cos(theta) + g*sin(theta))");
  // time cancels from L, so the Jacobi integral exists: p θ̇ − L = ½mR²θ̇² − ½mR²Ω² sin²θ − m g R cos θ
  ASSERT_EQ(integralNames(c), std::vector<std::string>{"jacobi"});
  EXPECT_EQ(sym::toString(c.ctx, c.eom->integrals[0].value),
            "m*R*(0.5*R*der(theta)^2 - 0.5*R*Omega^2*sin(theta)^2 - g*cos(theta))");

  Compilation none;
  none.options.simplify = sym::SimplifyLevel::None;
  ASSERT_TRUE(driver::compileSource(none, "hoop.qd", kHoop, "", Stage::Derive));
  EXPECT_GT(sym::toString(none.ctx, none.eom->rows[0].residual).size(), 5 * textbook.size());
  EXPECT_TRUE(integralNames(none).empty());
}

TEST(SimplifyPipeline, CartesianSphericalPendulumHasCyclicAzimuth) {
  Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "spherical.qd", kSpherical, "", Stage::Derive));
  ASSERT_EQ(integralNames(c), (std::vector<std::string>{"p(phi)", "jacobi"}));
  // p(φ) = m l² sin²θ φ̇
  EXPECT_EQ(sym::toString(c.ctx, c.eom->integrals[0].value), "m*l^2*der(phi)*sin(theta)^2");
}

// A value in [0.3, 1.3] for a symbol, from its name (so two compilations agree) and the seed.
double valueOf(const std::string& name, uint64_t seed) {
  uint64_t h = std::hash<std::string>{}(name) ^ (seed * 0x9e3779b97f4a7c15ull);
  h ^= h >> 29;
  h *= 0xbf58476d1ce4e5b9ull;
  h ^= h >> 32;
  return 0.3 + static_cast<double>(h % 100000) / 100000.0;
}

double evaluateByName(Compilation& c, sym::Expr e, uint64_t seed) {
  std::vector<double> values(c.ctx.symbolCount());
  for (sym::Expr s : c.ctx.freeSymbols(e)) values[s->symbolId] = valueOf(std::string(c.ctx.symbolName(s)), seed);
  return sym::evaluate(e, values);
}

TEST(SimplifyPipeline, EveryExampleKeepsItsEquations) {
  int rows = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(QDOT_SOURCE_DIR "/examples")) {
    if (entry.path().extension() != ".qd") continue;
    Compilation plain, fast;
    plain.options.simplify = sym::SimplifyLevel::None;
    if (!driver::compileFile(plain, entry.path().string(), "", Stage::Derive)) continue;
    ASSERT_TRUE(driver::compileFile(fast, entry.path().string(), "", Stage::Derive)) << entry.path();
    ASSERT_EQ(plain.eom->rows.size(), fast.eom->rows.size());
    EXPECT_GE(fast.eom->integrals.size(), plain.eom->integrals.size()) << entry.path();
    for (size_t r = 0; r < plain.eom->rows.size(); ++r) {
      for (uint64_t seed = 1; seed <= 3; ++seed) {
        double a = evaluateByName(plain, plain.eom->rows[r].residual, seed);
        double b = evaluateByName(fast, fast.eom->rows[r].residual, seed);
        if (!std::isfinite(a)) continue;  // the point is outside the model's domain (sqrt of < 0)
        EXPECT_NEAR(a, b, 1e-9 * (1 + std::abs(a))) << entry.path() << " row " << r << ": "
                                                     << sym::toString(fast.ctx, fast.eom->rows[r].residual);
      }
      ++rows;
    }
  }
  EXPECT_GT(rows, 50);
}

}  // namespace
}  // namespace qdot::test
