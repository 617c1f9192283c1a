// The backends of a run (driver/Backends.h). The tiered model's background compile owns what it
// reads: the model may outlive the Compilation it came from, and the JIT it switches to computes
// what the VM computes, bit for bit.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>

#include "driver/Backends.h"
#include "unit/pipeline/CompiledModel.h"

namespace qdot::driver {
namespace {

// The residual of `m` at a fixed state (the U-tube: x, der(x), E).
std::vector<double> residualAt(const QdotModel& m) {
  std::vector<double> p(m.nParameters), y(m.nVariables, 0.03), yp(m.nVariables, -0.2), F(m.nVariables);
  EXPECT_EQ(m.parameters(&m, nullptr, nullptr, p.data()), 0);
  EXPECT_EQ(m.residual(&m, 0.5, y.data(), yp.data(), p.data(), F.data()), 0);
  return F;
}

TEST(Backends, TieredModelOutlivesItsCompilation) {
  const std::string text = test::readSource("examples/textbook/utube.qd");
  RunnableModel tiered;
  {
    Compilation c;
    ASSERT_TRUE(compileSource(c, "utube.qd", text, "", Stage::Kernel));
    tiered = makeRunnableModel(c, Backend::Background, false);
    ASSERT_TRUE(tiered.model) << tiered.error;
    EXPECT_EQ(tiered.what, "bytecode then llvm");
  }  // the kernels and sources of the compilation go away while the JIT may still be compiling
  // Call the model until the JIT is ready (bounded: a compile of this model takes milliseconds).
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  std::vector<double> onVm = residualAt(*tiered.model);
  while (rt::tierReport(tiered.model.get())->compiling && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  rt::TierReport report = *rt::tierReport(tiered.model.get());
  ASSERT_FALSE(report.compiling);
  ASSERT_TRUE(report.ready) << tiered.jit->error;
  std::vector<double> onJit = residualAt(*tiered.model);
  EXPECT_GT(rt::tierReport(tiered.model.get())->secondTierCalls, 0u);
  ASSERT_EQ(onVm.size(), onJit.size());
  EXPECT_EQ(std::memcmp(onVm.data(), onJit.data(), onVm.size() * sizeof(double)), 0);
}

// What a model computes per output row (outputs, invariants) at a fixed state.
std::vector<double> perRowAt(const QdotModel& m) {
  std::vector<double> p(m.nParameters), y(m.nVariables, 0.3), yp(m.nVariables, -0.2);
  std::vector<double> out(m.nOutputs + m.nInvariants);
  EXPECT_EQ(m.parameters(&m, nullptr, nullptr, p.data()), 0);
  EXPECT_EQ(m.outputs(&m, 0.5, y.data(), yp.data(), p.data(), out.data()), 0);
  if (m.nInvariants > 0) {
    EXPECT_EQ(m.invariants(&m, 0.5, y.data(), yp.data(), p.data(), out.data() + m.nOutputs), 0);
  }
  return out;
}

// The background JIT takes the outputs and invariants too (a rigid body's angles and rotation
// matrices, written every output row; a pendulum's energy), and the tiered model sends them to it:
// the same bits as the VM's.
void expectPerRowCallsOnNativeCode(const std::string& file, bool outputs, bool invariants) {
  const std::string text = test::readSource(file);
  Compilation vm, tiered;
  vm.options.keepInvariants = tiered.options.keepInvariants = invariants;  // --invariants
  ASSERT_TRUE(compileSource(vm, file, text, "", Stage::Kernel));
  ASSERT_TRUE(compileSource(tiered, file, text, "", Stage::Kernel));
  RunnableModel onVm = makeRunnableModel(vm, Backend::Bytecode, invariants);
  RunnableModel m = makeRunnableModel(tiered, Backend::Background, invariants);
  ASSERT_TRUE(onVm.model && m.model) << onVm.error << m.error;
  ASSERT_EQ(m.model->nOutputs > 0, outputs);
  ASSERT_EQ(m.model->nInvariants > 0, invariants);
  auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (rt::tierReport(m.model.get())->compiling && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  ASSERT_TRUE(rt::tierReport(m.model.get())->ready) << m.jit->error;
  // Compiled, not interpreted.
  if (outputs) {
    EXPECT_NE(m.jit->stats.functions[programIndex(ModelProgram::Outputs)], 0u);
  }
  EXPECT_EQ(m.jit->stats.functions[programIndex(ModelProgram::Invariants)] != 0, invariants);
  uint64_t before = rt::tierReport(m.model.get())->secondTierCalls;
  std::vector<double> native = perRowAt(*m.model), interpreted = perRowAt(*onVm.model);
  EXPECT_EQ(rt::tierReport(m.model.get())->secondTierCalls, before + 1 + (invariants ? 1 : 0));
  ASSERT_EQ(native.size(), interpreted.size());
  EXPECT_EQ(std::memcmp(native.data(), interpreted.data(), native.size() * sizeof(double)), 0);
}

TEST(Backends, OutputsAndInvariantsMoveToNativeCodeWithTheSameBits) {
  expectPerRowCallsOnNativeCode("examples/rigid/fast_top.qd", true, false);
  expectPerRowCallsOnNativeCode("examples/pendulum/double_pendulum.qd", false, true);
}

// qdot run's releaseStages: the flat model, the equations of motion, the DAE and the symbolic
// nodes are gone once the kernels are built, the experiment is kept, the bytecode is moved into the
// VM model — and every backend computes what it computes from a compilation that kept everything.
TEST(Backends, ReleasedStagesChangeNoResult) {
  const std::string text = test::readSource("examples/textbook/utube.qd");
  for (Backend backend : {Backend::Bytecode, Backend::Native, Backend::Background}) {
    Compilation kept, released;
    released.options.releaseStages = true;
    ASSERT_TRUE(compileSource(kept, "utube.qd", text, "", Stage::Kernel));
    ASSERT_TRUE(compileSource(released, "utube.qd", text, "", Stage::Kernel));
    EXPECT_TRUE(kept.flat && kept.eom && kept.dae);
    EXPECT_FALSE(released.flat || released.eom || released.dae);
    EXPECT_EQ(released.ctx.symbolCount(), sym::Context().symbolCount());
    EXPECT_EQ(released.experiment.stopTime, kept.dae->experiment.stopTime);
    RunnableModel a = makeRunnableModel(kept, backend, false), b = makeRunnableModel(released, backend, false);
    ASSERT_TRUE(a.model && b.model) << a.error << b.error;
    EXPECT_EQ(released.bytecode.has_value(), false);
    std::vector<double> fa = residualAt(*a.model), fb = residualAt(*b.model);
    ASSERT_EQ(fa.size(), fb.size());
    EXPECT_EQ(std::memcmp(fa.data(), fb.data(), fa.size() * sizeof(double)), 0);
  }
}

TEST(Backends, EachBackendSaysWhatItIs) {
  const std::string text = test::readSource("examples/textbook/utube.qd");
  for (auto [backend, what] : {std::pair{Backend::Bytecode, "bytecode"}, std::pair{Backend::Native, "llvm"}}) {
    Compilation c;
    ASSERT_TRUE(compileSource(c, "utube.qd", text, "", Stage::Kernel));
    RunnableModel m = makeRunnableModel(c, backend, false);
    ASSERT_TRUE(m.model) << m.error;
    EXPECT_EQ(m.what, what);
    EXPECT_EQ(m.waited, backend == Backend::Native);
    EXPECT_FALSE(rt::tierReport(m.model.get()).has_value());
  }
}

TEST(Pipeline, ContinueToRunsEachStageOnceAndBothBackendsFromOneCompilation) {
  Compilation c;
  ASSERT_TRUE(compileSource(c, "utube.qd", test::readSource("examples/textbook/utube.qd"), "", Stage::Dae));
  EXPECT_FALSE(c.kernels);
  ASSERT_TRUE(continueTo(c, Stage::Native));
  EXPECT_TRUE(c.native);
  EXPECT_FALSE(c.bytecode);  // Native does not build the bytecode
  auto kernels = c.kernels;
  ASSERT_TRUE(continueTo(c, Stage::Bytecode));
  EXPECT_TRUE(c.bytecode);
  EXPECT_EQ(c.kernels, kernels);  // not rebuilt
}

TEST(Pipeline, AFailedJitLeavesTheBytecodeBackend) {
  Compilation c;
  std::atomic<bool> cancelled{true};  // the JIT gives up at once, as when a tiered run ends first
  c.options.jit.cancel = &cancelled;
  ASSERT_TRUE(compileSource(c, "utube.qd", test::readSource("examples/textbook/utube.qd"), "", Stage::Kernel));
  EXPECT_FALSE(continueTo(c, Stage::Native));
  EXPECT_NE(c.internalError.find("cancelled"), std::string::npos) << c.internalError;
  EXPECT_FALSE(c.diags.hasErrors());  // not the model's fault
  EXPECT_TRUE(continueTo(c, Stage::Bytecode));
  EXPECT_TRUE(c.bytecode);
}

TEST(Pipeline, AMissingFileIsOneError) {
  Compilation c;
  EXPECT_FALSE(compileFile(c, "/does/not/exist.qd", "", Stage::Parse));
  ASSERT_EQ(c.diags.errorCount(), 1u);
}

// The default backend weighs the JIT before compiling: a short run on a small model (the U-tube's
// residual costs well under a microsecond on the VM) never starts the compiler.
TEST(Backends, TheDefaultDoesNotCompileForAShortRun) {
  Compilation c;
  ASSERT_TRUE(compileSource(c, "utube.qd", test::readSource("examples/textbook/utube.qd"), "", Stage::Kernel));
  RunnableModel m = makeRunnableModel(c, Backend::Tiered, false);
  ASSERT_TRUE(m.model) << m.error;
  EXPECT_EQ(m.what, "bytecode then llvm");
  EXPECT_GT(m.jitEstimate.cpuSeconds, 0);
  rt::setTierHorizon(m.model.get(), 0, 1);
  std::vector<double> p(m.model->nParameters), y(m.model->nVariables, 0.03), yp(m.model->nVariables, -0.2);
  std::vector<double> F(m.model->nVariables);
  ASSERT_EQ(m.model->parameters(m.model.get(), nullptr, nullptr, p.data()), 0);
  for (int k = 1; k <= 100; ++k)  // the whole horizon in 100 calls
    ASSERT_EQ(m.model->residual(m.model.get(), k / 100.0, y.data(), yp.data(), p.data(), F.data()), 0);
  rt::TierReport report = *rt::tierReport(m.model.get());
  EXPECT_FALSE(report.started);
  EXPECT_FALSE(report.compiling);
  EXPECT_EQ(report.firstTierCalls, 100u);
  EXPECT_DOUBLE_EQ(report.startedAt.progress, 1.0);
}

}  // namespace
}  // namespace qdot::driver
