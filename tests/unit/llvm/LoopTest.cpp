// Kernel programs with loops, written by hand, on every backend: kernel::interpret, the bytecode VM
// and the JIT (O2 in one function; O0 split every 3 instructions, so loops must stay whole and
// values from before a loop cross parts) give the same bits as the direct C++ computation — an
// affine stencil with peeled ends and invariant registers, count 0 and 1, a table loop storing
// through a permutation (stx) with ldidx, negative strides, a value from before a loop used after
// it, a parameter array read with ldpl, a sum over a loop (stadd), table entries as numbers (ldx). A NaN inside a loop is named with its iteration on the VM
// and on the JIT.
#include <cstdio>
#include <functional>
#include <random>
#include <sstream>

#include "KernelSource.h"
#include "bytecode/Emitter.h"
#include "llvm/ObjectFile.h"
#include "vm/Vm.h"

namespace qdot::test {
namespace {

using kernel::Instr;
using kernel::Loop;
using kernel::Op;

// Appends instructions to a kernel program (instruction i defines %i).
struct Writer {
  kernel::Program p;
  uint32_t op(Op o, uint32_t a = 0, uint32_t b = 0, uint32_t c = 0, uint32_t imm = 0) {
    p.code.push_back(Instr{o, a, b, c, imm, 0});
    return static_cast<uint32_t>(p.code.size() - 1);
  }
  uint32_t k(double v) {
    p.constants.push_back(v);
    return op(Op::LoadConst, 0, 0, 0, static_cast<uint32_t>(p.constants.size() - 1));
  }
  void loop(Loop l) {
    p.loops.push_back(l);
    op(Op::LoopBegin, 0, 0, 0, static_cast<uint32_t>(p.loops.size() - 1));
  }
  void endLoop() { op(Op::LoopEnd, 0, 0, 0, static_cast<uint32_t>(p.loops.size() - 1)); }
};

// A model of n variables x0.. and one parameter k whose residual is `residual`.
kernel::KernelModule moduleWith(kernel::Program residual, uint32_t n) {
  kernel::KernelModule m;
  ModelDescription& d = m.description.edit();
  d.name = "Loops";
  for (uint32_t i = 0; i < n; ++i) d.variableNames.push_back(std::string("x").append(std::to_string(i)));
  d.isDifferential.assign(n, 1), d.fixed.assign(n, 0), d.jacobianColumnStarts.assign(n + 1, 0);
  d.parameterNames = {"k"}, d.parameterDescriptions = {""};
  kernel::Program& params = m.program(ModelProgram::Parameters);
  params.name = "parameters";
  params.code = {Instr{Op::LoadGiven, 0, 0, 0, 0}, Instr{Op::Store, 0, 0, 0, 0}};
  params.outputCount = 1;
  m.program(ModelProgram::InitialValues).outputCount = 3 * n;
  residual.name = "residual", residual.outputCount = n;
  m.program(ModelProgram::Residual) = std::move(residual);
  m.sources = {{"equation 1", {}, ""}};
  return m;
}

using Direct = std::function<void(const double* y, const double* yp, double k, double* F)>;

struct Inputs {
  std::vector<double> y, yp;
  double k = 1.75;
  explicit Inputs(uint32_t n) : y(n), yp(n) {
    std::mt19937_64 rng(n);
    std::uniform_real_distribution<double> u(-2, 2);
    for (uint32_t i = 0; i < n; ++i) y[i] = u(rng), yp[i] = u(rng);
  }
};

Result<ModelPtr> vmModel(const kernel::KernelModule& m) {
  SourceManager sm;
  return vm::createModel(bytecode::emitBytecode(m, sm));
}

Result<ModelPtr> jitModel(const kernel::KernelModule& m, int level, uint32_t split) {
  SourceManager sm;
  llvmbackend::JitOptions o = verified({});
  o.optLevel = o.jacobianOptLevel = o.coldOptLevel = level;
  o.maxInstructionsPerFunction = split;
  return llvmbackend::createJitModel(m, sm, o);
}

void expectSame(const std::vector<double>& got, const std::vector<double>& want, const std::string& who) {
  for (size_t i = 0; i < want.size(); ++i)
    EXPECT_TRUE(sameBits(got[i], want[i])) << who << " F[" << i << "] = " << got[i] << ", expected " << want[i];
}

// interpret, the VM and the JIT (two ways) against `direct`.
void expectEveryBackend(const kernel::Program& residual, uint32_t n, const Direct& direct) {
  kernel::KernelModule m = moduleWith(residual, n);
  Inputs in(n);
  std::vector<double> want(n), got(n, -123.0);
  direct(in.y.data(), in.yp.data(), in.k, want.data());
  kernel::interpret(m.program(ModelProgram::Residual), {.y = in.y.data(), .yp = in.yp.data(), .p = &in.k}, got);
  expectSame(got, want, "interpret");
  auto run = [&](Result<ModelPtr> model, const std::string& who) {
    ASSERT_TRUE(model.ok()) << who << ": " << model.error();
    QdotModel* q = model.value().get();
    std::fill(got.begin(), got.end(), -123.0);
    EXPECT_EQ(q->residual(q, 0, in.y.data(), in.yp.data(), &in.k, got.data()), 0) << q->lastError(q);
    expectSame(got, want, who);
  };
  run(vmModel(m), "vm");
  run(jitModel(m, 2, 5000), "jit O2");
  run(jitModel(m, 0, 3), "jit O0 split");
}

// F[i] = k*(y[i+1] - 2 y[i] + y[i-1]) + yp[i], y[-1] = y[n] = 0: ends peeled, interior looped.
kernel::Program stencil(uint32_t n) {
  Writer w;
  uint32_t k = w.op(Op::LoadP), m2 = w.k(-2.0);
  for (uint32_t end : {0u, n - 1}) {
    uint32_t s = w.op(Op::Add, w.op(Op::Mul, m2, w.op(Op::LoadY, 0, 0, 0, end)), w.op(Op::LoadY, 0, 0, 0, end == 0 ? 1 : n - 2));
    w.op(Op::Store, w.op(Op::Add, w.op(Op::Mul, k, s), w.op(Op::LoadYp, 0, 0, 0, end)), 0, 0, end);
  }
  w.loop(Loop{.count = n - 2, .first = 0, .stride = 1});
  uint32_t s = w.op(Op::Add, w.op(Op::LoadYLooped, 0, 0, 0, 2), w.op(Op::Mul, m2, w.op(Op::LoadYLooped, 0, 0, 0, 1)));
  s = w.op(Op::Add, s, w.op(Op::LoadYLooped, 0, 0, 0, 0));
  w.op(Op::StoreLooped, w.op(Op::Add, w.op(Op::Mul, k, s), w.op(Op::LoadYpLooped, 0, 0, 0, 1)), 0, 0, 1);
  w.endLoop();
  return w.p;
}

void stencilDirect(uint32_t n, const double* y, const double* yp, double k, double* F) {
  F[0] = k * (-2.0 * y[0] + y[1]) + yp[0];
  F[n - 1] = k * (-2.0 * y[n - 1] + y[n - 2]) + yp[n - 1];
  for (uint32_t i = 1; i + 1 < n; ++i) F[i] = k * (y[i + 1] + -2.0 * y[i] + y[i - 1]) + yp[i];
}

TEST(Loops, AffineStencilWithPeeledEndsOnEveryBackend) {
  for (uint32_t n : {2u, 3u, 4u, 17u, 200u})  // interior loops of count 0, 1, 2, 15, 198
    expectEveryBackend(stencil(n), n, [n](const double* y, const double* yp, double k, double* F) {
      stencilDirect(n, y, yp, k, F);
    });
}

// out[S[c]] = 2*y[L] + L (ldidx) for L = X[c] (a permutation), then out[n-1] = k + 1 after the loop
// (k loaded before it).
TEST(Loops, TableLoopAndIndexedStoresOnEveryBackend) {
  const uint32_t n = 7;
  std::vector<uint32_t> offsets = {3, 0, 5, 1, 4, 2}, slots = {4, 2, 0, 5, 1, 3};
  Writer w;
  w.p.indexTable = offsets;
  w.p.indexTable.insert(w.p.indexTable.end(), slots.begin(), slots.end());
  uint32_t k = w.op(Op::LoadP), two = w.k(2.0), one = w.k(1.0);
  w.loop(Loop{.count = n - 1, .offsetTable = 0});
  uint32_t v = w.op(Op::Add, w.op(Op::Mul, two, w.op(Op::LoadYLooped)), w.op(Op::LoadLoopOffset));
  w.op(Op::StoreIndexed, v, 0, 0, n - 1);
  w.endLoop();
  w.op(Op::Store, w.op(Op::Add, k, one), 0, 0, n - 1);
  expectEveryBackend(w.p, n, [&](const double* y, const double*, double kv, double* F) {
    for (uint32_t c = 0; c + 1 < n; ++c) F[slots[c]] = 2.0 * y[offsets[c]] + double(offsets[c]);
    F[n - 1] = kv + 1.0;
  });
}

// A table entry as a number (ldx, a template's iterator value in a table loop): out[L] = y[L]·(W[c] + 0.5)
// for L = X[c], W a second table read at the same iteration.
TEST(Loops, TableEntriesAsNumbersOnEveryBackend) {
  const uint32_t n = 6;
  std::vector<uint32_t> offsets = {3, 0, 5, 1, 4, 2}, weights = {7, 1, 0, 4, 2, 9};
  Writer w;
  w.p.indexTable = offsets;
  w.p.indexTable.insert(w.p.indexTable.end(), weights.begin(), weights.end());
  uint32_t half = w.k(0.5);
  w.loop(Loop{.count = n, .offsetTable = 0});
  uint32_t weight = w.op(Op::Add, w.op(Op::LoadTable, 0, 0, 0, n), half);
  w.op(Op::StoreLooped, w.op(Op::Mul, w.op(Op::LoadYLooped), weight), 0, 0, 0);
  w.endLoop();
  expectEveryBackend(w.p, n, [&](const double* y, const double*, double, double* F) {
    for (uint32_t c = 0; c < n; ++c) F[offsets[c]] = y[offsets[c]] * (double(weights[c]) + 0.5);
  });
}

// Two loops: out[L] = 0.01*L + yp[L] for L = n-1 down to 3 (stride -1), then the rest with L = c.
TEST(Loops, NegativeStrideAndTwoLoopsOnEveryBackend) {
  const uint32_t n = 9;
  Writer w;
  uint32_t h = w.k(0.01);
  w.loop(Loop{.count = n - 3, .first = int32_t(n - 1), .stride = -1});
  w.op(Op::StoreLooped, w.op(Op::Add, w.op(Op::Mul, h, w.op(Op::LoadLoopOffset)), w.op(Op::LoadYpLooped)), 0, 0, 0);
  w.endLoop();
  w.loop(Loop{.count = 3});
  w.op(Op::StoreLooped, w.op(Op::Mul, h, w.op(Op::LoadYLooped)), 0, 0, 0);
  w.endLoop();
  expectEveryBackend(w.p, n, [&](const double* y, const double* yp, double, double* F) {
    for (uint32_t L = n - 1; L >= 3; --L) F[L] = 0.01 * double(L) + yp[L];
    for (uint32_t L = 0; L < 3; ++L) F[L] = 0.01 * y[L];
  });
}

// A sum over a loop (stadd, an invariant's Σ over every element): out[0] = y[0]² + Σ_L y[L]·yp[L]
// for L = 1 .. n-2 (added in order), out[n-1] = k after it, the other slots 0.
TEST(Loops, ASumOverALoopOnEveryBackend) {
  const uint32_t n = 9;
  Writer w;
  uint32_t y0 = w.op(Op::LoadY);
  w.op(Op::Store, w.op(Op::Mul, y0, y0), 0, 0, 0);
  w.loop(Loop{.count = n - 2, .first = 1, .stride = 1});
  w.op(Op::StoreAdd, w.op(Op::Mul, w.op(Op::LoadYLooped), w.op(Op::LoadYpLooped)), 0, 0, 0);
  w.endLoop();
  uint32_t zero = w.k(0.0);
  for (uint32_t i = 1; i + 1 < n; ++i) w.op(Op::Store, zero, 0, 0, i);
  w.op(Op::Store, w.op(Op::LoadP), 0, 0, n - 1);
  expectEveryBackend(w.p, n, [&](const double* y, const double* yp, double kv, double* F) {
    F[0] = y[0] * y[0];
    for (uint32_t L = 1; L + 1 < n; ++L) F[0] += y[L] * yp[L];
    for (uint32_t i = 1; i + 1 < n; ++i) F[i] = 0.0;
    F[n - 1] = kv;
  });
}

// A parameter array read in a loop (ldpl): F[L] = a[L + 1]*y[L] + a[L]*yp[L] for L = 0 .. n-2, and
// F[n-1] = k·y[n-1] with k = a[0] read before the loop, n parameters a0 .. a{n-1}; the same bits on
// interpret, the VM and the JIT (O2 whole, O0 split every 3 instructions).
TEST(Loops, AParameterArrayReadInALoopOnEveryBackend) {
  const uint32_t n = 9;
  Writer w;
  uint32_t k = w.op(Op::LoadP);
  w.loop(Loop{.count = n - 1});
  uint32_t right = w.op(Op::Mul, w.op(Op::LoadPLooped, 0, 0, 0, 1), w.op(Op::LoadYLooped));
  w.op(Op::StoreLooped, w.op(Op::Add, right, w.op(Op::Mul, w.op(Op::LoadPLooped), w.op(Op::LoadYpLooped))));
  w.endLoop();
  w.op(Op::Store, w.op(Op::Mul, k, w.op(Op::LoadY, 0, 0, 0, n - 1)), 0, 0, n - 1);
  kernel::KernelModule m = moduleWith(w.p, n);
  m.description.edit().parameterNames.clear();
  kernel::Program& params = m.program(ModelProgram::Parameters);
  params.code.clear();
  for (uint32_t i = 0; i < n; ++i) {
    m.description.edit().parameterNames.push_back("a" + std::to_string(i));
    params.code.push_back(Instr{Op::LoadGiven, 0, 0, 0, i});
    params.code.push_back(Instr{Op::Store, 2 * i, 0, 0, i});
  }
  m.description.edit().parameterDescriptions.assign(n, "");
  params.outputCount = n;
  ASSERT_EQ(kernel::checkLoops(m.program(ModelProgram::Residual), n, n), "");
  Inputs in(n);
  std::vector<double> a(n), want(n), got(n);
  for (uint32_t i = 0; i < n; ++i) a[i] = 0.5 + 0.25 * i * i;
  for (uint32_t L = 0; L + 1 < n; ++L) want[L] = a[L + 1] * in.y[L] + a[L] * in.yp[L];
  want[n - 1] = a[0] * in.y[n - 1];
  kernel::interpret(m.program(ModelProgram::Residual), {.y = in.y.data(), .yp = in.yp.data(), .p = a.data()}, got);
  expectSame(got, want, "interpret");
  auto run = [&](Result<ModelPtr> model, const std::string& who) {
    ASSERT_TRUE(model.ok()) << who << ": " << model.error();
    QdotModel* q = model.value().get();
    std::fill(got.begin(), got.end(), -123.0);
    EXPECT_EQ(q->residual(q, 0, in.y.data(), in.yp.data(), a.data(), got.data()), 0) << q->lastError(q);
    expectSame(got, want, who);
  };
  run(vmModel(m), "vm");
  run(jitModel(m, 2, 5000), "jit O2");
  run(jitModel(m, 0, 3), "jit O0 split");
}

TEST(Loops, ANaNInsideALoopIsNamedWithItsIterationOnTheVmAndTheJit) {
  kernel::KernelModule m = moduleWith(stencil(10), 10);
  Inputs in(10);
  in.y[5] = std::nan("");  // first read by iteration c = 3 (y[2 + L], L = 3)
  std::vector<double> F(10);
  for (auto* make : {+[](const kernel::KernelModule& k) { return vmModel(k); },
                     +[](const kernel::KernelModule& k) { return jitModel(k, 0, 3); }}) {
    Result<ModelPtr> model = make(m);
    ASSERT_TRUE(model.ok()) << model.error();
    QdotModel* q = model.value().get();
    EXPECT_EQ(q->residual(q, 0, in.y.data(), in.yp.data(), &in.k, F.data()), 1);
    std::string e = q->lastError(q);
    EXPECT_NE(e.find("the value of x5 is nan (loop iteration 3, offset 3) in equation 1"), std::string::npos) << e;
  }
}

// Start values of n masses as a large model has them: x_i = 0.01 i by one loop, the 2n rates and
// nominals 0 by another (what KernelBuilder::numberRuns emits).
kernel::Program loopedStartValues(uint32_t n) {
  Writer w;
  uint32_t step = w.k(0.01), one = w.k(1.0);
  w.loop(Loop{.count = n, .first = 0, .stride = 1});
  w.op(Op::StoreLooped, w.op(Op::Mul, step, w.op(Op::Add, w.op(Op::LoadLoopOffset), one)), 0, 0, 0);
  w.endLoop();
  uint32_t zero = w.k(0.0);
  w.loop(Loop{.count = 2 * n, .first = 0, .stride = 1});
  w.op(Op::StoreLooped, zero, 0, 0, n);
  w.endLoop();
  w.p.name = "initialValues", w.p.outputCount = 3 * n;
  return w.p;
}

// Start values stored one instruction each, no loop: a run executes every instruction once.
kernel::Program straightStartValues(uint32_t n) {
  Writer w;
  uint32_t zero = w.k(0.0);
  for (uint32_t i = 0; i < n; ++i) w.op(Op::Store, w.k(0.01 * (static_cast<double>(i) + 1.0)), 0, 0, i);
  for (uint32_t i = n; i < 3 * n; ++i) w.op(Op::Store, zero, 0, 0, i);
  w.p.name = "initialValues", w.p.outputCount = 3 * n;
  return w.p;
}

// A program that runs once is left to the interpreter unless one run of it executes at least
// JitOptions::compileRunOnceFrom instructions, kRunOnceRepeats times its length (a large model's
// looped start values; straight-line code never); compiled or not, its values are the VM's and the
// direct computation's, bit for bit.
TEST(Loops, LongStartValueLoopsAreCompiledOtherRunOnceCodeInterpreted) {
  struct Case {
    uint32_t n;
    bool looped, compiled;
  };
  for (Case c : {Case{100, true, false}, Case{40000, true, true}, Case{4000, false, false}}) {
    kernel::KernelModule m = moduleWith(stencil(c.n), c.n);
    m.program(ModelProgram::InitialValues) = c.looped ? loopedStartValues(c.n) : straightStartValues(c.n);
    llvmbackend::JitOptions options = verified({});
    options.compileRunOnceFrom = 10000;  // below every case's executed instructions but the smallest
    SourceManager sm;
    llvmbackend::JitStats stats;
    Result<ModelPtr> jit = llvmbackend::createJitModel(m, sm, options, &stats);
    ASSERT_TRUE(jit.ok()) << jit.error();
    EXPECT_EQ(stats.functions[programIndex(ModelProgram::InitialValues)] > 0, c.compiled) << c.n;
    EXPECT_EQ(stats.functions[programIndex(ModelProgram::Parameters)], 0u) << c.n;  // two instructions
    Result<ModelPtr> vm = vmModel(m);
    ASSERT_TRUE(vm.ok()) << vm.error();
    double k = 1.75;
    for (QdotModel* q : {jit.value().get(), vm.value().get()}) {
      std::vector<double> y(c.n, -1.0), yp(c.n, -1.0), nominal(c.n, -1.0);
      ASSERT_EQ(q->initialValues(q, &k, 0.0, y.data(), yp.data(), nominal.data()), 0) << q->lastError(q);
      for (uint32_t i = 0; i < c.n; ++i) {
        ASSERT_TRUE(sameBits(y[i], 0.01 * (static_cast<double>(i) + 1.0))) << c.n << " y[" << i << "] = " << y[i];
        ASSERT_EQ(yp[i], 0.0);
        ASSERT_EQ(nominal[i], 0.0);
      }
    }
  }
}

TEST(Loops, PrintersShowTheLoop) {
  kernel::KernelModule m = moduleWith(stencil(6), 6);
  std::ostringstream kernelText, bytecodeText;
  kernel::printProgram(kernelText, m.program(ModelProgram::Residual), m);
  EXPECT_NE(kernelText.str().find("loop 0 (count 4, L = 0 + 1*c)"), std::string::npos) << kernelText.str();
  EXPECT_NE(kernelText.str().find("    %"), std::string::npos);  // the body is indented
  EXPECT_NE(kernelText.str().find("ldyl 2 + L"), std::string::npos);
  EXPECT_NE(kernelText.str().find("stl out[1 + L]"), std::string::npos);
  SourceManager sm;
  vm::disassembleFunction(bytecodeText, bytecode::emitBytecode(m, sm), ModelProgram::Residual);
  EXPECT_NE(bytecodeText.str().find("loop    0 (count 4, L = 0 + 1*c, exit "), std::string::npos) << bytecodeText.str();
  EXPECT_NE(bytecodeText.str().find("endloop 0"), std::string::npos);
}

// The bytecode's registers: a value from before the loop that the body reads keeps its register
// to the endloop (no body value may reuse it), so a long body does not clobber it.
TEST(Loops, RegistersOfValuesReadInsideTheBodyLiveToTheEndloop) {
  const uint32_t n = 5;
  Writer w;
  uint32_t k = w.op(Op::LoadP);
  w.loop(Loop{.count = n});
  uint32_t acc = w.op(Op::LoadYLooped);
  for (int i = 0; i < 6; ++i) acc = w.op(Op::Add, acc, w.op(Op::Mul, acc, acc));  // registers die and are reused
  w.op(Op::StoreLooped, w.op(Op::Mul, acc, k));  // k read last in the body
  w.endLoop();
  expectEveryBackend(w.p, n, [&](const double* y, const double*, double kv, double* F) {
    for (uint32_t i = 0; i < n; ++i) {
      double a = y[i];
      for (int j = 0; j < 6; ++j) a = a + a * a;
      F[i] = a * kv;
    }
  });
}

// `qdot build` lowers the same way into one object file (the IR verifier runs there).
TEST(Loops, ObjectFilesHoldLoopedPrograms) {
  Writer w;  // a table loop (the table becomes a global) after the stencil
  w.p = stencil(12);
  w.p.indexTable = {11, 0, 5};
  w.loop(Loop{.count = 3, .offsetTable = 0});
  w.op(Op::StoreIndexed, w.op(Op::LoadLoopOffset), 0, 0, 0);
  w.endLoop();
  kernel::KernelModule m = moduleWith(w.p, 12);
  std::string path = ::testing::TempDir() + "qdot_loops.o";
  Result<llvmbackend::ObjectFileInfo> info = llvmbackend::emitObjectFile(m, 2, path);
  ASSERT_TRUE(info.ok()) << info.error();
  EXPECT_EQ(info->entryNames[programIndex(ModelProgram::Residual)], "qdot_residual");
  std::remove(path.c_str());
}

}  // namespace
}  // namespace qdot::test
