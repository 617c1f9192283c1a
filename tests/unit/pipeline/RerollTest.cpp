// dae::rerollRows (dae/Reroll.h): runs of scalar rows that are one row shifted along the unknowns
// and parameters become template blocks. Reference: the same DAE not rerolled — its kernels give
// the same residual and Jacobian, row by row and entry by entry (rows are matched by their origin,
// since rerolling moves them), at random states, with default and with given parameter values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>
#include <map>
#include <sstream>
#include <string>

#include "dae/Reroll.h"
#include "kernel/Kernel.h"
#include "unit/pipeline/KernelPair.h"

namespace qdot {
namespace {

// The chain of spring-dampers and masses from arrays of library components (as
// tests/sim/models/chain_components.qd), n masses.
std::string componentChain(int n) {
  return "model C\n  import Vibration.*;\n  parameter Integer n = " + std::to_string(n) +
         ";\n  Fixed wall;\n"
         "  SpringDamper links[n](k = {1000 + 10*i for i in 1:n}, c = fill(0.5, n));\n"
         "  Mass ms[n](m = {1 + 0.01*i for i in 1:n}, s(start = {0.01*i for i in 1:n}));\n"
         "equation\n  connect(wall.a, links[1].a);\n"
         "  for i in 1:n loop\n    connect(links[i].b, ms[i].a);\n  end for;\n"
         "  for i in 2:n loop\n    connect(ms[i - 1].b, links[i].a);\n  end for;\nend C;\n";
}

// The model's DAE as `qdot run` has it before rerolling: expanded to scalars, the explicit
// algebraic unknowns (the link forces) solved out.
struct ScalarDae {
  driver::Compilation c;
  bool ok = false;
  explicit ScalarDae(const std::string& text) {
    c.options.eliminateAlgebraics = true;
    ok = driver::compileSource(c, "model.qd", text, driver::Stage::Dae);
  }
};

// What identifies a row whichever its position: its origin.
std::string rowKey(const dae::Equation& e) {
  std::ostringstream os;
  os << static_cast<int>(e.origin.kind) << ':' << e.origin.variable << ':' << e.origin.range.file << '@' << e.origin.range.begin << ':'
     << e.origin.element;
  return os.str();
}

struct Evaluated {
  std::map<std::string, double> F;                  // by row
  std::map<std::pair<std::string, int>, double> J;  // by (row, column)
  std::vector<double> outputs;                      // in their order (the result columns')
};

Evaluated evaluated(const dae::Dae& d, const kernel::KernelModule& k, int trial, const test::GivenParameters& given = {}) {
  test::KernelValues v = test::evaluateAt(k, trial, given);
  Evaluated out;
  out.outputs = v.outputs;
  for (size_t r = 0; r < d.equations.size(); ++r) out.F[rowKey(d.equations[r])] = v.F[r];
  const auto& starts = k.description->jacobianColumnStarts;
  const auto& rows = k.description->jacobianRowIndices;
  for (size_t col = 0; col + 1 < starts.size(); ++col)
    for (int32_t at = starts[col]; at < starts[col + 1]; ++at)
      out.J[{rowKey(d.equations[rows[at]]), static_cast<int>(col)}] = v.J[at];
  return out;
}

void expectSameOutputs(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(b[i], a[i], 1e-12 * (1 + std::fabs(a[i]))) << "output " << i;
}

void expectSame(const Evaluated& a, const Evaluated& b) {
  expectSameOutputs(a.outputs, b.outputs);
  ASSERT_EQ(a.F.size(), b.F.size());
  for (const auto& [row, value] : a.F) EXPECT_NEAR(b.F.at(row), value, 1e-12 * (1 + std::fabs(value))) << row;
  ASSERT_EQ(a.J.size(), b.J.size()) << "the same Jacobian pattern";
  for (const auto& [entry, value] : a.J) {
    auto at = b.J.find(entry);
    ASSERT_NE(at, b.J.end()) << entry.first << ", column " << entry.second;
    EXPECT_NEAR(at->second, value, 1e-12 * (1 + std::fabs(value))) << entry.first << ", column " << entry.second;
  }
}

// The residual's values and each Jacobian column's values, each sorted: rows in any order.
void expectSameUpToRowOrder(const kernel::KernelModule& a, const kernel::KernelModule& b, int trial) {
  test::KernelValues x = test::evaluateAt(a, trial), y = test::evaluateAt(b, trial);
  auto sorted = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v;
  };
  auto near = [](const std::vector<double>& u, const std::vector<double>& v) {
    ASSERT_EQ(u.size(), v.size());
    for (size_t i = 0; i < u.size(); ++i) EXPECT_NEAR(v[i], u[i], 1e-12 * (1 + std::fabs(u[i])));
  };
  expectSameOutputs(x.outputs, y.outputs);
  near(sorted(x.F), sorted(y.F));
  const auto &sa = a.description->jacobianColumnStarts, &sb = b.description->jacobianColumnStarts;
  ASSERT_EQ(sa, sb) << "the same number of entries in each column";
  for (size_t col = 0; col + 1 < sa.size(); ++col)
    near(sorted({x.J.begin() + sa[col], x.J.begin() + sa[col + 1]}), sorted({y.J.begin() + sb[col], y.J.begin() + sb[col + 1]}));
}

TEST(RerollRows, AChainOfComponentArraysLoopsWithTheScalarKernelsValues) {
  const int n = 40;
  ScalarDae model(componentChain(n));
  ASSERT_TRUE(model.ok);
  dae::Dae scalar = *model.c.dae;
  dae::Dae rerolled = *model.c.dae;
  dae::RerollResult r = dae::rerollRows(rerolled, model.c.ctx);
  // The masses' rows but the first (the wall's link) and the last (no link after it), and the
  // kinematic rows: two loops.
  EXPECT_EQ(r.blocks, 2u);
  EXPECT_EQ(r.rows, static_cast<size_t>((n - 2) + n));
  // The flows the DAE solved out, result columns: links[i].b.f (the link's law), their negatives
  // ms[i].a.f, the other ends ms[i-1].b.f and links[i].a.f, each run but its first element.
  EXPECT_EQ(r.outputBlocks, 4u);
  EXPECT_GE(r.outputs, static_cast<size_t>(4 * (n - 2)));
  for (const dae::OutputBlock& o : rerolled.outputBlocks)
    for (int i = o.first; i < o.first + o.count; ++i) EXPECT_EQ(rerolled.outputs[i].value, nullptr);
  ASSERT_EQ(rerolled.templateBlocks.size(), r.blocks);
  for (const dae::TemplateBlock& b : rerolled.templateBlocks)
    for (int row = b.firstRow; row < b.firstRow + static_cast<int>(flat::pointCount(b.region)); ++row)
      EXPECT_EQ(rerolled.equations[row].residual, nullptr) << "a block's rows are its template's";

  DiagnosticEngine diags;
  kernel::KernelModule a = kernel::buildKernels(scalar, model.c.ctx, diags);
  kernel::KernelModule b = kernel::buildKernels(rerolled, model.c.ctx, diags);
  ASSERT_FALSE(diags.hasErrors());
  EXPECT_EQ(test::loopCount(a.program(ModelProgram::Residual)), 0u);
  EXPECT_EQ(test::loopCount(b.program(ModelProgram::Residual)), 2u);
  EXPECT_EQ(test::loopCount(b.program(ModelProgram::Outputs)), 4u);
  EXPECT_EQ(a.description->outputNames, b.description->outputNames) << "the same columns, in the same order";
  EXPECT_LT(b.program(ModelProgram::Residual).code.size(), a.program(ModelProgram::Residual).code.size() / 5);
  EXPECT_EQ(a.description->parameterNames.size(), b.description->parameterNames.size());
  for (int trial = 0; trial < 3; ++trial) expectSame(evaluated(scalar, a, trial), evaluated(rerolled, b, trial));
  // The links' parameters were interleaved (k, c, s0 of each link) and are now one array each;
  // values given by name still reach the same parameters.
  test::GivenParameters given{{"links[7].k", 2500}, {"links[40].c", 3}, {"ms[13].m", 7}, {"links[2].s0", 0.25}};
  expectSame(evaluated(scalar, a, 5, given), evaluated(rerolled, b, 5, given));
}

TEST(RerollRows, ShortRunsStayRows) {
  ScalarDae model(componentChain(12));  // runs of 10 and 12 rows: under the 16 a loop needs
  ASSERT_TRUE(model.ok);
  dae::Dae d = *model.c.dae;
  EXPECT_EQ(dae::rerollRows(d, model.c.ctx).blocks, 0u);
  EXPECT_FALSE(d.templated());
  EXPECT_EQ(dae::rerollRows(d, model.c.ctx, 8).blocks, 2u) << "a lower minimum takes them";
}

// Every row of x reads one common unknown (the frame position y): in the loop it is a column of its
// own in each row (kernel::TemplateEntry::fixed), the same pattern and values as the scalar rows.
TEST(RerollRows, RowsReadingOneCommonUnknownLoopWithItsColumn) {
  driver::Compilation c;
  c.options.eliminateAlgebraics = true;
  ASSERT_TRUE(driver::compileSource(c, "m.qd",
                                    "model M\n  parameter Integer n = 30;\n  coordinate Real x[n](start = {0.01*i for i in 1:n});\n"
                                    "  coordinate Real y(start = 0.1);\nmechanics\n"
                                    "  kinetic = sum(0.5*der(x[i])^2 for i in 1:n) + 0.5*der(y)^2;\n"
                                    "  potential = sum(0.5*(x[i] - y)^2 + 0.1*(x[i] - y)^4 for i in 1:n) + 0.5*y^2;\n"
                                    "  dissipation = sum(0.05*(der(x[i]) - der(y))^2 for i in 1:n);\nend M;\n",
                                    driver::Stage::Dae));
  dae::Dae scalar = *c.dae, rerolled = *c.dae;
  dae::RerollResult r = dae::rerollRows(rerolled, c.ctx);
  EXPECT_EQ(r.blocks, 2u) << "the rows of x, and the kinematic rows";
  EXPECT_EQ(r.rows, 30u + 31u) << "y, the unknown after x[30], has a kinematic row like theirs";
  DiagnosticEngine diags;
  kernel::KernelModule a = kernel::buildKernels(scalar, c.ctx, diags);
  kernel::KernelModule b = kernel::buildKernels(rerolled, c.ctx, diags);
  ASSERT_FALSE(diags.hasErrors());
  for (int trial = 0; trial < 3; ++trial) expectSame(evaluated(scalar, a, trial), evaluated(rerolled, b, trial));
}

// `qdot run`'s pipeline: a chain of components of 40 masses is rerolled, and says so.
TEST(RerollRows, QdotRunRerollsAndReportsIt) {
  test::CompiledKernels looped(componentChain(40), true, true);
  ASSERT_TRUE(looped.ok) << looped.diagnostics();
  EXPECT_EQ(looped.c.rerolled.blocks, 0u) << "off unless asked for (tests keep the scalar path)";
  driver::Compilation c;
  c.options.keepLoops = c.options.rerollRows = c.options.eliminateAlgebraics = true;
  ASSERT_TRUE(driver::compileSource(c, "model.qd", componentChain(40), driver::Stage::Kernel));
  EXPECT_EQ(c.rerolled.blocks, 2u);
  EXPECT_EQ(test::loopCount(c.kernels->program(ModelProgram::Residual)), 2u);
}

}  // namespace
}  // namespace qdot

namespace qdot {
namespace {

// Every example and simulation-test model, compiled as `qdot run` compiles it, with rerolling at
// runs of two rows or outputs (so that small models reroll too): where some were rerolled, the
// kernels give the values of the same model compiled without rerolling, row by row, entry by
// entry, output by output.
TEST(RerollRows, EveryModelRerolledEvenByTwoRowsKeepsItsValues) {
  namespace fs = std::filesystem;
  std::vector<fs::path> files;
  for (const char* dir : {"examples", "tests/sim/models"})
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(QDOT_SOURCE_DIR) / dir))
      if (entry.path().extension() == ".qd") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  size_t rerolled = 0;
  for (const fs::path& file : files) {
    auto compile = [&](driver::Compilation& c, bool reroll) {
      c.options.keepLoops = c.options.eliminateAlgebraics = true;
      c.options.rerollRows = reroll;
      c.options.rerollMinimumRun = 2;
      return driver::compileFile(c, file.string(), "", driver::Stage::Kernel);
    };
    driver::Compilation plain, looped;
    if (!compile(plain, false)) continue;  // (models that are meant to fail)
    ASSERT_TRUE(compile(looped, true)) << file;
    if (looped.rerolled.blocks == 0 && looped.rerolled.outputBlocks == 0) continue;
    ++rerolled;
    SCOPED_TRACE(file.string());
    std::set<std::string> keys;
    for (const auto& e : plain.dae->equations) keys.insert(rowKey(e));
    for (int trial = 0; trial < 2; ++trial)
      if (keys.size() == plain.dae->equations.size())
        expectSame(evaluated(*plain.dae, *plain.kernels, trial), evaluated(*looped.dae, *looped.kernels, trial));
      else  // rows an origin does not tell apart (a body's vector equations): the same values per column
        expectSameUpToRowOrder(*plain.kernels, *looped.kernels, trial);
  }
  EXPECT_GE(rerolled, 10u) << "models whose rows were rerolled and compared";
}

}  // namespace
}  // namespace qdot

namespace qdot {
namespace {

// Three equal oscillators (rows that repeat, by two) with an initial equation that is not a start
// value: its row at t0 is planned over every row's residual, so the rows stay rows. (Found by the
// pipeline fuzzer: rerolled rows have no residual of their own.)
TEST(RerollRows, AModelWithInitialEquationsKeepsItsRows) {
  driver::Compilation c;
  c.options.keepLoops = c.options.eliminateAlgebraics = c.options.rerollRows = true;
  c.options.rerollMinimumRun = 2;
  ASSERT_TRUE(driver::compileSource(c, "init.qd",
                                    "model Init\n  coordinate Real x(start = 1, fixed = true);\n  coordinate Real y;\n"
                                    "  coordinate Real z(start = 0.5, fixed = false);\nmechanics\n"
                                    "  kinetic = 0.5*der(x)^2 + 0.5*der(y)^2 + 0.5*der(z)^2;\n"
                                    "  potential = 0.5*x^2 + 0.5*y^2 + 0.5*z^2;\ninitial equation\n  der(der(z)) = 0.25;\nend Init;\n",
                                    driver::Stage::Kernel));
  EXPECT_EQ(c.rerolled.blocks, 0u);
  EXPECT_FALSE(c.dae->templated());
}

}  // namespace
}  // namespace qdot
