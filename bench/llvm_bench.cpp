// qdot_llvm_bench: compile-time and run-time measurements of the LLVM backend (README.md).
//   qdot_llvm_bench FILE.qd [n] [optLevel] [maxInstructionsPerFunction] [pipelineLevel] [threads] [mask] [jacobianOptLevel]
// Compiles through the driver's pipeline (overriding `Integer n = ...` with n if given), then JIT-compiles the kernels
// and prints the compile phases, and the residual evaluation time of the JIT and the bytecode VM.
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <optional>
#include <regex>
#include <sstream>

#include "driver/Pipeline.h"
#include "vm/Vm.h"

using namespace qdot;
using Clock = std::chrono::steady_clock;

static double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Nanoseconds per residual (or Jacobian) call (repeats until ~0.3 s have passed).
static double residualNs(const QdotModel* q, const std::vector<double>& p, bool jacobian = false) {
  size_t n = q->nVariables;
  std::vector<double> y(n), yp(n), F(std::max<size_t>(n, q->jacobianNonzeros));
  for (size_t i = 0; i < n; ++i) y[i] = 0.01 * (i % 17), yp[i] = 0.02 * (i % 5);
  size_t calls = 0;
  auto start = Clock::now();
  double elapsed = 0;
  do {
    for (int r = 0; r < 16; ++r, ++calls)
      if (jacobian) q->jacobian(q, 0.1, y.data(), yp.data(), p.data(), 10.0, F.data());
      else q->residual(q, 0.1, y.data(), yp.data(), p.data(), F.data());
    elapsed = since(start);
  } while (elapsed < 0.3);
  return elapsed / calls * 1e9;
}

int main(int argc, char** argv) {
  if (argc < 2) {
    std::cerr << "usage: qdot_llvm_bench FILE.qd [n] [optLevel] [maxInstructionsPerFunction] [pipelineLevel] [threads] [compiledPrograms mask] [jacobianOptLevel]\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  if (argc > 2) text = std::regex_replace(text, std::regex("Integer n = [0-9]+"), std::string("Integer n = ") + argv[2]);
  llvmbackend::JitOptions options;
  if (argc > 3) options.optLevel = std::atoi(argv[3]);
  if (argc > 4) options.maxInstructionsPerFunction = static_cast<uint32_t>(std::atol(argv[4]));
  if (argc > 5) options.pipelineLevel = std::atoi(argv[5]);
  if (argc > 6) options.threads = static_cast<unsigned>(std::atoi(argv[6]));
  if (argc > 7) options.compiledPrograms = static_cast<uint32_t>(std::atoi(argv[7]));
  if (argc > 8) options.jacobianOptLevel = std::atoi(argv[8]);

  auto t0 = Clock::now();
  driver::Compilation c;
  c.options.jit = options;
  if (!driver::compileSource(c, argv[1], text, "", driver::Stage::Kernel)) {
    c.diags.render(std::cerr, c.sources);
    return 1;
  }
  double frontEnd = since(t0);
  const kernel::KernelModule& k = *c.kernels;
  size_t instructions = 0;
  for (const auto& p : k.programs) instructions += p.code.size();

  auto t1 = Clock::now();
  bool compiled = driver::continueTo(c, driver::Stage::Native);
  double total = since(t1);
  if (!compiled) {
    std::cerr << c.internalError << "\n";
    return 1;
  }
  const llvmbackend::JitStats& stats = c.jitStats;
  auto t2 = Clock::now();
  driver::continueTo(c, driver::Stage::Bytecode);
  Result<ModelPtr> vmModel = vm::createModel(*c.bytecode);
  double vmBuild = since(t2);
  if (!vmModel) {
    std::cerr << vmModel.error() << "\n";
    return 1;
  }
  ModelPtr jitModel = std::move(c.native);
  QdotModel *jit = jitModel.get(), *vm = vmModel->get();

  std::vector<double> p(jit->nParameters);
  jit->parameters(jit, nullptr, nullptr, p.data());
  uint32_t functions = 0;
  for (uint32_t f : stats.functions) functions += f;
  std::cout << "n=" << (argc > 2 ? argv[2] : "-") << " O" << options.optLevel << " pipeline O" << (options.pipelineLevel >= 0 ? options.pipelineLevel : options.optLevel) << " split " << options.maxInstructionsPerFunction << " variables=" << jit->nVariables
            << " instructions=" << instructions << " residual=" << k.program(ModelProgram::Residual).code.size()
            << " functions=" << functions << " frontend=" << frontEnd << "s jit=" << total
            << "s (lower " << stats.lowerSeconds << " opt " << stats.optimiseSeconds << " codegen "
            << stats.codegenSeconds << " link " << stats.linkSeconds << ", " << stats.units << " units on " << stats.threads
            << " threads) vmbuild=" << vmBuild << "s";
  if (jit->nVariables <= 20000)
    std::cout << " residual_ns jit=" << residualNs(jit, p) << " vm=" << residualNs(vm, p)
              << " jacobian_ns jit=" << residualNs(jit, p, true) << " vm=" << residualNs(vm, p, true);
  std::cout << "\n";
  return 0;
}
