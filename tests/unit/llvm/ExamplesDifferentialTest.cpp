// Differential tests over every example model (examples/**/*.qd): the JIT-compiled programs
// against the kernel reference interpreter (kernel::interpret) on random inputs — parameters
// (defaults and overrides), start values, residual, Jacobian, outputs, invariants — with the
// default options, with LLVM's O2 IR pipeline, and at O0 with every program split into functions
// of 3 instructions.
#include <algorithm>
#include <filesystem>
#include <iostream>
#include <random>

#include "KernelSource.h"

namespace qdot::test {
namespace {

// Measured: 0 ulps everywhere (the compiled code performs the interpreter's operations in its
// order); a few ulps are allowed for libm calls LLVM may rewrite (pow with special exponents).
constexpr uint64_t kMaxUlps = 4;

std::vector<std::string> exampleFiles() {
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(std::string(QDOT_SOURCE_DIR) + "/examples"))
    if (e.path().extension() == ".qd") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

struct Variant {
  int optLevel;
  uint32_t maxInstructions;
  int pipelineLevel;
};

class JitExamplesTest : public ::testing::TestWithParam<std::tuple<std::string, Variant>> {
 protected:
  std::mt19937_64 rng{2024};
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
  std::vector<double> randoms(size_t n, double lo, double hi) {
    std::vector<double> v(n);
    for (double& x : v) x = uniform(lo, hi);
    return v;
  }
  uint64_t maxUlps = 0;

  // Runs the reference interpreter and compares all of `jit` with it.
  void compare(const KernelSource& m, ModelProgram id, const ModelCall& in, const std::vector<double>& jit,
               int rc, const std::string& what) {
    const kernel::Program& prog = m.kernel.program(id);
    std::vector<double> ref(prog.outputCount);
    kernel::interpret(prog, in, ref);
    bool finite = std::all_of(ref.begin(), ref.end(), [](double x) { return std::isfinite(x); });
    EXPECT_EQ(rc, finite ? 0 : 1) << what << ": " << m.model->lastError(m.model);
    for (size_t i = 0; i < ref.size(); ++i) {
      uint64_t u = ulpDistance(jit[i], ref[i]);
      maxUlps = std::max(maxUlps, u);
      EXPECT_LE(u, kMaxUlps) << what << "[" << i << "]: jit " << jit[i] << " vs interpreter " << ref[i];
    }
  }
};

TEST_P(JitExamplesTest, AgreesWithTheKernelInterpreter) {
  auto [file, variant] = GetParam();
  llvmbackend::JitOptions options;
  options.optLevel = options.jacobianOptLevel = options.coldOptLevel = variant.optLevel;
  options.compiledPrograms = llvmbackend::kAllPrograms;  // all six programs compiled and compared
  options.maxInstructionsPerFunction = variant.maxInstructions;
  options.pipelineLevel = variant.pipelineLevel;
  KernelSource m(file, readFile(file), options);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  size_t n = q->nVariables, np = q->nParameters;
  EXPECT_EQ(q->abiVersion, uint32_t(QDOT_MODEL_ABI_VERSION));
  EXPECT_EQ(q->jacobianNonzeros, m.kernel.description->jacobianRowIndices.size());

  // Parameters: defaults, then some overridden with random values.
  std::vector<double> p(np), given = randoms(np, 0.5, 2.0);
  std::vector<uint8_t> none(np, 0), some(np);
  for (size_t i = 0; i < np; ++i) some[i] = i % 2;
  ModelCall pin;
  pin.given = given.data(), pin.overridden = none.data();
  compare(m, ModelProgram::Parameters, pin, p, q->parameters(q, given.data(), none.data(), p.data()), "p");
  std::vector<double> p2(np);
  pin.overridden = some.data();
  compare(m, ModelProgram::Parameters, pin, p2, q->parameters(q, given.data(), some.data(), p2.data()), "p'");

  // Start values.
  std::vector<double> y0(n), yp0(n), nominal(n), start;
  int rc = q->initialValues(q, p.data(), 0.25, y0.data(), yp0.data(), nominal.data());
  start.insert(start.end(), y0.begin(), y0.end());
  start.insert(start.end(), yp0.begin(), yp0.end());
  start.insert(start.end(), nominal.begin(), nominal.end());
  ModelCall sin;
  sin.t = 0.25, sin.p = p.data();
  compare(m, ModelProgram::InitialValues, sin, start, rc, "start");

  // State functions at random states.
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<double> y = randoms(n, -1.5, 1.5), yp = randoms(n, -2, 2), F(q->nResiduals), J(q->jacobianNonzeros);
    std::vector<double> out(q->nOutputs), inv(q->nInvariants);
    double t = uniform(0, 10), cj = uniform(0.1, 100);
    ModelCall in;
    in.t = t, in.cj = cj, in.y = y.data(), in.yp = yp.data(), in.p = p.data();
    compare(m, ModelProgram::Residual, in, F, q->residual(q, t, y.data(), yp.data(), p.data(), F.data()), "F");
    compare(m, ModelProgram::Jacobian, in, J,
            q->jacobian(q, t, y.data(), yp.data(), p.data(), cj, J.data()), "J");
    compare(m, ModelProgram::Outputs, in, out, q->outputs(q, t, y.data(), yp.data(), p.data(), out.data()), "out");
    compare(m, ModelProgram::Invariants, in, inv,
            q->invariants(q, t, y.data(), yp.data(), p.data(), inv.data()), "inv");
  }
  std::cout << "[ ulps ] " << std::filesystem::path(file).filename().string() << " O" << variant.optLevel
            << " split " << variant.maxInstructions << " pipeline O" << variant.pipelineLevel << ": max " << maxUlps << ", residual in "
            << m.stats.functions[2] << " function(s)\n";
}

INSTANTIATE_TEST_SUITE_P(Examples, JitExamplesTest,
                         ::testing::Combine(::testing::ValuesIn(exampleFiles()),
                                            ::testing::Values(Variant{2, 500, 0}, Variant{2, 500, 2}, Variant{0, 3, 0})),
                         [](const auto& info) {
                           std::string s = std::filesystem::path(std::get<0>(info.param)).stem().string();
                           const Variant& v = std::get<1>(info.param);
                           return s + "_O" + std::to_string(v.optLevel) + "_split" + std::to_string(v.maxInstructions) + "_pipeline" +
                                  std::to_string(v.pipelineLevel);
                         });

}  // namespace
}  // namespace qdot::test
