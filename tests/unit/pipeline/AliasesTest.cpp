// Alias equations between plain unknowns (`w = -v`, `h + v = 0`, `g = 2*c0`) from .qd text through
// the whole pipeline: they leave the DAE with fewer unknowns, every eliminated variable keeps its
// result column with its value and sign (checked against the closed form), and an alias equation
// that contradicts the others is a located error. The structural pass itself is tested in
// tests/unit/structural/AliasEliminationTest.cpp.
#include <algorithm>
#include <cmath>
#include <memory>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "CompiledModel.h"
#include "dae/Dae.h"
#include "driver/Backends.h"
#include "output/ResultSink.h"
#include "sim/RunOptions.h"
#include "sim/Simulation.h"

namespace qdot::test {
namespace {

struct Columns : rt::ResultSink {
  std::vector<std::string> names;
  std::vector<double> times;
  std::vector<std::vector<double>> rows;
  void begin(std::span<const std::string> columns) override { names.assign(columns.begin(), columns.end()); }
  void row(double t, std::span<const double> values) override {
    times.push_back(t);
    rows.emplace_back(values.begin(), values.end());
  }
  void finish() override {}
  // The largest |column(t) − f(t)| over the run (NaN if the column is missing).
  template <class F>
  double maxError(const std::string& column, F f) const {
    auto it = std::find(names.begin(), names.end(), column);
    if (it == names.end() || rows.empty()) return std::nan("");
    double worst = 0;
    for (size_t k = 0; k < rows.size(); ++k)
      worst = std::max(worst, std::fabs(rows[k][it - names.begin()] - f(times[k])));
    return worst;
  }
};

std::string rendered(driver::Compilation& c) {
  std::ostringstream os;
  c.diags.render(os, c.sources);
  return os.str();
}

// x' = w g, w = −v, v = x, g = 2 c0 = 1, h = −v: x = e^−t. Three of the five unknowns are aliases
// (w and h of v, g of the parameters); v = x stays an equation (x is a state).
constexpr const char* kAliases = R"(model Aliases
  parameter Real c0 = 0.5;
  Real x(start = 1, fixed = true);
  Real v;
  Real w(start = -1);
  Real g;
  Real h;
equation
  der(x) = w*g;
  w = -v;
  v = x;
  g = 2*c0;
  h + v = 0;
end Aliases;)";

TEST(AliasEquations, PlainAliasesLeaveTheDaeAndKeepTheirColumns) {
  CompiledModel m("aliases.qd", kAliases);
  ASSERT_TRUE(m.ok());
  std::vector<std::string> unknowns;
  for (const auto& v : m.dae().variables) unknowns.push_back(v.name);
  EXPECT_EQ(unknowns, (std::vector<std::string>{"x", "v"}));
  EXPECT_EQ(m.dae().equations.size(), 2u);
  std::vector<std::string> outputs;
  for (const auto& o : m.dae().outputs) outputs.push_back(o.name);
  for (const char* name : {"w", "g", "h"})
    EXPECT_NE(std::find(outputs.begin(), outputs.end(), name), outputs.end()) << name << " is not a result column";
  EXPECT_TRUE(m.compilation().diags.diagnostics().empty()) << rendered(m.compilation());  // w's start agrees
  // What `qdot equations --json` lists: two unknowns, v starting at 1 (w's start -1 through w = -v).
  std::ostringstream json;
  dae::printEquationsJson(json, m.dae(), m.compilation().ctx, m.compilation().sources);
  size_t names = 0;
  for (size_t at = json.str().find("\"name\""); at != std::string::npos; at = json.str().find("\"name\"", at + 1)) ++names;
  EXPECT_EQ(names, 3u) << json.str();  // x, v, the parameter c0 (no coordinates: no Jacobi integral)
  EXPECT_NE(json.str().find(R"({"name": "v", "kind": "algebraic", "role": "algebraic", "start": "1")"), std::string::npos)
      << json.str();
}

TEST(AliasEquations, EliminatedVariablesFollowTheClosedForm) {
  driver::Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "aliases.qd", kAliases, "", driver::Stage::Kernel)) << rendered(c);
  driver::RunnableModel m = driver::makeRunnableModel(c, driver::Backend::Bytecode, false);
  ASSERT_TRUE(m.model) << m.error;
  rt::SimulationSettings s;
  s.stop = 2;
  s.interval = 0.01;
  s.rtol = 1e-9;
  s.parameters = rt::evaluateParameters(*m.model, rt::parameterOverrides(*m.model, {}));
  Columns r;
  ASSERT_TRUE(rt::simulate(*m.model, s, r).success);
  auto decay = [](double t) { return std::exp(-t); };
  EXPECT_LT(r.maxError("x", decay), 1e-6);
  EXPECT_LT(r.maxError("v", decay), 1e-6);
  EXPECT_LT(r.maxError("w", [&](double t) { return -decay(t); }), 1e-6);
  EXPECT_LT(r.maxError("h", [&](double t) { return -decay(t); }), 1e-6);
  EXPECT_EQ(r.maxError("g", [](double) { return 1.0; }), 0.0);
}

// The one error of `text`: its code and line:col.
void expectOneError(const std::string& text, DiagCode code, unsigned line, unsigned col, const std::string& says) {
  driver::Compilation c;
  EXPECT_FALSE(driver::compileSource(c, "aliases.qd", text, "", driver::Stage::Dae));
  std::vector<const Diagnostic*> errors;
  for (const Diagnostic& d : c.diags.diagnostics())
    if (d.severity == Severity::Error) errors.push_back(&d);
  ASSERT_EQ(errors.size(), 1u) << rendered(c);
  EXPECT_EQ(errors[0]->code, code) << rendered(c);
  LineCol at = c.sources.lineCol(errors[0]->range.file, errors[0]->range.begin);
  EXPECT_EQ(at.line, line) << rendered(c);
  EXPECT_EQ(at.col, col) << rendered(c);
  EXPECT_NE(errors[0]->message.find(says), std::string::npos) << rendered(c);
}

TEST(AliasEquations, EqualAndOppositeIsALocatedError) {
  expectOneError("model M\n  Real a, b;\nequation\n  a = b;\n  b = -a;\nend M;", DiagCode::E0321, 5, 3,
                 "'a' and 'b' are made both equal and opposite");
}

TEST(AliasEquations, AVariableGivenTwoValuesIsALocatedError) {
  expectOneError("model M\n  parameter Real p = 1;\n  Real a, b;\nequation\n  a = -b;\n  b = p;\n  a = 3;\nend M;",
                 DiagCode::E0321, 7, 3, "'a' is given twice");
}

TEST(AliasEquations, StartValueThatDisagreesThroughTheSignIsReportedWhereItIsGiven) {
  driver::Compilation c;
  ASSERT_TRUE(driver::compileSource(c, "aliases.qd", R"(model M
  Real x(start = 1, fixed = true);
  Real a(start = 1), b(start = 1);
equation
  der(x) = a;
  a = x;
  b = -a;
end M;)", "", driver::Stage::Dae)) << rendered(c);
  ASSERT_EQ(c.diags.diagnostics().size(), 1u) << rendered(c);
  const Diagnostic& d = c.diags.diagnostics().front();
  EXPECT_EQ(d.code, DiagCode::W0302);
  LineCol at = c.sources.lineCol(d.range.file, d.range.begin);
  EXPECT_EQ(at.line, 3u);
  EXPECT_EQ(at.col, 22u);
  EXPECT_EQ(d.message,
            "the start value 1 of 'b' is not used: through alias equations it is the negative of 'a', which starts at 1");
}

TEST(AliasEquations, StatesAndDerivativesAreNotAliases) {
  // x = -y with der(y) in the model: y is a state, and only aliases between two unknowns that are
  // not states are eliminated, so the equation stays.
  CompiledModel m("aliases.qd", R"(model M
  Real x, y(start = 1, fixed = true);
equation
  der(y) = -y;
  x = -y;
end M;)");
  ASSERT_TRUE(m.ok());
  EXPECT_EQ(m.dae().variables.size(), 2u);
  EXPECT_EQ(m.dae().equations.size(), 2u);
}

}  // namespace
}  // namespace qdot::test
