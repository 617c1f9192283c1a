// The qdot command line: subcommands over the Pipeline, diagnostics to stderr, exit codes
//   0 success, 1 the model has errors, 2 the command line is wrong.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <iostream>

#include "ast/ASTPrinter.h"
#include "driver/Pipeline.h"

namespace {

using namespace qdot;

struct Options {
  std::string file;
  std::string model;
  bool json = false;
  std::string emit;
  bool timings = false;
};

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
  if (!first.empty() && first[0] != '-' && first != "check" && first != "equations") {
    std::cerr << "qdot: unknown command '" << argv[1] << "'; the commands are: check, equations (see qdot --help)\n";
    return 2;
  }
  if (argc == 1) {
    std::cout << app.help();
    return 2;
  }
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
  if (*check) return runCheck(o);
  return runEquations(o);
}
