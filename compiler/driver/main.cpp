// The qdot command line: subcommands over the Pipeline, diagnostics to stderr, exit codes
//   0 success, 1 the model has errors, 2 the command line is wrong.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

#include "ast/ASTPrinter.h"
#include "bytecode/Emitter.h"
#include "driver/Pipeline.h"
#include "kernel/Kernel.h"
#include "llvm/JitModel.h"
#include "llvm/ObjectFile.h"
#include "sim/Run.h"
#include "sim/TieredModel.h"
#include "vm/Vm.h"

namespace {

using namespace qdot;

struct Options {
  std::string file;
  std::string model;
  bool json = false;
  std::string emit;
  bool timings = false;
  std::string backend = "llvm";
  bool jitWait = false;  // --jit-wait
  rt::RunOptions run;
  std::string exePath;  // qdot build -o
  std::string buildBackend = "llvm";  // qdot build --backend
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

// How the JIT compiled (--stats).
void printJitStats(const llvmbackend::JitStats& jit) {
  uint32_t functions = 0;
  for (uint32_t f : jit.functions) functions += f;
  std::cerr << "jit: " << functions << " functions in " << jit.units << " modules on " << jit.threads
            << " threads in " << jit.wallSeconds * 1e3 << " ms; lower " << jit.lowerSeconds * 1e3
            << " ms, machine code " << jit.codegenSeconds * 1e3 << " ms (summed over threads), link "
            << jit.linkSeconds * 1e3 << " ms\n";
}

// --stats: the time of every compile stage, and how the JIT compiled.
void printCompileStats(const driver::StageTimes& t, double kernel, const std::string& backend, double codegen,
                       const llvmbackend::JitStats* jit) {
  double total = t.parse + t.check + t.flatten + t.derive + t.dae + kernel + codegen;
  std::cerr << "compile [ms]: parse " << t.parse * 1e3 << ", check " << t.check * 1e3 << ", flatten "
            << t.flatten * 1e3 << ", derive " << t.derive * 1e3 << ", dae " << t.dae * 1e3 << ", kernel "
            << kernel * 1e3 << ", codegen (" << backend << ") " << codegen * 1e3 << "; total " << total * 1e3 << "\n";
  if (jit) printJitStats(*jit);
}

rt::ExperimentDefaults experimentOf(const dae::Dae& d) {
  return {d.experiment.startTime, d.experiment.stopTime, d.experiment.interval, d.experiment.tolerance};
}

// What the JIT reports; shared with the compile thread when it runs in the background (read it
// after rt::finishTiering).
struct JitOutcome {
  llvmbackend::JitStats stats;
  std::string error;
};

// The model a run simulates, and how it was made.
struct CompiledModel {
  QdotModel* model = nullptr;
  std::string what;     // "bytecode", "llvm", "bytecode then llvm"
  bool waited = false;  // the JIT compiled before the run
  std::shared_ptr<JitOutcome> jit = std::make_shared<JitOutcome>();
  std::string error;    // why there is no model
};

// --backend llvm (default): the run starts on the VM while the JIT compiles on a background thread
// (rt::TieredModel), leaving one core to the solver; --jit-wait compiles first. --backend bytecode:
// the VM only. A JIT that fails leaves the run on the VM, with a warning.
CompiledModel compileModel(const kernel::KernelModule& kernels, const SourceManager& sources, const Options& o) {
  CompiledModel out;
  if (o.backend == "llvm" && o.jitWait) {
    out.model = llvmbackend::createJitModel(kernels, sources, llvmbackend::jitOptionsForRun(o.run.invariants), out.jit->error, &out.jit->stats);
    out.what = "llvm";
    out.waited = true;
    if (out.model) return out;
    std::cerr << "qdot: warning: the LLVM JIT failed (" << out.jit->error << "); running on the bytecode VM instead\n";
  }
  QdotModel* vmModel = vm::createModel(bytecode::emitBytecode(kernels, sources), out.error);
  out.what = "bytecode";
  out.waited = false;
  if (!vmModel || o.backend != "llvm" || o.jitWait) {
    out.model = vmModel;
    return out;
  }
  llvmbackend::JitOptions options = llvmbackend::jitOptionsForRun(o.run.invariants);
  options.threads = std::max(2u, std::thread::hardware_concurrency()) - 1;  // one core keeps solving
  out.what = "bytecode then llvm";
  out.model = rt::createTieredModel(vmModel, [&kernels, &sources, options, jit = out.jit](const std::atomic<bool>& cancel) {
    llvmbackend::JitOptions withCancel = options;
    withCancel.cancel = &cancel;
    return llvmbackend::createJitModel(kernels, sources, withCancel, jit->error, &jit->stats);
  });
  return out;
}

// After a tiered run: when the JIT was ready and how many calls each tier made (--stats), or why
// it never was. The JIT outcome is read only once the compile thread has finished.
void reportTiers(const rt::TierReport& tiers, const JitOutcome& jit, bool stats) {
  bool failed = !tiers.compiling && !tiers.ready && !jit.error.empty() && jit.error != "cancelled";
  if (failed) std::cerr << "qdot: warning: the LLVM JIT failed (" << jit.error << "); the run stayed on the bytecode VM\n";
  if (!stats) return;
  if (tiers.ready) {
    std::cerr << "jit: native code ready " << tiers.readySeconds * 1e3 << " ms after the VM started; "
              << tiers.firstTierCalls << " model calls on the VM, " << tiers.secondTierCalls << " on native code\n";
    printJitStats(jit.stats);
  } else if (!failed) {
    std::cerr << "jit: the run ended before the native code was ready (all " << tiers.firstTierCalls
              << " model calls on the VM)\n";
  }
}

// Compiles (JIT by default, or bytecode for the VM) and simulates. Exit codes: 0, 1 (model errors), 2 (usage),
// 3 (the solver or the model failed during the run; the rows computed so far are kept).
int runSimulate(const Options& o) {
  driver::Compilation c;
  if (!driver::compileFile(c, o.file, o.model, driver::Stage::Dae)) return finish(c, false);
  auto t0 = std::chrono::steady_clock::now();
  kernel::KernelModule kernels = kernel::buildKernels(*c.dae, c.ctx, c.diags);
  double kernelSeconds = secondsSince(t0);
  if (c.diags.hasErrors()) return finish(c, false);
  if (o.emit == "kernel") {
    kernel::printKernels(std::cout, kernels, &c.sources);
    return finish(c, true);
  }
  if (o.emit == "bytecode") {
    vm::disassemble(std::cout, bytecode::emitBytecode(kernels, c.sources));
    return finish(c, true);
  }
  t0 = std::chrono::steady_clock::now();
  CompiledModel compiled = compileModel(kernels, c.sources, o);
  double codegenSeconds = secondsSince(t0);
  if (!compiled.model) {
    std::cerr << "qdot: internal error: " << compiled.error << "\n";
    return 4;
  }
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  if (o.run.stats)
    printCompileStats(c.times, kernelSeconds, compiled.what, codegenSeconds, compiled.waited ? &compiled.jit->stats : nullptr);
  int code = rt::runModel(*compiled.model, o.run, experimentOf(*c.dae), std::cout, std::cerr);
  if (std::optional<rt::TierReport> tiers = rt::tierReport(compiled.model)) {
    reportTiers(*tiers, *compiled.jit, o.run.stats);
    if (tiers->compiling) {  // its code can no longer be used: exit without waiting for the compiler
      std::cout.flush();
      std::cerr.flush();
      std::fflush(nullptr);
      std::_Exit(code);
    }
  }
  compiled.model->destroy(compiled.model);
  return code;
}

#ifdef QDOT_EXE_LIBS
// qdot build: the model's bytecode, serialised into a generated C++ source file next to its
// experiment annotation (runtime/exe/Embedded.h), compiled and linked with the prebuilt runtime
// main (qdot_exe_main) and the static runtime libraries by the system C++ compiler. The paths
// are those of the build tree qdot was built in (QDOT_EXE_LIBS, QDOT_EXE_CXX).
std::vector<std::string> splitPaths(std::string_view text) {
  std::vector<std::string> out;
  std::size_t begin = 0;
  while (begin <= text.size()) {
    std::size_t end = text.find('|', begin);
    if (end == std::string_view::npos) end = text.size();
    if (end > begin) out.emplace_back(text.substr(begin, end - begin));
    begin = end + 1;
  }
  return out;
}

// native: the entry points and spill sizes of the object file, or null (the VM runs the model).
bool writeModelSource(const std::filesystem::path& path, const std::vector<uint8_t>& bytes, const dae::Dae& d,
                      const llvmbackend::ObjectFileInfo* native) {
  std::ofstream out(path);
  out << "// Generated by qdot build.\n#include <cstdint>\nextern \"C\" {\n";
  out << "typedef void (*qdot_program_fn)(const double*, const double*, const double*, const double*, const double*,"
         " const uint8_t*, double*, double*);\n";
  if (native) {
    for (const auto& name : native->entryNames) out << "void " << name << "(const double*, const double*, const double*,"
      " const double*, const double*, const uint8_t*, double*, double*);\n";
    out << "extern const qdot_program_fn qdot_native_programs[6] = {";
    for (const auto& name : native->entryNames) out << name << ',';
    out << "};\nextern const uint32_t qdot_native_spill[6] = {";
    for (uint32_t n : native->spillSlots) out << n << "u,";
    out << "};\n";
  } else {
    out << "extern const qdot_program_fn qdot_native_programs[6] = {};\n"
           "extern const uint32_t qdot_native_spill[6] = {};\n";
  }
  out << "extern const uint8_t qdot_model_bytes[] = {";
  for (std::size_t i = 0; i < bytes.size(); ++i) out << (i % 24 == 0 ? "\n" : "") << unsigned(bytes[i]) << ',';
  if (bytes.empty()) out << '0';
  out << "};\nextern const uint64_t qdot_model_size = " << bytes.size() << "u;\n";
  const auto& e = d.experiment;
  const std::optional<double>* fields[4] = {&e.startTime, &e.stopTime, &e.interval, &e.tolerance};
  out << "extern const double qdot_experiment_values[4] = {";
  out.precision(17);
  for (auto* f : fields) out << std::scientific << f->value_or(0.0) << ',';
  out << "};\nextern const uint8_t qdot_experiment_given[4] = {";
  for (auto* f : fields) out << (f->has_value() ? 1 : 0) << ',';
  out << "};\n}\n";
  return static_cast<bool>(out);
}

int spawnAndWait(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0) return -1;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int runBuild(const Options& o) {
  driver::Compilation c;
  if (!driver::compileFile(c, o.file, o.model, driver::Stage::Dae)) return finish(c, false);
  kernel::KernelModule kernels = kernel::buildKernels(*c.dae, c.ctx, c.diags);
  if (c.diags.hasErrors()) return finish(c, false);
  bc::Module module = bytecode::emitBytecode(kernels, c.sources);
  std::vector<uint8_t> bytes = bc::serialize(module);
  {  // the bytes must load exactly as the executable will load them
    std::string error;
    QdotModel* model = vm::createModelFromBytes(bytes, error);
    if (!model) {
      std::cerr << "qdot: internal error: " << error << "\n";
      return 1;
    }
    model->destroy(model);
  }
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any

  namespace fs = std::filesystem;
  std::string tmpl = (fs::temp_directory_path() / "qdot-build-XXXXXX").string();
  if (!mkdtemp(tmpl.data())) {
    std::cerr << "qdot: error: cannot create a temporary directory in " << fs::temp_directory_path() << "\n";
    return 1;
  }
  fs::path dir = tmpl;
  fs::path source = dir / "model.cpp";
  fs::path object = dir / "model.o";
  int code = 0;
  llvmbackend::ObjectFileInfo native;
  std::string error;
  bool llvm = o.buildBackend == "llvm";
  if (llvm && !llvmbackend::emitObjectFile(kernels, 2, object.string(), native, error)) {
    std::cerr << "qdot: internal error: " << error << "\n";
    code = 1;
  } else if (!writeModelSource(source, bytes, *c.dae, llvm ? &native : nullptr)) {
    std::cerr << "qdot: error: cannot write " << source << "\n";
    code = 1;
  } else {
    const char* cxx = std::getenv("QDOT_CXX");
    std::vector<std::string> args = {cxx && *cxx ? cxx : QDOT_EXE_CXX, "-std=c++20", "-x", "c++", source.string(),
                                     "-x", "none"};
    if (llvm) args.push_back(object.string());
    for (const auto& lib : splitPaths(QDOT_EXE_LIBS)) args.push_back(lib);
    args.insert(args.end(), {"-o", o.exePath});
    int status = spawnAndWait(args);
    if (status != 0) {
      std::cerr << "qdot: error: linking " << o.exePath << " failed (" << args[0]
                << (status < 0 ? " could not be run" : " exited with " + std::to_string(status))
                << "); qdot build needs the build tree qdot was built in\n";
      code = 1;
    }
  }
  std::error_code ignored;
  fs::remove_all(dir, ignored);
  return code;
}
#endif

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
  if (!first.empty() && first[0] != '-' && first != "check" && first != "equations" && first != "run" &&
      first != "build") {
    std::cerr << "qdot: unknown command '" << argv[1]
              << "'; the commands are: check, equations, run, build (see qdot --help)\n";
    return 2;
  }
  if (argc == 1) {
    std::cout << app.help();
    return 2;
  }
  auto* run = app.add_subcommand("run", "Simulate a model with SUNDIALS IDA and write the results as CSV");
  run->add_option("file", o.file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  run->add_option("--model", o.model, "the model (default: the last model in the file)");
  run->add_option("--backend", o.backend, "code generator: llvm (native code by the in-process JIT, default) or bytecode (the VM: no compile time)")
      ->check(CLI::IsMember({"bytecode", "llvm"}));
  run->add_flag("--jit-wait", o.jitWait,
                "with --backend llvm: compile before the first step instead of starting on the VM while the JIT "
                "compiles in the background (same results either way)");
  run->add_option("--emit", o.emit, "print a stage's output instead of running: kernel, bytecode")
      ->check(CLI::IsMember({"kernel", "bytecode"}));
  rt::addRunOptions(*run, o.run);

#ifdef QDOT_EXE_LIBS
  auto* build = app.add_subcommand(
      "build", "Compile a model into a standalone executable taking the run options of 'qdot run' (from the build tree)");
  build->add_option("file", o.file, "the model file (.qd)")->required()->check(CLI::ExistingFile);
  build->add_option("--model", o.model, "the model (default: the last model in the file)");
  build->add_option("-o,--output", o.exePath, "the executable to write")->required();
  build->add_option("--backend", o.buildBackend,
                    "code generator: llvm (native code, default) or bytecode (the VM, linked in)")
      ->check(CLI::IsMember({"bytecode", "llvm"}));
#endif

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
#ifdef QDOT_EXE_LIBS
    if (*build) return runBuild(o);
#endif
    return runEquations(o);
  } catch (const std::exception& e) {  // a bug, not a user error: say so instead of aborting
    std::cerr << "qdot: internal error: " << e.what() << "\n";
    return 4;
  }
}
