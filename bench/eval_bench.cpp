// eval_bench: the two backends side by side on one model, in one process (bench/README.md).
//   eval_bench MODEL.qd [--repeat R] [--no-llvm] [--no-eval] [--loops] [--calls N] [--min-time S]
// Compiles the file R times (best of R per stage): the front end (parse .. dae, driver::compileFile,
// as qdot run), kernel::buildKernels, then each backend's code generation — bytecode::emitBytecode +
// vm::createModel, and llvmbackend::createJitModel with the default options, as
// `qdot run --jit-wait`. Then (unless --no-eval) times model->residual and model->jacobian of
// both models on one fixed state (y = y0 + 0.01 (i mod 17), y' = 0.02 (i mod 5), cj = 10): calls
// in batches until --min-time seconds have passed, best of 3 batches, in ns per call; and checks
// that both backends return the same F and J (max |difference|). With --calls N each of the four
// loops instead runs exactly N calls, in its own non-inlined function (evalVmResidual,
// evalJitResidual, evalVmJacobian, evalJitJacobian) for callgrind's inclusive instruction counts.
// Prints one JSON object on stdout.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <vector>

#include "driver/Pipeline.h"
#include "kernel/Kernel.h"
#include "llvm/JitModel.h"
#include "vm/Vm.h"

namespace {

using namespace qdot;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

struct State {
  std::vector<double> y, yp, p, F, J;
};


template <bool Jacobian>
void calls(const QdotModel* m, State& s, long n) {
  for (long i = 0; i < n; ++i) {
    if constexpr (Jacobian)
      m->jacobian(m, 0.1, s.y.data(), s.yp.data(), s.p.data(), 10.0, s.J.data());
    else
      m->residual(m, 0.1, s.y.data(), s.yp.data(), s.p.data(), s.F.data());
  }
}

// Separate symbols for callgrind (--calls N): inclusive instructions per loop.
extern "C" __attribute__((noinline)) void evalVmResidual(const QdotModel* m, State& s, long n) { calls<false>(m, s, n); }
extern "C" __attribute__((noinline)) void evalJitResidual(const QdotModel* m, State& s, long n) { calls<false>(m, s, n); }
extern "C" __attribute__((noinline)) void evalVmJacobian(const QdotModel* m, State& s, long n) { calls<true>(m, s, n); }
extern "C" __attribute__((noinline)) void evalJitJacobian(const QdotModel* m, State& s, long n) { calls<true>(m, s, n); }

namespace {

/// ns per call: batches until minTime has passed, best of 3 batches.
double nsPerCall(void (*loop)(const QdotModel*, State&, long), const QdotModel* m, State& s, double minTime) {
  long batch = 1;
  for (;;) {  // find a batch that takes about minTime / 4
    auto t0 = Clock::now();
    loop(m, s, batch);
    if (secondsSince(t0) > minTime / 4 || batch > (1L << 40)) break;
    batch *= 2;
  }
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < 3; ++r) {
    auto t0 = Clock::now();
    long done = 0;
    double elapsed = 0;
    do {
      loop(m, s, batch);
      done += batch;
      elapsed = secondsSince(t0);
    } while (elapsed < minTime);
    best = std::min(best, elapsed / done * 1e9);
  }
  return best;
}

State fixedState(const QdotModel* m) {
  State s;
  size_t n = m->nVariables;
  s.p.resize(m->nParameters);
  m->parameters(m, nullptr, nullptr, s.p.data());
  s.y.resize(n), s.yp.resize(n), s.F.resize(n), s.J.resize(m->jacobianNonzeros);
  std::vector<double> nominal(n);
  m->initialValues(m, s.p.data(), 0.0, s.y.data(), s.yp.data(), nominal.data());
  for (size_t i = 0; i < n; ++i) s.y[i] += 0.01 * double(i % 17), s.yp[i] = 0.02 * double(i % 5);
  return s;
}

double maxDiff(const std::vector<double>& a, const std::vector<double>& b) {
  double d = 0;
  for (size_t i = 0; i < a.size(); ++i) d = std::max(d, std::abs(a[i] - b[i]));
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"both backends on one model: compile stages and residual/Jacobian ns per call (bench/)"};
  std::string file;
  int repeat = 1;
  bool noLlvm = false, noEval = false, loops = false;
  long fixedCalls = 0;
  double minTime = 0.1;
  app.add_option("file", file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  app.add_option("--repeat", repeat, "compile this many times, best per stage")->check(CLI::PositiveNumber);
  app.add_flag("--no-llvm", noLlvm, "bytecode only");
  app.add_flag("--no-eval", noEval, "compile times only");
  app.add_flag("--loops", loops, "keep repeated structure as loops, as qdot run does (default: every element on its own)");
  app.add_option("--calls", fixedCalls, "run exactly N calls per loop (for callgrind) instead of timing");
  app.add_option("--min-time", minTime, "seconds per timed batch");
  CLI11_PARSE(app, argc, argv);

  const double inf = std::numeric_limits<double>::infinity();
  double parse = inf, check = inf, flatten = inf, derive = inf, dae = inf, kernel = inf, bytecode = inf, llvm = inf;
  double lower = inf, codegen = inf;
  size_t instructions = 0, residualInstructions = 0;
  uint32_t functions = 0;
  ModelPtr vmModel, jitModel;
  for (int r = 0; r < repeat; ++r) {
    vmModel.reset(), jitModel.reset();
    driver::Compilation c;
    c.options.jit = llvmbackend::JitOptions{};  // the defaults, as qdot run --jit-wait
    c.options.keepLoops = c.options.eliminateAlgebraics = c.options.rerollRows = loops;  // as qdot run (driver/main.cpp)
    if (!driver::compileFile(c, file, "", driver::Stage::Kernel)) {
      c.diags.render(std::cerr, c.sources);
      return 1;
    }
    const auto& t = c.times;
    parse = std::min(parse, t.parse), check = std::min(check, t.check), flatten = std::min(flatten, t.flatten);
    derive = std::min(derive, t.derive), dae = std::min(dae, t.dae), kernel = std::min(kernel, t.kernel);
    const kernel::KernelModule& kernels = *c.kernels;
    instructions = 0;
    for (const auto& p : kernels.programs) instructions += p.code.size();
    residualInstructions = kernels.program(ModelProgram::Residual).code.size();
    auto t0 = Clock::now();
    driver::continueTo(c, driver::Stage::Bytecode);
    Result<ModelPtr> vm = vm::createModel(*c.bytecode);
    bytecode = std::min(bytecode, secondsSince(t0));
    if (!vm) {
      std::cerr << vm.error() << "\n";
      return 1;
    }
    vmModel = std::move(vm).value();
    if (!noLlvm) {
      if (!driver::continueTo(c, driver::Stage::Native)) {
        std::cerr << c.internalError << "\n";
        return 1;
      }
      llvm = std::min(llvm, t.native);
      jitModel = std::move(c.native);
      const llvmbackend::JitStats& stats = c.jitStats;
      lower = std::min(lower, stats.lowerSeconds + stats.optimiseSeconds), codegen = std::min(codegen, stats.codegenSeconds);
      functions = 0;
      for (uint32_t f : stats.functions) functions += f;
    }
  }
  const QdotModel* vm = vmModel.get();
  const double front = parse + check + flatten + derive + dae;
  std::cout.precision(9);
  std::cout << "{\"variables\": " << vm->nVariables << ", \"nonzeros\": " << vm->jacobianNonzeros
            << ", \"instructions\": " << instructions << ", \"residualInstructions\": " << residualInstructions
            << ", \"stages\": {\"parse\": " << parse << ", \"check\": " << check << ", \"flatten\": " << flatten
            << ", \"derive\": " << derive << ", \"dae\": " << dae << ", \"kernel\": " << kernel
            << ", \"bytecode\": " << bytecode;
  if (!noLlvm) std::cout << ", \"llvm\": " << llvm << ", \"llvmLower\": " << lower << ", \"llvmCodegen\": " << codegen;
  std::cout << "}, \"frontEnd\": " << front << ", \"compileBytecode\": " << front + kernel + bytecode;
  if (!noLlvm) std::cout << ", \"compileLlvm\": " << front + kernel + llvm << ", \"functions\": " << functions;
  if (!noEval && !noLlvm) {
    const QdotModel* jit = jitModel.get();
    State a = fixedState(vm), b = fixedState(jit);
    calls<false>(vm, a, 1), calls<false>(jit, b, 1), calls<true>(vm, a, 1), calls<true>(jit, b, 1);
    std::cout << ", \"maxDiffF\": " << maxDiff(a.F, b.F) << ", \"maxDiffJ\": " << maxDiff(a.J, b.J);
    if (fixedCalls > 0) {
      evalVmResidual(vm, a, fixedCalls), evalJitResidual(jit, b, fixedCalls);
      evalVmJacobian(vm, a, fixedCalls), evalJitJacobian(jit, b, fixedCalls);
      std::cout << ", \"calls\": " << fixedCalls;
    } else {
      std::cout << ", \"residualNs\": {\"bytecode\": " << nsPerCall(evalVmResidual, vm, a, minTime)
                << ", \"llvm\": " << nsPerCall(evalJitResidual, jit, b, minTime) << "}, \"jacobianNs\": {\"bytecode\": "
                << nsPerCall(evalVmJacobian, vm, a, minTime) << ", \"llvm\": " << nsPerCall(evalJitJacobian, jit, b, minTime)
                << "}";
    }
  }
  std::cout << "}\n";
  return 0;
}
