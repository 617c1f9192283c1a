// The qdot command line: parses the options, then one action per command over the driver library
// (Pipeline.h, Backends.h, Executable.h, Emit.h). Exit codes: qdot::ExitCode.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>

#include "dae/Dae.h"
#include "driver/Backends.h"
#include "driver/Emit.h"
#include "driver/Executable.h"
#include "driver/Modes.h"
#include "driver/Pipeline.h"
#include "driver/WorkPrecision.h"
#include "qdot/exit_code.hpp"
#include "sim/MemoryReuse.h"
#include "sim/Names.h"
#include "sim/Run.h"

namespace {

using namespace qdot;

enum class Action { Check, Equations, Run, Build, Modes, Linearize, WorkPrecision };

struct Options {
  std::string file;
  std::string model;
  std::string emit;      // --emit=STAGE: print that stage's output and stop
  std::string simplify = "fast";  // --simplify=none|fast|full
  bool json = false;     // equations --json
  bool timings = false;  // check/equations --timings
  bool quiet = false;    // check --quiet
  std::string backend = "llvm";
  bool jitWait = false;  // run --jit-wait
  bool noLoops = false;  // run --no-loops
  rt::RunOptions run;
  driver::WorkPrecisionOptions wp;
  driver::ExecutableOptions exe;
  std::string buildBackend = "llvm";
  std::string at = "equilibrium";  // modes/linearize --at
  std::vector<std::string> results;  // equations/build --outputs: compile only what these need
};

ExitCode finish(driver::Compilation& c, bool ok) {
  c.diags.render(std::cerr, c.sources, isatty(2));
  return ok ? ExitCode::Success : ExitCode::ModelError;
}

void printTimings(const driver::StageTimes& t) {
  std::cerr << "timings [ms]: parse " << t.parse * 1e3 << ", check " << t.check * 1e3 << ", flatten "
            << t.flatten * 1e3 << ", derive " << t.derive * 1e3 << ", dae " << t.dae * 1e3 << ", kernel "
            << t.kernel * 1e3 << "\n";
}

// Compiles to `until`. Values given with -p for Integer parameters (structural: they size arrays)
// are applied before flattening; the other -p values stay in o.run.parameters for the run.
// Returns false after a model error or a bad -p (then `code` says which).
bool compileTo(driver::Compilation& c, Options& o, driver::Stage until, ExitCode& code) {
  code = ExitCode::ModelError;
  if (o.run.parameters.empty() || until <= driver::Stage::Check) return driver::compileFile(c, o.file, until);
  if (!driver::compileFile(c, o.file, driver::Stage::Check)) return false;
  if (std::string error = driver::takeStructuralParameters(c, o.run.parameters); !error.empty()) {
    std::cerr << "error: " << error << "\n";
    code = ExitCode::Usage;
    return false;
  }
  return driver::continueTo(c, until);
}

// compileTo(Stage::Kernel) for the commands that go on to use the model: nullopt, or the exit
// code of the failure (its diagnostics printed).
std::optional<ExitCode> compileToKernels(driver::Compilation& c, Options& o) {
  ExitCode code;
  if (compileTo(c, o, driver::Stage::Kernel, code)) return std::nullopt;
  return code == ExitCode::Usage ? code : finish(c, false);
}

// --emit=STAGE: compile up to the stage, print its output, stop.
ExitCode emitStage(driver::Compilation& c, Options& o) {
  driver::EmitStage stage = *driver::parseEmitStage(o.emit);
  // What `qdot run` compiles, loops included (unless --no-loops), where the stage shown is past the DAE.
  c.options.keepLoops = driver::stageNeeded(stage) >= driver::Stage::Kernel && !o.noLoops;
  c.options.eliminateAlgebraics = c.options.keepLoops;
  c.options.rerollRows = c.options.keepLoops;
  c.options.keepInvariants = o.run.invariants;
  ExitCode failure;
  bool ok = compileTo(c, o, driver::stageNeeded(stage), failure) && driver::emit(c, stage, std::cout);
  if (!ok && failure == ExitCode::Usage) return failure;
  if (o.timings) printTimings(c.times);
  if (!ok && !c.internalError.empty()) {
    c.diags.render(std::cerr, c.sources, isatty(2));
    std::cerr << "qdot: internal error: " << c.internalError << "\n";
    return ExitCode::Internal;
  }
  return finish(c, ok);
}

// qdot check: every check that does not need the solver (up to the kernels), then one line.
ExitCode check(driver::Compilation& c, const Options& o) {
  bool ok = driver::compileFile(c, o.file, driver::Stage::Kernel);
  if (o.timings) printTimings(c.times);
  if (ok && !o.quiet) {
    const dae::Dae& d = *c.dae;
    std::cout << c.sources.name(c.ast->file) << ": model " << d.name << " is valid: " << d.equations.size()
              << " equations in " << d.variables.size() << " unknowns (" << d.stateCount() << " states, "
              << d.variables.size() - d.stateCount() << " algebraic), " << d.parameters.size() << " parameters\n";
  }
  return finish(c, ok);
}

// What --outputs kept (or why nothing was pruned).
void printPruning(const dae::PruneReport& r, std::ostream& os) {
  if (!r.unknownNames.empty()) {
    os << "\n--outputs: nothing pruned: no variable, output or invariant is named";
    for (const auto& n : r.unknownNames) os << " '" << n << "'";
    os << "\n";
    return;
  }
  os << "\n--outputs: kept " << r.variablesKept << " of " << r.variablesBefore << " unknowns and " << r.equationsKept
     << " of " << r.equationsBefore << " equations (what the requested results need; outputs and first integrals "
     << "not requested are left out)\n";
}

ExitCode equations(driver::Compilation& c, const Options& o) {
  c.options.results = o.results;
  bool ok = driver::compileFile(c, o.file, driver::Stage::Dae);
  if (ok && o.json) dae::printEquationsJson(std::cout, *c.dae, c.ctx, c.sources);
  else if (ok) dae::printEquations(std::cout, *c.dae, c.ctx, c.sources);
  if (ok && !o.results.empty()) printPruning(c.pruned, o.json ? std::cerr : std::cout);
  if (o.timings) printTimings(c.times);
  return finish(c, ok);
}

// --stats: the time of every compile stage, and how the JIT compiled.
void printCompileStats(const driver::StageTimes& t, const driver::RunnableModel& m) {
  std::cerr << "compile [ms]: parse " << t.parse * 1e3 << ", check " << t.check * 1e3 << ", flatten "
            << t.flatten * 1e3 << ", derive " << t.derive * 1e3 << ", dae " << t.dae * 1e3 << ", kernel "
            << t.kernel * 1e3 << ", codegen (" << m.what << ") " << m.codegenSeconds * 1e3 << "; total "
            << (t.frontEnd() + m.codegenSeconds) * 1e3 << "\n";
  if (m.waited) driver::printJitStats(m.jit->stats, std::cerr);
}

rt::ExperimentDefaults experimentOf(const flat::Experiment& e) {
  return {e.startTime, e.stopTime, e.interval, e.tolerance};
}

driver::Backend backendOf(const Options& o) {
  if (o.backend == "bytecode") return driver::Backend::Bytecode;
  return o.jitWait ? driver::Backend::Native : driver::Backend::Tiered;
}

// qdot run: compile (only what --outputs needs), simulate, write the CSV.
ExitCode run(driver::Compilation& c, Options& o) {
  c.options.results = o.run.outputs;
  c.options.keepInvariants = o.run.invariants;
  c.options.keepLoops = !o.noLoops;
  c.options.rerollRows = !o.noLoops;
  c.options.eliminateAlgebraics = true;
  c.options.releaseStages = true;
  if (std::optional<ExitCode> failed = compileToKernels(c, o)) return *failed;
  driver::RunnableModel m = driver::makeRunnableModel(c, backendOf(o), o.run.invariants);
  if (!m.model) {
    std::cerr << "qdot: internal error: " << m.error << "\n";
    return ExitCode::Internal;
  }
  if (!m.warning.empty()) std::cerr << "qdot: warning: " << m.warning << "\n";
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  if (o.run.stats) printCompileStats(c.times, m);
  if (o.run.stats && c.loops)
    std::cerr << (c.loops->empty() ? "loops: the model's repeated structure is compiled as loops\n"
                                   : "loops: the model's repeated structure is expanded to scalars: " + *c.loops + "\n");
  if (o.run.stats && c.componentsSummed)
    std::cerr << "loops: arrays of components: their energies are summed over the connections (the connectors' flows "
                 "are not computed: ask for one with --outputs to keep them)\n";
  if (o.run.stats && c.rerolled.blocks)
    std::cerr << "loops: " << c.rerolled.rows << " of the scalar rows repeat along arrays of unknowns: rerolled into "
              << c.rerolled.blocks << (c.rerolled.blocks == 1 ? " loop\n" : " loops\n");
  if (o.run.stats && c.rerolled.outputBlocks)
    std::cerr << "loops: " << c.rerolled.outputs << " outputs repeat along arrays of unknowns: computed by "
              << c.rerolled.outputBlocks << (c.rerolled.outputBlocks == 1 ? " loop\n" : " loops\n");
  if (o.run.stats && c.eliminated.eliminated)
    std::cerr << "system: " << c.eliminated.eliminated << " algebraic unknowns that their equations define "
              << "explicitly are solved out and computed with the results (qdot equations shows them)\n";
  ExitCode code = rt::runModel(*m.model, o.run, experimentOf(c.experiment), std::cout, std::cerr);
  std::optional<rt::TierReport> tiers = driver::reportTiers(m, o.run.stats, std::cerr);
  if (tiers && tiers->compiling) {
    // The background compile owns what it reads, so destroying the model (cancel and join) is
    // safe; but its code can no longer be used, so the process ends without waiting for it.
    std::cout.flush();
    std::cerr.flush();
    std::fflush(nullptr);
    std::_Exit(toInt(code));
  }
  return code;
}

// qdot build --outputs: every name a column of what was compiled (a variable, an output or a first
// integral), as `qdot run` and the executable's own --outputs check theirs: a typo is an error
// here, not an executable that silently keeps everything. "" if they all are.
std::string unknownResult(const ModelDescription& d, const std::vector<std::string>& names) {
  std::vector<std::string_view> columns;
  for (const auto* list : {&d.variableNames, &d.outputNames, &d.invariantNames}) columns.insert(columns.end(), list->begin(), list->end());
  for (const std::string& name : names)
    if (std::find(columns.begin(), columns.end(), name) == columns.end()) return rt::unknownNameMessage("output column", name, columns);
  return "";
}

ExitCode build(driver::Compilation& c, Options& o) {
  c.options.results = o.results;
  c.options.eliminateAlgebraics = true;  // the system `qdot run` integrates, with its loops
  c.options.keepLoops = true;
  c.options.rerollRows = true;
  c.options.keepInvariants = o.run.invariants;  // as qdot run --invariants
  c.options.releaseStages = true;  // what is built is the kernels, the bytecode and the experiment
  if (std::string why = driver::checkOutputPath(o.exe.outputPath); !why.empty()) {
    std::cerr << "qdot: error: cannot write the executable: " << why << "\n";
    return ExitCode::Usage;
  }
  if (std::optional<ExitCode> failed = compileToKernels(c, o)) return *failed;
  if (std::string why = unknownResult(c.kernels->description, o.results); !why.empty()) {
    std::cerr << "error: --outputs: " << why << "\n";
    return ExitCode::Usage;
  }
  if (!o.run.parameters.empty()) {
    std::cerr << "error: -p " << o.run.parameters.front() << ": qdot build takes values only for Integer parameters ("
              << (driver::structuralParameterList(c).empty() ? "this model has none" : driver::structuralParameterList(c))
              << "), which are fixed in the executable; the others stay run-time inputs: give them to the executable\n";
    return ExitCode::Usage;
  }
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  driver::ExecutableOptions exe = o.exe;
  exe.native = o.buildBackend == "llvm";
  return driver::buildExecutable(c, exe, std::cerr);
}

// qdot modes: natural frequencies, damping ratios and mode shapes.
ExitCode modes(driver::Compilation& c, Options& o) {
  if (std::optional<ExitCode> failed = compileToKernels(c, o)) return *failed;
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  auto at = o.at == "start" ? linear::OperatingPoint::Start : linear::OperatingPoint::Equilibrium;
  driver::ModesResult r = driver::computeModes(c, o.run.parameters, at);
  if (!r.error.empty()) {
    std::cerr << "error: " << r.error << "\n";
    return r.code;
  }
  if (o.json) linear::printModesJson(std::cout, r.system, r.modes);
  else linear::printModes(std::cout, r.system, r.modes);
  return ExitCode::Success;
}

// qdot linearize: the state-space matrices A, B, C, D about the operating point.
ExitCode linearize(driver::Compilation& c, Options& o) {
  if (std::optional<ExitCode> failed = compileToKernels(c, o)) return *failed;
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  auto at = o.at == "start" ? linear::OperatingPoint::Start : linear::OperatingPoint::Equilibrium;
  driver::LinearizeResult r = driver::linearizeModel(c, o.run.parameters, at);
  if (!r.error.empty()) {
    std::cerr << "error: " << r.error << "\n";
    return r.code;
  }
  if (o.json) linear::printStateSpaceJson(std::cout, r.model);
  else linear::printStateSpace(std::cout, r.model);
  return ExitCode::Success;
}

// qdot wp: the work-precision study (driver/WorkPrecision.h). -p is shared with compileTo, which
// takes the structural (Integer) assignments out of it.
ExitCode workPrecision(driver::Compilation& c, Options& o) {
  o.run.parameters = o.wp.run.parameters;
  c.options.eliminateAlgebraics = true;  // the system `qdot run` integrates
  if (std::optional<ExitCode> failed = compileToKernels(c, o)) return *failed;
  c.diags.render(std::cerr, c.sources, isatty(2));  // warnings, if any
  o.wp.run.parameters = o.run.parameters;
  return driver::workPrecision(c, o.file, o.wp, std::cout, std::cerr);
}

ExitCode dispatch(Action action, Options& o) {
  driver::Compilation c;
  c.options.model = o.model;
  sym::parseSimplifyLevel(o.simplify, c.options.simplify);  // checked by CLI11
  if (!o.emit.empty()) return emitStage(c, o);
  switch (action) {
    case Action::Check: return check(c, o);
    case Action::Equations: return equations(c, o);
    case Action::Run: return run(c, o);
    case Action::Build: return build(c, o);
    case Action::Modes: return modes(c, o);
    case Action::Linearize: return linearize(c, o);
    case Action::WorkPrecision: return workPrecision(c, o);
  }
  return ExitCode::Internal;
}

// The options every command takes: the file ("-" for standard input), --model, --emit.
CLI::App* addCommand(CLI::App& app, const char* name, const char* help, Options& o) {
  CLI::App* cmd = app.add_subcommand(name, help);
  cmd->add_option("file", o.file, "the model file (.qd), or - to read it from standard input")
      ->required()
      ->check(CLI::ExistingFile | CLI::IsMember({"-"}));
  cmd->add_option("--model", o.model, "the model (default: the last model in the file)");
  cmd->add_option("--emit", o.emit, "print a stage's output and stop: " + driver::emitStageList())
      ->check(CLI::IsMember(driver::emitStageNames()));
  cmd->add_option("--simplify", o.simplify,
                  "simplification of the derived equations: none, fast (default: within a budget) or full")
      ->check(CLI::IsMember({"none", "fast", "full"}));
  return cmd;
}

}  // namespace

int main(int argc, char** argv) {
  rt::reuseFreedMemory();  // the compiler's freed stages become the solver's memory (sim/MemoryReuse.h)
  CLI::App app{"qdot — a compiler for mechanics models (.qd): derives the equations of motion and solves them"};
  app.set_version_flag("--version", std::string("qdot ") + QDOT_VERSION);
  app.require_subcommand(1);
  Options o;

  auto* check = addCommand(app, "check", "Parse and check a model (every check short of solving it); print a summary", o);
  check->add_flag("--timings", o.timings, "print the time each stage took");
  check->add_flag("-q,--quiet", o.quiet, "print nothing on success");

  auto* eqs = addCommand(app, "equations", "Print the derived equations of motion and the DAE", o);
  eqs->add_flag("--json", o.json, "print JSON for tools instead of text");
  eqs->add_option("--outputs", o.results, "only what these results need: the equations and unknowns kept")
      ->delimiter(',');
  eqs->add_flag("--timings", o.timings, "print the time each stage took");

  auto* run = addCommand(app, "run", "Simulate a model with SUNDIALS IDA and write the results as CSV", o);
  run->add_option("--backend", o.backend, "code generator: llvm (native code by the in-process JIT, default) or bytecode (the VM: no compile time)")
      ->check(CLI::IsMember({"bytecode", "llvm"}));
  run->add_flag("--jit-wait", o.jitWait,
                "with --backend llvm: compile before the first step instead of starting on the VM while the JIT "
                "compiles in the background (same results either way)");
  run->add_flag("--no-loops", o.noLoops,
                "compile every array element on its own instead of keeping repeated structure as loops "
                "(for comparison and debugging: the results agree to rounding; docs/loops.md)");
  rt::addRunOptions(*run, o.run);
  run->get_option("-p")->description(
      "set a parameter: -p NAME=VALUE (repeatable). Integer parameters are structural (they size arrays): "
      "their values are applied before compiling; the others are run-time inputs");

  auto* build = addCommand(app, "build", "Compile a model into a standalone executable taking the run options of 'qdot run'", o);
  build->add_option("-o,--output", o.exe.outputPath, "the executable to write (required unless --emit)");
  build->add_option("-p,--parameter", o.run.parameters,
                    "NAME=VALUE for an Integer parameter (it sizes arrays, so it is fixed in the executable); "
                    "repeatable")
      ->allow_extra_args(false);
  build->add_option("--outputs", o.results,
                    "compile only what these results need (the executable then writes these columns)")
      ->delimiter(',');
  build->add_flag("--invariants", o.run.invariants,
                  "keep the first integrals (the Jacobi integral, conserved momenta) for the executable's "
                  "--invariants also when --outputs leaves out what they need");
  build->add_option("--backend", o.buildBackend, "code generator: llvm (native code, default) or bytecode (the VM, linked in)")
      ->check(CLI::IsMember({"bytecode", "llvm"}));

  auto* modesCmd = addCommand(app, "modes", "Natural frequencies, damping ratios and mode shapes of the linearized model", o);
  modesCmd->add_option("-p,--parameter", o.run.parameters, "set a parameter: -p NAME=VALUE (repeatable)")
      ->allow_extra_args(false);
  modesCmd->add_option("--at", o.at, "linearize about the static equilibrium nearest the start values (default) or the start state")
      ->check(CLI::IsMember({"equilibrium", "start"}));
  modesCmd->add_flag("--json", o.json, "print JSON for tools instead of text");

  auto* linearizeCmd = addCommand(app, "linearize", "State-space matrices A, B, C, D of the model linearized about an operating point (inputs: its 'input' variables)", o);
  linearizeCmd->add_option("-p,--parameter", o.run.parameters, "set a parameter or an input: -p NAME=VALUE (repeatable)")
      ->allow_extra_args(false);
  linearizeCmd->add_option("--at", o.at, "linearize about the static equilibrium nearest the start values (default) or the start state")
      ->check(CLI::IsMember({"equilibrium", "start"}));
  linearizeCmd->add_flag("--json", o.json, "print JSON for tools instead of CSV blocks");

  auto* wpCmd = addCommand(app, "wp", "Work-precision study: error and cost at a ladder of tolerances (table, CSV, SVG diagram)", o);
  driver::addWorkPrecisionOptions(*wpCmd, o.wp);

  std::string first = argc > 1 ? argv[1] : "";
  bool known = false;
  for (const CLI::App* cmd : app.get_subcommands({})) known = known || cmd->get_name() == first;
  if (!first.empty() && first[0] != '-' && !known) {
    std::cerr << "qdot: unknown command '" << first << "'; the commands are: check, equations, run, build, modes, linearize, wp (see qdot --help)\n";
    return toInt(ExitCode::Usage);
  }
  if (argc == 1) {
    std::cout << app.help();
    return toInt(ExitCode::Usage);
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    int code = app.exit(e);
    return code == 0 ? 0 : toInt(ExitCode::Usage);
  }
  Action action = *check ? Action::Check
                  : *eqs ? Action::Equations
                  : *run ? Action::Run
                  : *build ? Action::Build
                  : *modesCmd ? Action::Modes
                  : *linearizeCmd ? Action::Linearize
                  : Action::WorkPrecision;
  if (action == Action::Build && o.emit.empty() && o.exe.outputPath.empty()) {
    std::cerr << "qdot build: -o,--output is required (the executable to write)\nRun with --help for more information.\n";
    return toInt(ExitCode::Usage);
  }
  try {
    return toInt(dispatch(action, o));
  } catch (const std::exception& e) {  // a bug, not a user error: say so instead of aborting
    std::cerr << "qdot: internal error: " << e.what() << "\n";
    return toInt(ExitCode::Internal);
  }
}
