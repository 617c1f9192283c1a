// Repeated structure kept as templates (flatten/IndexedSums.cpp, issue 15): a sum kept as an
// IndexedSum and expanded again must give exactly the energy terms the scalar lowering gives (the
// same hash-consed nodes), and only sums whose bodies index arrays by iterator + constant are kept.
#include <gtest/gtest.h>

#include "unit/common/SourceDae.h"
#include <algorithm>
#include <cmath>

#include "flatten/Flatten.h"
#include "mechanics/EulerLagrange.h"
#include "mechanics/TemplateRows.h"

namespace qdot {
namespace {

struct Flattened {
  std::optional<flat::FlatModel> scalar, templated;
};

// Both flattenings of one checked model, in one Context (so equal terms are the same node).
Flattened flattenBoth(test::SourceDae& s) {
  Flattened f;
  f.scalar = flat::flatten(*s.compilation.checked, s.ctx, s.diags, {});
  flat::FlattenLimits keep;
  keep.keepLoops = true;
  f.templated = flat::flatten(*s.compilation.checked, s.ctx, s.diags, keep);
  return f;
}

void expectSameTerms(const std::vector<flat::Term>& a, const std::vector<flat::Term>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].value, b[i].value) << what << " term " << i;
}

// Expands the templates and checks the model is the scalar one: energies node for node, variables
// in the same order.
void expectExpandsToScalar(test::SourceDae& s, Flattened& f) {
  ASSERT_TRUE(f.scalar && f.templated);
  flat::expandIndexedSums(*f.templated, s.ctx);
  expectSameTerms(f.scalar->kinetic, f.templated->kinetic, "kinetic");
  expectSameTerms(f.scalar->potential, f.templated->potential, "potential");
  expectSameTerms(f.scalar->dissipation, f.templated->dissipation, "dissipation");
  ASSERT_EQ(f.scalar->forces.size(), f.templated->forces.size());
  for (size_t i = 0; i < f.scalar->forces.size(); ++i) {
    EXPECT_EQ(f.scalar->forces[i].first, f.templated->forces[i].first) << "force " << i;
    EXPECT_EQ(f.scalar->forces[i].second.value, f.templated->forces[i].second.value) << "force " << i;
  }
  ASSERT_EQ(f.scalar->variables.size(), f.templated->variables.size());
  for (size_t i = 0; i < f.scalar->variables.size(); ++i)
    EXPECT_EQ(f.scalar->variables[i].symbol, f.templated->variables[i].symbol) << "variable " << i;
}

constexpr const char* kChain = R"(model Chain
  parameter Integer n = 6;
  parameter Real m = 1, k = 1000, c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  dissipation = 0.5*c*der(x[1])^2 + sum(0.5*c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1);
end Chain;
)";

TEST(IndexedSum, ChainKeepsEverySumAndExpandsToTheScalarTerms) {
  test::SourceDae s("chain.qd", kChain, driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.templated);
  ASSERT_EQ(f.templated->indexedSums.size(), 3u);
  EXPECT_EQ(f.templated->indexedSums[1].box, (std::vector<std::pair<long, long>>{{1, 5}}));
  // x and der(x): the arrays the relative symbols index
  ASSERT_EQ(f.templated->patterns->arrays.size(), 2u);
  EXPECT_EQ(f.templated->patterns->arrays[1].name, "der(x)");
  sym::Expr next = s.ctx.findSymbol("x[%1+1]");
  ASSERT_NE(next, nullptr);
  const flat::RelativeElement* rel = f.templated->relativeElement(next);
  ASSERT_NE(rel, nullptr);
  EXPECT_EQ(rel->dims[0].iterator, 0);
  EXPECT_EQ(rel->dims[0].offset, 1);
  expectExpandsToScalar(s, f);
}

// Forces in `for` loops (IndexedForce): one template per force statement of a loop whose body is
// only forces on x[i + o] (nested loops too); expanded, the forces the scalar lowering gives, node
// for node and in the same places among the other forces. A force on a constant element keeps its
// loop scalar; the iterator as a number (`0.01*i`) is the template's %1.
TEST(IndexedForce, ForceLoopsAreTemplatesAndExpandToTheScalarForces) {
  test::SourceDae s("forces.qd", R"(model Forces
  parameter Integer n = 6, m = 3;
  parameter Real k = 1000, c = 0.5, a[n] = {0.1*i for i in 1:n};
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z[n, m](each start = 0.1);
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n) + sum(0.5*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1) + sum(k*z[i, j]^2 for i in 1:n, j in 1:m);
  force(x[2]) = -1;
  for i in 2:n loop
    force(x[i]) = -c*der(x[i]) + a[i]*sin(time);
    force(x[i-1]) = c*(der(x[i]) - der(x[i-1]));
  end for;
  force(x[n]) = 2;
  for i in 1:n loop
    for j in 1:m loop
      force(z[i, j]) = -c*der(z[i, j]) + x[i];
    end for;
  end for;
  for i in 1:n loop
    force(x[1]) = 0.01*i;
  end for;
  for i in 1:n loop
    force(x[i]) = 0.01*i;
  end for;
end Forces;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.templated);
  ASSERT_EQ(f.templated->indexedForces.size(), 4u);  // the loop of two, the nested loop, the last loop
  EXPECT_EQ(f.templated->indexedForces[0].box, (flat::Box{{2, 6}}));
  EXPECT_EQ(f.templated->indexedForces[0].position, 1u);  // after force(x[2])
  EXPECT_EQ(f.templated->indexedForces[2].box, (flat::Box{{1, 6}, {1, 3}}));
  EXPECT_EQ(f.templated->forces.size(), 2u + 6u);  // the scalar ones, and the loop kept scalar
  expectExpandsToScalar(s, f);
}

TEST(IndexedSum, GridOfMassesKeepsTwoIterators) {
  test::SourceDae s("grid.qd", R"(model Grid
  parameter Integer n = 4, m = 3;
  parameter Real k = 10, mass[n, m] = fill(2, n, m);
  coordinate Real z[n, m](each start = 0.1);
mechanics
  kinetic = sum(0.5*mass[i, j]*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k*(z[i, j+1] - z[i, j])^2 for i in 1:n, j in 1:m-1)
            + sum(0.5*k*z[1, j]^2 for j in 1:m) - sum(-0.5*k*z[n, j]^2 for j in 1:m);
end Grid;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.templated);
  EXPECT_EQ(f.templated->indexedSums.size(), 5u);
  EXPECT_NE(s.ctx.findSymbol("z[%1,%2+1]"), nullptr);
  EXPECT_NE(s.ctx.findSymbol("z[1,%1]"), nullptr);
  expectExpandsToScalar(s, f);
}

TEST(IndexedSum, BodiesThatAreNotAffineInTheIteratorStayScalar) {
  test::SourceDae s("other.qd", R"(model Other
  parameter Integer n = 4;
  coordinate Real x[2*n];
mechanics
  kinetic = sum(0.5*der(x[2*i])^2 + 0.5*der(x[2*i-1])^2 for i in 1:n);
  potential = sum(x[n + 1 - i]^2 for i in 1:n) + sum(x[j]^2 for j in {1, 3, 5}) + sum(if j > 2 then x[j]^4 else 0 for j in 1:2*n);
end Other;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.templated);
  EXPECT_TRUE(f.templated->indexedSums.empty());
  expectExpandsToScalar(s, f);
}

// An iterator used as a number (`i*x[i]^2`, `(1 + 0.1*i)*…`, `sin(0.1*i)`) is the symbol %1 of the
// template; expanded, the terms of the scalar lowering to rounding (its constants may fold in
// another order: (i + 1)²·exp(−i/n)/(2i) differs in the last bit at i = 5), which is why the
// pipeline flattens such a model again when the templates do not apply (PipelineFallback below).
TEST(IndexedSum, IteratorsAsNumbersStayTemplatesAndExpandToTheScalarTermsToRounding) {
  test::SourceDae s("numbers.qd", R"(model Numbers
  parameter Integer n = 7;
  parameter Real k = 10, w = 2;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = sum(0.5*(1 + 0.01*i)*der(x[i])^2 for i in 1:n);
  potential = sum(i*x[i]^2 for i in 1:n) + sum(0.5*k*(1 + 0.1*sin(w*i))*(x[i+1] - x[i])^2 for i in 1:n-1)
            + sum((i + 1)^2*exp(-i/n)*x[i]^4/(2*i) for i in 2:n);
  for i in 1:n loop
    force(x[i]) = 0.3*i*sin(time) - 0.1*i*der(x[i]);
  end for;
end Numbers;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.scalar && f.templated);
  EXPECT_EQ(f.templated->indexedSums.size(), 4u);
  EXPECT_EQ(f.templated->indexedForces.size(), 1u);
  EXPECT_TRUE(f.templated->patterns->readsIterator(s.ctx, f.templated->indexedSums[0].body));
  flat::expandIndexedSums(*f.templated, s.ctx);
  std::vector<double> values(s.ctx.symbolCount());
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.3 + 0.7 * std::sin(1.0 + 1.7 * static_cast<double>(i));
  auto same = [&](sym::Expr a, sym::Expr b, const std::string& what) {
    double va = sym::evaluate(a, values), vb = sym::evaluate(b, values);
    EXPECT_NEAR(vb, va, 1e-14 * (1 + std::abs(va))) << what;
  };
  for (size_t t = 0; t < f.scalar->kinetic.size(); ++t) same(f.scalar->kinetic[t].value, f.templated->kinetic[t].value, "kinetic");
  for (size_t t = 0; t < f.scalar->potential.size(); ++t) same(f.scalar->potential[t].value, f.templated->potential[t].value, "potential");
  ASSERT_EQ(f.scalar->forces.size(), f.templated->forces.size());
  for (size_t i = 0; i < f.scalar->forces.size(); ++i) {
    EXPECT_EQ(f.scalar->forces[i].first, f.templated->forces[i].first);
    same(f.scalar->forces[i].second.value, f.templated->forces[i].second.value, "force " + std::to_string(i));
  }
}

}  // namespace
}  // namespace qdot

namespace qdot {
namespace {

// Coordinates that occur outside the templates (scalar energy terms, forces): their rows are peeled.
std::vector<char> peeledCoordinates(const flat::FlatModel& m, sym::Context& ctx) {
  std::vector<char> peeled(m.variables.size(), 0);
  auto mark = [&](sym::Expr e) {
    for (sym::Expr s : ctx.freeSymbols(e)) {
      int var = m.variableOf(s);
      if (var < 0) continue;
      if (m.variables[var].role == flat::VarRole::Velocity) var = m.variables[var].derivativeOf;
      peeled[var] = 1;
    }
  };
  for (const auto* terms : {&m.kinetic, &m.potential, &m.dissipation})
    for (const auto& t : *terms) mark(t.value);
  for (const auto& f : m.forces) peeled[f.first] = 1;
  return peeled;
}

// Each template row, instantiated at every point of its region, equals the scalar derivation's row
// of that element (evaluated at the same random values of every symbol: both are polynomials or
// smooth functions of them, so equal values at random points are equal rows for all practical
// purposes; a wrong offset or sign changes the value). Returns the rows for further checks.
std::vector<mech::TemplateRow> expectRowsMatchScalarDerivation(const char* name, const char* text) {
  test::SourceDae s(name, text, driver::Stage::Check);
  Flattened f = flattenBoth(s);
  EXPECT_TRUE(f.scalar && f.templated);
  if (!f.scalar || !f.templated) return {};
  auto eom = mech::deriveEquationsOfMotion(*f.scalar, s.ctx, s.diags);
  EXPECT_TRUE(eom);
  if (!eom) return {};
  mech::TemplateDerivation t =
      mech::deriveTemplateRows(*f.templated, s.ctx, peeledCoordinates(*f.templated, s.ctx), sym::SimplifyLevel::Fast);
  EXPECT_TRUE(t.scalarSums.empty());
  std::vector<double> values(s.ctx.symbolCount() + 1000);
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.3 + 0.7 * std::sin(1.0 + 1.7 * static_cast<double>(i));
  for (const mech::TemplateRow& row : t.rows) {
    const flat::ArrayVariable& a = f.templated->patterns->arrays[row.array];
    flat::forEachPoint(row.region, [&](std::span<const long> point, size_t) {
      sym::Expr coordinate = a.elements[static_cast<size_t>(flat::linearIndex(a.shape, point))];
      const mech::CoordinateRow* scalar = nullptr;
      for (const auto& r : eom->rows)
        if (f.scalar->variables[r.coordinate].symbol == coordinate) scalar = &r;
      EXPECT_NE(scalar, nullptr);
      if (scalar) {
        values.resize(std::max(values.size(), s.ctx.symbolCount()), 0.5);
        sym::Expr instance = flat::instantiate(*f.templated, s.ctx, row.residual, point);
        values.resize(std::max(values.size(), s.ctx.symbolCount()), 0.5);
        double expected = sym::evaluate(scalar->residual, values), got = sym::evaluate(instance, values);
        EXPECT_NEAR(got, expected, 1e-12 * (1 + std::abs(expected))) << s.ctx.symbolName(coordinate);
      }
    });
  }
  // The whole derivation with templates: template rows where the regions are, the scalar rows of
  // the peeled elements (with the templates' contributions instantiated), each equal to the scalar one.
  auto templated = mech::deriveEquationsOfMotion(*f.templated, s.ctx, s.diags);
  EXPECT_TRUE(templated);
  if (!templated) return t.rows;
  EXPECT_EQ(templated->rows.size(), eom->rows.size());
  EXPECT_EQ(templated->templateRows.size(), t.rows.size());
  size_t viaTemplates = 0;
  for (size_t r = 0; r < std::min(templated->rows.size(), eom->rows.size()); ++r) {
    const auto& row = templated->rows[r];
    EXPECT_EQ(f.templated->variables[row.coordinate].symbol, f.scalar->variables[eom->rows[r].coordinate].symbol);
    sym::Expr value = row.residual;
    if (row.templateRow >= 0) {
      ++viaTemplates;
      const mech::TemplateRow& tr = templated->templateRows[row.templateRow];
      const flat::ArrayVariable& a = f.templated->patterns->arrays[tr.array];
      size_t k = std::find(a.elements.begin(), a.elements.end(), f.templated->variables[row.coordinate].symbol) - a.elements.begin();
      std::vector<long> point(a.shape.size());
      for (size_t d = a.shape.size(); d-- > 0;) point[d] = static_cast<long>(k % a.shape[d]) + 1, k /= a.shape[d];
      value = flat::instantiate(*f.templated, s.ctx, tr.residual, point);
    }
    values.resize(std::max(values.size(), s.ctx.symbolCount()), 0.5);
    double expected = sym::evaluate(eom->rows[r].residual, values), got = sym::evaluate(value, values);
    EXPECT_NEAR(got, expected, 1e-12 * (1 + std::abs(expected))) << "row " << r;
  }
  EXPECT_GT(viaTemplates, 0u);
  return t.rows;
}

// An output defined by sums (`output Real E = sum(…) + …`): its sums are kept as templates
// (Output::sums) and its value holds the other summands; expanded, it is the scalar lowering's
// value node for node. The output read by another definition is expanded where that one is made.
constexpr const char* kChainWithEnergyOutputs = R"(model Chain
  parameter Integer n = 6;
  parameter Real m = 1, k = 1000, c = 0.5;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  output Real E = sum(0.5*m*der(x[i])^2 for i in 1:n) + 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  output Real P = -sum(c*(der(x[i+1]) - der(x[i]))^2 for i in 1:n-1) - c*der(x[1])^2;
mechanics
  kinetic = sum(0.5*m*der(x[i])^2 for i in 1:n);
  potential = 0.5*k*x[1]^2 + sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
end Chain;
)";

void expectSameOutputs(const flat::FlatModel& scalar, const flat::FlatModel& expanded) {
  ASSERT_EQ(scalar.outputs.size(), expanded.outputs.size());
  for (size_t o = 0; o < scalar.outputs.size(); ++o) {
    EXPECT_EQ(scalar.outputs[o].name, expanded.outputs[o].name);
    EXPECT_EQ(scalar.outputs[o].value, expanded.outputs[o].value) << scalar.outputs[o].name;
    EXPECT_TRUE(expanded.outputs[o].sums.empty());
  }
}

TEST(IndexedSum, OutputSumsStayTemplatesAndExpandToTheScalarValue) {
  test::SourceDae s("outputs.qd", kChainWithEnergyOutputs, driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.scalar && f.templated);
  ASSERT_EQ(f.templated->outputs.size(), 2u);
  const flat::Output& E = f.templated->outputs[0];
  EXPECT_EQ(E.name, "E");
  ASSERT_EQ(E.sums.size(), 2u);
  EXPECT_EQ(E.sums[0].box, (flat::Box{{1, 6}}));
  EXPECT_EQ(E.sums[1].box, (flat::Box{{1, 5}}));
  EXPECT_TRUE(E.sums[0].shape.empty());  // the pipeline gives it (shapeOutputSums)
  EXPECT_EQ(sym::toString(s.ctx, E.value), "0.5*k*x[1]^2");
  EXPECT_EQ(f.templated->outputs[1].sums.size(), 1u);
  flat::expandIndexedSums(*f.templated, s.ctx);
  expectSameOutputs(*f.scalar, *f.templated);
}

TEST(IndexedSum, AnOutputReadElsewhereIsExpandedAsTheScalarLoweringDoes) {
  for (const char* other : {"  output Real twice = 2*E;\n", "  Real half = E/2;\n  output Real h = half;\n"}) {
    std::string text = kChainWithEnergyOutputs;
    std::string before = text, after = text;
    size_t e = text.find("  output Real E"), p = text.find("  output Real P");
    after.insert(p, other);    // declared after E: E is kept first, then expanded by the use
    before.insert(e, other);   // declared before E: resolved through the use first
    for (const std::string& t : {after, before}) {
      test::SourceDae s("used.qd", t, driver::Stage::Check);
      Flattened f = flattenBoth(s);
      ASSERT_TRUE(f.scalar && f.templated);
      size_t at = 0;
      while (at < f.templated->outputs.size() && f.templated->outputs[at].name != "E") ++at;
      ASSERT_LT(at, f.templated->outputs.size());
      EXPECT_TRUE(f.templated->outputs[at].sums.empty()) << other;
      flat::expandIndexedSums(*f.templated, s.ctx);
      expectSameOutputs(*f.scalar, *f.templated);
    }
  }
}

// `text` flattened with templates (FlattenLimits::keepLoops), which must fail: its diagnostics.
std::string diagnosticsFlatteningWithTemplates(const std::string& text) {
  test::SourceDae s("bad.qd", text, driver::Stage::Check);
  flat::FlattenLimits keep;
  keep.keepLoops = true;
  EXPECT_FALSE(flat::flatten(*s.compilation.checked, s.ctx, s.diags, keep));
  std::ostringstream rendered;
  s.diags.render(rendered, s.sources);
  return rendered.str();
}

TEST(IndexedSum, AnOutputSumReadingItselfIsTheUsualCycleError) {
  std::string text = kChainWithEnergyOutputs;
  text.replace(text.find("- c*der(x[1])^2;"), 16, "- c*der(x[1])^2 + P;");
  std::string out = diagnosticsFlatteningWithTemplates(text);
  EXPECT_NE(out.find("error[E0312]: the definition of 'P' depends on itself"), std::string::npos) << out;
}

// `kinetic = T` with `Real T = sum(…)`: the definition's binding is the statement's (definitions are
// substituted), so its sums are kept; expanded, node for node the scalar terms (no factor).
TEST(IndexedSum, EnergiesThroughDefinitionsKeepTheirSums) {
  test::SourceDae s("defs.qd", R"(model Defs
  parameter Integer n = 6;
  parameter Real m = 1, k = 1000;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real T = sum(0.5*m*der(x[i])^2 for i in 1:n);
  Real springs = sum(0.5*k*(x[i+1] - x[i])^2 for i in 1:n-1);
  Real V = 0.5*k*x[1]^2 + springs;
mechanics
  kinetic = T;
  potential = V;
end Defs;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.templated);
  EXPECT_EQ(f.templated->indexedSums.size(), 2u);  // T's, and springs' through V
  EXPECT_FALSE(f.templated->templatesRound);
  expectExpandsToScalar(s, f);
}

// Factors over sums (`0.5*m*sum(…)`, `k*(x[1]^2 + sum(…))/2`): kept, each body times its factors;
// expanded, equal to the scalar terms to rounding (FlatModel::templatesRound says so). A product of
// two sums is not linear in either: one scalar term.
TEST(IndexedSum, FactorsOverSumsAreTheBodiesFactors) {
  test::SourceDae s("factors.qd", R"(model Factors
  parameter Integer n = 6;
  parameter Real m = 1, k = 1000, e = 0.001;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
mechanics
  kinetic = 0.5*m*sum(der(x[i])^2 for i in 1:n);
  potential = k*(x[1]^2 + sum((x[i+1] - x[i])^2 for i in 1:n-1))/2 - sum(x[i] for i in 1:n)*e*sum(x[i] for i in 1:n);
end Factors;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.scalar && f.templated);
  EXPECT_EQ(f.templated->indexedSums.size(), 2u);
  EXPECT_TRUE(f.templated->templatesRound);
  flat::expandIndexedSums(*f.templated, s.ctx);
  std::vector<double> values(s.ctx.symbolCount());
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.3 + 0.7 * std::sin(1.0 + 1.7 * static_cast<double>(i));
  for (auto [a, b] : {std::pair{&f.scalar->kinetic, &f.templated->kinetic}, {&f.scalar->potential, &f.templated->potential}}) {
    ASSERT_EQ(a->size(), b->size());
    for (size_t t = 0; t < a->size(); ++t) {
      double va = sym::evaluate((*a)[t].value, values), vb = sym::evaluate((*b)[t].value, values);
      EXPECT_NEAR(vb, va, 1e-13 * (1 + std::abs(va)));
    }
  }
}

// Flattened with templates, `text` fails with exactly one error `code`.
void expectReportedOnce(const std::string& text, const std::string& code) {
  std::string out = diagnosticsFlatteningWithTemplates(text);
  size_t first = out.find("error[" + code + "]");
  EXPECT_NE(first, std::string::npos) << out;
  EXPECT_EQ(out.find("error[" + code + "]", first + 1), std::string::npos) << "reported twice:\n" << out;
}

// A definition that only a statement inlines is not resolved on its own (its sums would be
// expanded for nothing), but its errors are reported once, there; one nothing uses is resolved
// at the end, and its errors reported as before. The same for an array definition a sum reads
// element by element.
TEST(IndexedSum, InlinedAndUnusedDefinitionsReportTheirErrorsOnce) {
  for (bool used : {true, false}) {
    expectReportedOnce(R"(model Bad
  parameter Integer n = 6;
  parameter Real m = 1;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  Real T = sum(0.5*m*der(x[i])^2 for i in 1:n) + x[n+1];
mechanics
  kinetic = )" + std::string(used ? "T" : "sum(0.5*m*der(x[i])^2 for i in 1:n)") + R"(;
end Bad;
)", "E0301");
    expectReportedOnce(R"(model Bad
  parameter Integer n = 6;
  parameter Real m = 1, l = 1;
  coordinate Real th[n](start = {0.01*i for i in 1:n});
  Real px[n] = {l*sin(th[i + 1]) for i in 1:n};
mechanics
  kinetic = )" + std::string(used ? "sum(0.5*m*der(px[i])^2 for i in 1:n)" : "sum(0.5*m*der(th[i])^2 for i in 1:n)") + R"(;
end Bad;
)", "E0301");
  }
}

TEST(TemplateRows, ChainInteriorIsOneTemplateAndEqualsTheScalarRows) {
  std::string chain = kChain;
  auto rows = expectRowsMatchScalarDerivation("chain.qd", chain.c_str());
  ASSERT_EQ(rows.size(), 1u);  // x[1] and x[n] peeled (the wall spring, the free end)
  EXPECT_EQ(rows[0].region, (std::vector<std::pair<long, long>>{{2, 5}}));
}

// The equations of motion of both flattenings.
std::pair<std::optional<mech::EquationsOfMotion>, std::optional<mech::EquationsOfMotion>> deriveBoth(test::SourceDae& s,
                                                                                                      Flattened& f) {
  return {mech::deriveEquationsOfMotion(*f.scalar, s.ctx, s.diags), mech::deriveEquationsOfMotion(*f.templated, s.ctx, s.diags)};
}

// First integrals with templates. Reference: the scalar derivation of the same model. The free end
// x[n] of the undamped chain is in no scalar term but in the springs' sum: not cyclic (its momentum
// changes whenever the last spring is stretched), which the templated derivation once missed; the
// free particle z is cyclic in both. The Jacobi integral of a natural system is T + V: with
// templates its scalar part plus its sums (one per energy sum) at every point, evaluated at random
// values of every symbol, equals T + V of the scalar model.
TEST(TemplateRows, FirstIntegralsAreThoseOfTheScalarDerivationWithTheJacobiIntegralAsSums) {
  test::SourceDae s("undamped.qd", R"(model Undamped
  parameter Integer n = 6;
  parameter Real m[n] = {1 + 0.1*i for i in 1:n};
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z(start = 0);
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n) + 0.5*der(z)^2 + 0.25*der(z)*der(x[3]);
  potential = 0.5*100*x[1]^2 + sum(0.5*100*(x[i+1] - x[i])^2 + 3*x[i]^4 for i in 1:n-1);
end Undamped;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.scalar && f.templated);
  auto [scalar, templated] = deriveBoth(s, f);
  ASSERT_TRUE(scalar && templated);
  ASSERT_FALSE(templated->templateRows.empty());
  auto names = [](const mech::EquationsOfMotion& e) {
    std::vector<std::string> out;
    for (const auto& i : e.integrals) out.push_back(i.name);
    return out;
  };
  EXPECT_EQ(names(*scalar), (std::vector<std::string>{"p(z)", "jacobi"}));  // p(z) = ż + ẋ₃/4
  ASSERT_EQ(names(*templated), names(*scalar));
  const mech::FirstIntegral& h = templated->integrals.back();
  EXPECT_EQ(h.sums.size(), 2u);  // the kinetic sum and the potential sum
  std::vector<sym::Expr> terms{h.value};
  for (const flat::IndexedTerm& sum : h.sums)
    flat::forEachPoint(sum.box, [&](std::span<const long> p, size_t) { terms.push_back(flat::instantiate(*f.templated, s.ctx, sum.body, p)); });
  sym::Expr total = s.ctx.add(terms);
  std::vector<double> values(s.ctx.symbolCount());
  for (size_t i = 0; i < values.size(); ++i) values[i] = 0.3 + 0.7 * std::sin(1.0 + 1.7 * static_cast<double>(i));
  double energy = sym::evaluate(s.ctx.add(scalar->kinetic, scalar->potential), values);
  EXPECT_NEAR(sym::evaluate(scalar->integrals.back().value, values), energy, 1e-12 * std::abs(energy));
  EXPECT_NEAR(sym::evaluate(total, values), energy, 1e-12 * std::abs(energy));
  EXPECT_NEAR(sym::evaluate(templated->integrals[0].value, values), sym::evaluate(scalar->integrals[0].value, values), 1e-14);
}

// The cyclic coordinate of a chain with a free particle: its momentum with templates as without.
TEST(TemplateRows, CyclicMomentaAreThoseOfTheScalarDerivation) {
  test::SourceDae s("free.qd", R"(model Free
  parameter Integer n = 6;
  coordinate Real x[n](start = {0.01*i for i in 1:n});
  coordinate Real z(start = 0);
mechanics
  kinetic = sum(0.5*der(x[i])^2 for i in 1:n) + 0.5*der(z)^2;
  potential = 0.5*100*x[1]^2 + sum(0.5*100*(x[i+1] - x[i])^2 for i in 1:n-1);
end Free;
)", driver::Stage::Check);
  Flattened f = flattenBoth(s);
  ASSERT_TRUE(f.scalar && f.templated);
  auto [scalar, templated] = deriveBoth(s, f);
  ASSERT_TRUE(scalar && templated);
  std::vector<std::string> names;
  for (const auto& i : templated->integrals) names.push_back(i.name);
  EXPECT_EQ(names, (std::vector<std::string>{"p(z)", "jacobi"}));
  EXPECT_EQ(scalar->integrals.size(), 2u);
  EXPECT_EQ(templated->integrals[0].value, scalar->integrals[0].value);
}

TEST(TemplateRows, GridOfMassesHasItsInteriorAndEdgesAsTemplates) {
  auto rows = expectRowsMatchScalarDerivation("grid.qd", R"(model Grid
  parameter Integer n = 6, m = 5;
  parameter Real k = 10, c = 0.1, mass[n, m] = fill(2, n, m);
  coordinate Real z[n, m](each start = 0.1);
mechanics
  kinetic = sum(0.5*mass[i, j]*der(z[i, j])^2 for i in 1:n, j in 1:m);
  potential = sum(0.5*k*(z[i+1, j] - z[i, j])^2 for i in 1:n-1, j in 1:m)
            + sum(0.5*k*(z[i, j+1] - z[i, j])^2 + 0.1*k*z[i, j]^4 for i in 1:n, j in 1:m-1);
  dissipation = sum(0.5*c*(der(z[i+1, j]) - der(z[i, j]))^2 for i in 1:n-1, j in 1:m);
end Grid;
)");
  // dimension 1 splits into {1}, 2..5, {6}; dimension 2 into {1}, 2..4, {5}: the 9 regions less the
  // 4 corners (one element each)
  EXPECT_EQ(rows.size(), 5u);
}

}  // namespace
}  // namespace qdot
