// The qdot command line: subcommands over the Pipeline, diagnostics to stderr, exit codes
//   0 success, 1 the model has errors, 2 the command line is wrong.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <iostream>

#include "ast/ASTPrinter.h"
#include "bytecode/Emitter.h"
#include "driver/Pipeline.h"
#include "kernel/Kernel.h"
#include "llvm/JitModel.h"
#include "sim/Run.h"
#include "vm/Vm.h"

namespace {

using namespace qdot;

struct Options {
  std::string file;
  std::string model;
  bool json = false;
  std::string emit;
  bool timings = false;
  std::string backend = "bytecode";
  rt::RunOptions run;
};

double secondsSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

int finish(driver::Compilation& c, bool ok) {
  c.diags.render(std::cerr, c.sources, isatty(2));
  return ok ? 0 : 1;
}

void printTimings(const driver::StageTimes& t) {
  std::cerr << "timings [ms]: parse " << t.parse * 1e3 << ", check " << t.check * 1e3 << ", flatten "
            << t.flatten * 1e3 << ", derive " << t.derive * 1e3 << ", dae " << t.dae * 1e3 << "\n";
}

int runCheck(const Options& o) {
  driver::Compilation c;
  bool ok = driver::compileFile(c, o.file, o.model, o.emit == "ast" ? driver::Stage::Parse : driver::Stage::Dae);
  if (ok && o.emit == "ast") ast::printAST(std::cout, *c.ast, c.sources);
  if (o.timings) printTimings(c.times);
  return finish(c, ok);
}

int runEquations(const Options& o) {
  driver::Compilation c;
  bool ok = driver::compileFile(c, o.file, o.model, driver::Stage::Dae);
  if (ok) {
    if (o.json) dae::printEquationsJson(std::cout, *c.dae, c.ctx, c.sources);
    else dae::printEquations(std::cout, *c.dae, c.ctx, c.sources);
  }
  if (o.timings) printTimings(c.times);
  return finish(c, ok);
}

rt::ExperimentDefaults experimentOf(const dae::Dae& d) {
  return {d.experiment.startTime, d.experiment.stopTime, d.experiment.interval, d.experiment.tolerance};
}

// Compiles to bytecode and simulates on the VM. Exit codes: 0, 1 (model errors), 2 (usage),
// 3 (the solver or the model failed during the run; the rows computed so far are kept).
int runSimulate(const Options& o) {
  driver::Compilation c;
  if (!driver::compileFile(c, o.file, o.model, driver::Stage::Dae)) return finish(c, false);
  auto t0 = std::chrono::steady_clock::now();
  kernel::KernelModule kernels = kernel::buildKernels(*c.dae, c.ctx);
  double kernelSeconds = secondsSince(t0);
  for (const auto& e : kernels.errors) c.diags.error(c.dae->range, "E0601", e);
  if (!kernels.errors.empty()) return finish(c, false);
  if (o.emit == "kernel") {
    kernel::printKernels(std::cout, kernels, &c.sources);
    return finish(c, true);
  }
  t0 = std::chrono::steady_clock::now();
  std::string error;
  QdotModel* model = nullptr;
  if (o.backend == "llvm" && o.emit.empty()) {
    model = llvmbackend::createJitModel(kernels, c.sources, 2, error);
  } else {
    bc::Module module = bytecode::emitBytecode(kernels, c.sources);
    if (o.emit == "bytecode") {
      vm::disassemble(std::cout, module);
      return finish(c, true);
    }
    model = vm::createModel(module, error);
  }
  double codegenSeconds = secondsSince(t0);
  if (!model) {
    std::cerr << "qdot: internal error: " << error << "\n";
    return 1;
  }
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  if (o.run.stats) {
    const auto& t = c.times;
    std::cerr << "compile [ms]: parse " << t.parse * 1e3 << ", check " << t.check * 1e3 << ", flatten "
              << t.flatten * 1e3 << ", derive " << t.derive * 1e3 << ", dae " << t.dae * 1e3 << ", kernel "
              << kernelSeconds * 1e3 << ", codegen (" << o.backend << ") " << codegenSeconds * 1e3 << "\n";
  }
  int code = rt::runModel(*model, o.run, experimentOf(*c.dae), std::cout, std::cerr);
  model->destroy(model);
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"qdot — a compiler for mechanics models (.qd): derives the equations of motion and solves them"};
  app.set_version_flag("--version", std::string("qdot ") + QDOT_VERSION);
  app.require_subcommand(1);
  Options o;

  auto* check = app.add_subcommand("check", "Parse and check a model; print diagnostics (exit 1 on errors)");
  check->add_option("file", o.file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  check->add_option("--model", o.model, "the model to check (default: the last model in the file)");
  check->add_option("--emit", o.emit, "also print a stage's output: ast")->check(CLI::IsMember({"ast"}));
  check->add_flag("--timings", o.timings, "print the time each stage took");

  auto* eqs = app.add_subcommand("equations", "Print the derived equations of motion and the DAE");
  eqs->add_option("file", o.file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  eqs->add_option("--model", o.model, "the model (default: the last model in the file)");
  eqs->add_flag("--json", o.json, "print JSON for tools instead of text");
  eqs->add_flag("--timings", o.timings, "print the time each stage took");

  std::string first = argc > 1 ? argv[1] : "";
  if (!first.empty() && first[0] != '-' && first != "check" && first != "equations" && first != "run") {
    std::cerr << "qdot: unknown command '" << argv[1] << "'; the commands are: check, equations, run (see qdot --help)\n";
    return 2;
  }
  if (argc == 1) {
    std::cout << app.help();
    return 2;
  }
  auto* run = app.add_subcommand("run", "Simulate a model with SUNDIALS IDA and write the results as CSV");
  run->add_option("file", o.file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  run->add_option("--model", o.model, "the model (default: the last model in the file)");
  run->add_option("--backend", o.backend, "code generator: bytecode (the VM, default) or llvm (JIT)")
      ->check(CLI::IsMember({"bytecode", "llvm"}));
  run->add_option("--emit", o.emit, "print a stage's output instead of running: kernel, bytecode")
      ->check(CLI::IsMember({"kernel", "bytecode"}));
  rt::addRunOptions(*run, o.run);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    return 2;
  }
  try {
    if (*check) return runCheck(o);
    if (*run) return runSimulate(o);
    return runEquations(o);
  } catch (const std::exception& e) {  // a bug, not a user error: say so instead of aborting
    std::cerr << "qdot: internal error: " << e.what() << "\n";
    return 4;
  }
}
