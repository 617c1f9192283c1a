// Large programs are split into several LLVM functions (values crossing a boundary go through the
// spill array) and still agree with the kernel interpreter: the spring chain of examples/ with
// n = 1000 masses (2000 variables, a residual of ~10^4 instructions).
#include <random>
#include <regex>

#include "KernelSource.h"

namespace qdot::test {
namespace {

std::string chain(int n) {
  std::string text = readFile(std::string(QDOT_SOURCE_DIR) + "/examples/vibration/spring_chain.qd");
  return std::regex_replace(text, std::regex("Integer n = 10"), "Integer n = " + std::to_string(n));
}

TEST(JitSplit, BigChainSplitsIntoSeveralFunctionsAndAgrees) {
  llvmbackend::JitOptions options;
  options.maxInstructionsPerFunction = 1000;
  KernelSource m("chain.qd", chain(1000), options);
  ASSERT_TRUE(m.ok());
  const QdotModel* q = m.model;
  ASSERT_EQ(q->nVariables, 2000u);  // x and der(x)
  const auto& res = m.kernel.program(ModelProgram::Residual);
  EXPECT_GT(res.code.size(), 5000u);
  EXPECT_EQ(m.stats.functions[2], (res.code.size() + 999) / 1000);
  EXPECT_GT(m.stats.functions[3], 1u);
  EXPECT_GT(m.stats.spillSlots[2], 0u);
  std::cout << "[ split ] residual: " << res.code.size() << " instructions in " << m.stats.functions[2]
            << " functions, " << m.stats.spillSlots[2] << " spill slots; compile " << m.stats.lowerSeconds << " + " << m.stats.optimiseSeconds << " + "
            << m.stats.codegenSeconds << " s\n";

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  size_t n = q->nVariables;
  std::vector<double> p(q->nParameters), y(n), yp(n), F(n), ref(n), J(q->jacobianNonzeros), refJ(J.size());
  ASSERT_EQ(q->parameters(q, nullptr, nullptr, p.data()), 0);
  for (double& x : y) x = u(rng);
  for (double& x : yp) x = u(rng);
  ASSERT_EQ(q->residual(q, 0.5, y.data(), yp.data(), p.data(), F.data()), 0) << q->lastError(q);
  ASSERT_EQ(q->jacobian(q, 0.5, y.data(), yp.data(), p.data(), 20.0, J.data()), 0) << q->lastError(q);
  ModelCall in;
  in.t = 0.5, in.cj = 20.0, in.y = y.data(), in.yp = yp.data(), in.p = p.data();
  kernel::interpret(res, in, ref);
  kernel::interpret(m.kernel.program(ModelProgram::Jacobian), in, refJ);
  for (size_t i = 0; i < n; ++i) ASSERT_TRUE(sameBits(F[i], ref[i])) << i << ": " << F[i] << " vs " << ref[i];
  for (size_t i = 0; i < J.size(); ++i) ASSERT_TRUE(sameBits(J[i], refJ[i])) << i;
}

// The default compile plan: residual, Jacobian and outputs compiled in several units on several
// threads, parameters and start values interpreted; results identical to the interpreter whatever
// the number of threads.
TEST(JitUnits, DefaultPlanOnOneOrFourThreadsAgrees) {
  for (unsigned threads : {1u, 4u}) {
    llvmbackend::JitOptions options;
    options.threads = threads;
    options.maxInstructionsPerFunction = 200;
    KernelSource m("chain.qd", chain(300), options);
    ASSERT_TRUE(m.ok());
    EXPECT_EQ(m.stats.functions[0], 0u) << "parameters are interpreted";
    EXPECT_EQ(m.stats.functions[1], 0u) << "start values are interpreted";
    EXPECT_GT(m.stats.functions[2], 1u);
    EXPECT_GT(m.stats.functions[4], 0u) << "outputs are compiled";
    EXPECT_EQ(m.stats.threads, threads);
    EXPECT_GT(m.stats.units, threads);
    const QdotModel* q = m.model;
    size_t n = q->nVariables;
    std::vector<double> p(q->nParameters), y0(n), yp0(n), nominal(n), F(n), ref(n);
    ASSERT_EQ(q->parameters(q, nullptr, nullptr, p.data()), 0);
    EXPECT_EQ(p[1], 1000.0);  // k
    ASSERT_EQ(q->initialValues(q, p.data(), 0.0, y0.data(), yp0.data(), nominal.data()), 0);
    EXPECT_EQ(y0[299], 0.01 * 300);  // x[300] starts at 0.01*300
    for (size_t i = 0; i < n; ++i) yp0[i] = 0.001 * double(i);
    ASSERT_EQ(q->residual(q, 0.5, y0.data(), yp0.data(), p.data(), F.data()), 0);
    ModelCall in;
    in.t = 0.5, in.y = y0.data(), in.yp = yp0.data(), in.p = p.data();
    kernel::interpret(m.kernel.program(ModelProgram::Residual), in, ref);
    for (size_t i = 0; i < n; ++i) ASSERT_TRUE(sameBits(F[i], ref[i])) << threads << " threads, F[" << i << "]";
  }
}

}  // namespace
}  // namespace qdot::test
