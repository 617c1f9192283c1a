// Arrays of components with some results asked for (issue 15, docs/loops.md "Arrays of
// components"): the parts' energies summed over their connections (flat::sumConnectedEnergies)
// and the terms that repeat along the arrays made sums (flat::rerollTerms). Checked against
// hand-written rows of the same chain (m_i s_i'' + k_i (s_i − s_{i−1}) − k_{i+1} (s_{i+1} − s_i) = 0),
// and by what stays as it was where a flow is needed.
#include <cmath>
#include <string>

#include "CompiledModel.h"

namespace qdot::test {
namespace {

// Parts of its own (no library): a wall, masses and springs in arrays, connected in loops; the
// parameters differ from part to part.
constexpr const char* kParts = R"(
connector Flange
  Real s;
  flow Real f;
end Flange;
model Mass
  parameter Real m = 1;
  coordinate Real s;
  Flange a, b;
mechanics
  kinetic = 0.5*m*der(s)^2;
equation
  a.s = s;
  b.s = s;
end Mass;
model Spring
  parameter Real k = 100, s0 = 0;
  Flange a, b;
mechanics
  potential = 0.5*k*(b.s - a.s - s0)^2;
end Spring;
model Wall
  Flange a;
equation
  a.s = 0;
end Wall;
model Chain
  parameter Integer n = 12;
  Wall wall;
  Spring links[n](k = {100 + 10*i for i in 1:n});
  Mass ms[n](m = {1 + 0.1*i for i in 1:n});
equation
  connect(wall.a, links[1].a);
  for i in 1:n loop
    connect(links[i].b, ms[i].a);
  end for;
  for i in 2:n loop
    connect(ms[i - 1].b, links[i].a);
  end for;
end Chain;
)";

struct PartsRun {
  driver::Compilation c;
  bool ok = false;
  PartsRun(std::string text, std::vector<std::string> results, driver::Stage until, size_t minimumRun = 1000) {
    c.options.keepLoops = true;
    c.options.results = std::move(results);
    c.options.rerollMinimumRun = minimumRun;
    ok = driver::compileSource(c, "chain.qd", std::move(text), "Chain", until);
    std::ostringstream diag;
    c.diags.render(diag, c.sources);
    EXPECT_TRUE(ok) << diag.str();
  }
};

std::string at(const char* name, int i, const char* member) { return std::string(name) + "[" + std::to_string(i) + "]." + member; }

// Summed, not rerolled: one row per mass, no other unknown, each row the chain's.
TEST(SummedEnergies, EachMassRowIsTheChainsRow) {
  PartsRun run(kParts, {"ms[1].s"}, driver::Stage::Dae);
  ASSERT_TRUE(run.ok);
  const dae::Dae& d = *run.c.dae;
  EXPECT_EQ(run.c.loops, std::optional<std::string>("it has arrays of components (links[1], …), which are expanded"));
  EXPECT_EQ(d.variables.size(), 24u);  // 12 positions, 12 velocities: no flow, no potential of a flange
  for (const auto& v : d.variables) EXPECT_EQ(v.kind, dae::VarKind::State) << v.name;
  std::vector<double> values(run.c.ctx.symbolCount(), std::nan(""));
  auto set = [&](const std::string& name, double v) {
    sym::Expr s = run.c.ctx.findSymbol(name);
    ASSERT_NE(s, nullptr) << name;
    values[s->symbolId] = v;
  };
  const int n = 12;
  std::vector<double> s(n + 2, 0), a(n + 1, 0), k(n + 2, 0), m(n + 1, 0);
  for (int i = 1; i <= n; ++i) {
    s[i] = 0.01 * i + 0.003 * std::sin(7.0 * i), a[i] = std::cos(3.0 * i), k[i] = 100 + 10 * i, m[i] = 1 + 0.1 * i;
    set(at("ms", i, "s"), s[i]), set("der(der(" + at("ms", i, "s") + "))", a[i]);
    set("der(" + at("ms", i, "s") + ")", 0.1 * i);
    set(at("links", i, "k"), k[i]), set(at("links", i, "s0"), 0), set(at("ms", i, "m"), m[i]);
  }
  ASSERT_EQ(d.rowCoordinates.size(), 12u);
  for (size_t r = 0; r < d.rowCoordinates.size(); ++r) {
    int i = std::stoi(d.rowCoordinates[r].substr(3));
    double right = i < n ? k[i + 1] * (s[i + 1] - s[i]) : 0.0;
    double expected = m[i] * a[i] + k[i] * (s[i] - s[i - 1]) - right;
    EXPECT_TRUE(closeRelative(sym::evaluate(d.equations[r].residual, values), expected, 1 + std::fabs(expected)))
        << d.rowCoordinates[r];
  }
}

// Rerolled: the masses' kinetic terms and the links' potential terms from the second on are one sum
// each; the first link (to the wall) stays a term; the links' stiffnesses are consecutive variables.
TEST(SummedEnergies, RepeatedTermsBecomeSumsOverTheParts) {
  PartsRun run(kParts, {"ms[1].s"}, driver::Stage::Flatten, 4);
  ASSERT_TRUE(run.ok);
  const flat::FlatModel& m = *run.c.flat;
  ASSERT_EQ(m.indexedSums.size(), 2u);
  EXPECT_EQ(m.indexedSums[0].energy, flat::IndexedSum::Energy::Kinetic);
  EXPECT_EQ(m.indexedSums[0].box, (flat::Box{{1, 12}}));
  EXPECT_EQ(m.indexedSums[1].energy, flat::IndexedSum::Energy::Potential);
  EXPECT_EQ(m.indexedSums[1].box, (flat::Box{{2, 12}}));
  EXPECT_EQ(sym::toString(run.c.ctx, m.indexedSums[1].body), "0.5*links.k[%1]*(-links.s0[%1] - ms.s[%1-1] + ms.s[%1])^2");
  ASSERT_EQ(m.potential.size(), 2u);  // links[1]'s own term, and the one holding the sum
  int first = m.variableOf(run.c.ctx.findSymbol("links[1].k"));
  for (int i = 2; i <= 12; ++i) EXPECT_EQ(m.variableOf(run.c.ctx.findSymbol(at("links", i, "k"))), first + i - 1);
  for (const auto& v : m.variables) EXPECT_EQ(v.alias, nullptr) << v.name;
  EXPECT_EQ(run.c.loops, std::optional<std::string>(""));
}

// A flow among the results: the parts keep their rows and the flows stay unknowns.
TEST(SummedEnergies, AFlowAskedForKeepsTheParts) {
  PartsRun run(kParts, {"ms[1].s", "links[3].b.f"}, driver::Stage::Dae);
  ASSERT_TRUE(run.ok);
  EXPECT_NE(run.c.loops->find("the flow 'links[3].b.f' is among the results asked for"), std::string::npos) << *run.c.loops;
  ASSERT_TRUE(run.c.flat);
  EXPECT_TRUE(run.c.flat->indexedSums.empty());
  EXPECT_LT(run.c.dae->stateCount(), run.c.dae->variables.size());  // flows among the unknowns
}

// A result that is no variable but one letter from a flow (a typo): the parts stay as they are, so
// that the run's error can suggest the flow; a name far from every variable does not stop the sum.
TEST(SummedEnergies, AMisspeltFlowKeepsTheParts) {
  PartsRun misspelt(kParts, {"ms[1].s", "links[3].b.ff"}, driver::Stage::Flatten, 4);
  ASSERT_TRUE(misspelt.ok);
  EXPECT_NE(misspelt.c.loops->find("'links[3].b.ff', asked for, is not a result of the model"), std::string::npos)
      << *misspelt.c.loops;
  EXPECT_FALSE(misspelt.c.componentsSummed);
  EXPECT_TRUE(misspelt.c.flat->indexedSums.empty());
  EXPECT_GE(misspelt.c.flat->variableOf(misspelt.c.ctx.findSymbol("links[3].b.f")), 0);  // the flow is still there
  PartsRun far(kParts, {"ms[1].s", "jacobi"}, driver::Stage::Flatten, 4);
  ASSERT_TRUE(far.ok);
  EXPECT_TRUE(far.c.componentsSummed);
  EXPECT_EQ(far.c.flat->indexedSums.size(), 2u);
}

// A part whose equations read its flows (a spring written as equations): nothing is summed.
TEST(SummedEnergies, APartWithEquationsOverItsFlowsKeepsTheParts) {
  std::string text = kParts;
  text.replace(text.find("mechanics\n  potential = 0.5*k*(b.s - a.s - s0)^2;"),
               std::string("mechanics\n  potential = 0.5*k*(b.s - a.s - s0)^2;").size(),
               "equation\n  b.f = -k*(b.s - a.s - s0);\n  a.f = -b.f;");
  PartsRun run(text, {"ms[1].s"}, driver::Stage::Dae);
  ASSERT_TRUE(run.ok);
  EXPECT_NE(run.c.loops->find("which are expanded: it has equations"), std::string::npos) << *run.c.loops;
}

}  // namespace
}  // namespace qdot::test
