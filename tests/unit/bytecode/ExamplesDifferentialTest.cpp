// Differential tests over every example model (examples/**/*.qd): the VM running the emitted
// bytecode against direct evaluation of the DAE's expressions (sym::evaluate) on random inputs —
// parameters, start values, residual, outputs, invariants — and the VM's symbolic Jacobian
// against central finite differences of the VM's residual, including that its pattern covers
// every nonzero.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <random>

#include "SourceModel.h"

namespace qdot::test {
namespace {

// The VM against sym::evaluate: a result agrees within kMaxUlps ulps, or, where it is a
// difference of larger terms (ulps of the result then mean nothing), within kMaxMagnitudeUlps
// units of eps times the magnitude of its terms (Magnitudes). The kernel reorders sums because CSE
// re-canonicalises a sum over temporaries, so some difference is expected; the values measured
// are printed ("[ ulps ]" lines).
constexpr uint64_t kMaxUlps = 4;
constexpr double kMaxMagnitudeUlps = 4;  // measured: at most 1.75
constexpr double kEps = std::numeric_limits<double>::epsilon();

std::vector<std::string> exampleFiles() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(std::string(QDOT_SOURCE_DIR) + "/examples"))
    if (e.path().extension() == ".qd") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

struct UlpStats {
  uint64_t maxUlps = 0, compared = 0, beyond = 0;
  double maxMagnitudeUlps = 0;
  void check(double vm, double ref, double magnitude, const std::string& what) {
    ++compared;
    uint64_t ulps = ulpDistance(vm, ref);
    maxUlps = std::max(maxUlps, ulps);
    double relative = std::fabs(vm - ref) / (kEps * std::max(magnitude, 1e-300));
    maxMagnitudeUlps = std::max(maxMagnitudeUlps, relative);
    if (ulps <= kMaxUlps) return;
    ++beyond;
    EXPECT_LE(relative, kMaxMagnitudeUlps) << what << ": vm " << vm << " vs " << ref << " (" << ulps
                                           << " ulps, magnitude of the terms " << magnitude << ")";
  }
};

class ExamplesTest : public ::testing::TestWithParam<std::string> {
 protected:
  std::mt19937_64 rng{12345};
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
};

// Parameter defaults evaluated directly, repeating until every binding has seen its dependencies.
std::vector<double> referenceParameters(const SourceModel& m) {
  const auto& ps = m.dae->parameters;
  std::vector<double> v(m.ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN()), p(ps.size());
  for (size_t round = 0; round <= ps.size(); ++round)
    for (size_t k = 0; k < ps.size(); ++k) v[ps[k].symbol->symbolId] = p[k] = sym::evaluate(ps[k].value, v);
  return p;
}

TEST_P(ExamplesTest, ParametersAndStartValuesMatchDirectEvaluation) {
  SourceModel m(GetParam(), readFile(GetParam()));
  ASSERT_TRUE(m.ok());
  size_t n = m.model->nVariables;
  std::vector<double> p(m.model->nParameters), y0(n), yp0(n), nominal(n);
  ASSERT_EQ(m.model->parameters(m.model, nullptr, nullptr, p.data()), 0) << m.model->lastError(m.model);
  std::vector<double> ref = referenceParameters(m);
  for (size_t k = 0; k < p.size(); ++k) EXPECT_EQ(ulpDistance(p[k], ref[k]), 0u) << m.dae->parameters[k].name;
  ASSERT_EQ(m.model->initialValues(m.model, p.data(), 0.0, y0.data(), yp0.data(), nominal.data()), 0);
  std::vector<double> v = m.symbolValues(0, y0, yp0, p);
  for (size_t j = 0; j < n; ++j) {
    const auto& var = m.dae->variables[j];
    double expected = var.declaration.start ? sym::evaluate(var.declaration.start, v) : 0.0;
    bool setByInitialEquation = false;
    for (const auto& e : m.dae->initialEquations) setByInitialEquation |= e.lhs == var.y;
    if (!setByInitialEquation) {
      EXPECT_EQ(ulpDistance(y0[j], expected), 0u) << var.name;
    }
    EXPECT_EQ(yp0[j], 0.0);
  }
}

TEST_P(ExamplesTest, ResidualOutputsInvariantsMatchDirectEvaluation) {
  SourceModel m(GetParam(), readFile(GetParam()));
  ASSERT_TRUE(m.ok());
  size_t n = m.model->nVariables, rows = m.model->nResiduals, nOut = m.model->nOutputs;
  std::vector<sym::Expr> roots;  // residuals, outputs, invariants: the order the VM fills `all`
  for (const auto& e : m.dae->equations) roots.push_back(e.residual);
  for (const auto& o : m.dae->outputs) roots.push_back(o.value);
  for (const auto& i : m.dae->invariants) roots.push_back(i.value);
  Magnitudes magnitudes(roots);
  std::vector<double> p0(m.model->nParameters), p(p0.size()), y(n), yp(n), all(roots.size()), F(rows);
  ASSERT_EQ(m.model->parameters(m.model, nullptr, nullptr, p0.data()), 0);
  UlpStats stats;
  for (int trial = 0; trial < 200; ++trial) {
    for (size_t k = 0; k < p.size(); ++k) p[k] = p0[k] * uniform(0.5, 1.5);
    for (size_t j = 0; j < n; ++j) y[j] = uniform(-1.5, 1.5), yp[j] = uniform(-1.5, 1.5);
    double t = uniform(0, 10);
    const QdotModel* q = m.model;
    // F's rows beyond the DAE's equations are initial equations (t0 only): not compared here.
    size_t equations = m.dae->equations.size();
    ASSERT_EQ(q->residual(q, t, y.data(), yp.data(), p.data(), F.data()), 0) << q->lastError(q);
    std::copy(F.begin(), F.begin() + static_cast<long>(equations), all.begin());
    ASSERT_EQ(q->outputs(q, t, y.data(), yp.data(), p.data(), all.data() + equations), 0) << q->lastError(q);
    ASSERT_EQ(q->invariants(q, t, y.data(), yp.data(), p.data(), all.data() + equations + nOut), 0) << q->lastError(q);
    std::vector<double> v = m.symbolValues(t, y, yp, p);
    magnitudes.update(v);
    for (size_t i = 0; i < roots.size(); ++i)
      stats.check(all[i], sym::evaluate(roots[i], v), magnitudes.magnitude(roots[i]), "value " + std::to_string(i));
  }
  std::cout << "[ ulps ] " << std::filesystem::path(GetParam()).filename().string() << ": " << stats.compared
            << " values, max " << stats.maxUlps << " ulps of the result, max " << stats.maxMagnitudeUlps
            << " eps of the terms' magnitude, " << stats.beyond << " beyond " << kMaxUlps << " ulps\n";
}

// The VM runs exactly the kernel program: bit-identical to the kernel's reference interpreter
// (checks encoding and register reuse, which must not change a single operation).
TEST_P(ExamplesTest, VmIsBitIdenticalToKernelInterpreter) {
  SourceModel m(GetParam(), readFile(GetParam()));
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  size_t n = q->nVariables;
  std::vector<double> p(q->nParameters), y(n), yp(n), vmOut, kOut;
  ASSERT_EQ(q->parameters(q, nullptr, nullptr, p.data()), 0);
  for (int trial = 0; trial < 20; ++trial) {
    for (size_t j = 0; j < n; ++j) y[j] = uniform(-1.5, 1.5), yp[j] = uniform(-1.5, 1.5);
    ModelCall in{.t = uniform(0, 10), .cj = uniform(1, 100), .y = y.data(), .yp = yp.data(), .p = p.data()};
    for (auto id : {ModelProgram::Residual, ModelProgram::Jacobian, ModelProgram::Outputs,
                    ModelProgram::Invariants}) {
      const kernel::Program& prog = m.kernel.program(id);
      vmOut.assign(prog.outputCount, 0.0), kOut.assign(prog.outputCount, 1.0);
      kernel::interpret(prog, in, kOut);
      if (id == ModelProgram::Residual) q->residual(q, in.t, y.data(), yp.data(), p.data(), vmOut.data());
      if (id == ModelProgram::Jacobian) q->jacobian(q, in.t, y.data(), yp.data(), p.data(), in.cj, vmOut.data());
      if (id == ModelProgram::Outputs) q->outputs(q, in.t, y.data(), yp.data(), p.data(), vmOut.data());
      if (id == ModelProgram::Invariants) q->invariants(q, in.t, y.data(), yp.data(), p.data(), vmOut.data());
      for (size_t i = 0; i < vmOut.size(); ++i) EXPECT_EQ(ulpDistance(vmOut[i], kOut[i]), 0u) << prog.name << " " << i;
    }
  }
}

// J = dF/dy + cj dF/dy' against central differences of the residual (relative 1e-6), and zero
// (to the same tolerance) wherever the pattern has no entry.
TEST_P(ExamplesTest, JacobianMatchesFiniteDifferences) {
  SourceModel m(GetParam(), readFile(GetParam()));
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  size_t n = q->nVariables, rows = q->nResiduals;  // rows > n after index reduction
  std::vector<double> p(q->nParameters), y(n), yp(n), J(q->jacobianNonzeros), Fp(rows), Fm(rows), fd(n * rows, 0.0),
      rounding(n * rows, 0.0);
  ASSERT_EQ(q->parameters(q, nullptr, nullptr, p.data()), 0);
  for (int trial = 0; trial < 5; ++trial) {
    for (size_t j = 0; j < n; ++j) y[j] = uniform(-1.5, 1.5), yp[j] = uniform(-1.5, 1.5);
    double t = uniform(0, 10), cj = uniform(1, 1e3);
    ASSERT_EQ(q->jacobian(q, t, y.data(), yp.data(), p.data(), cj, J.data()), 0) << q->lastError(q);
    std::fill(fd.begin(), fd.end(), 0.0);
    std::fill(rounding.begin(), rounding.end(), 0.0);
    for (size_t j = 0; j < n; ++j)
      for (auto [v, factor] : {std::pair{&y, 1.0}, std::pair{&yp, cj}}) {
        double x = (*v)[j], h = 6e-6 * std::max(1.0, std::fabs(x));
        (*v)[j] = x + h, q->residual(q, t, y.data(), yp.data(), p.data(), Fp.data());
        (*v)[j] = x - h, q->residual(q, t, y.data(), yp.data(), p.data(), Fm.data());
        (*v)[j] = x;
        for (size_t i = 0; i < rows; ++i) {
          fd[j * rows + i] += factor * (Fp[i] - Fm[i]) / (2 * h);
          // the difference quotient's rounding: large residuals (pressures of 1e5 Pa, ρL/A der(Q))
          rounding[j * rows + i] += factor * 8 * kEps * std::max(std::fabs(Fp[i]), std::fabs(Fm[i])) / (2 * h);
        }
      }
    std::vector<double> dense(n * rows, 0.0);
    for (size_t j = 0; j < n; ++j)
      for (int32_t k = q->jacobianColumnStarts[j]; k < q->jacobianColumnStarts[j + 1]; ++k)
        dense[j * rows + q->jacobianRowIndices[k]] = J[k];
    for (size_t j = 0; j < n; ++j)
      for (size_t i = 0; i < rows; ++i)
        EXPECT_NEAR(dense[j * rows + i], fd[j * rows + i],
                    1e-6 * std::max({1.0, std::fabs(fd[j * rows + i]), cj}) + rounding[j * rows + i])
            << "row " << i << " column " << j << " (" << q->variableNames[j] << "), cj " << cj;
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, ExamplesTest, ::testing::ValuesIn(exampleFiles()),
                         [](const auto& info) { return std::filesystem::path(info.param).stem().string(); });

}  // namespace
}  // namespace qdot::test
