// The main of a standalone model executable (`qdot build`): the model is linked in as serialised
// bytecode (qdot_model_bytes, written by `qdot build` into a generated source file) and run on
// the VM, or, when the build linked compiled programs (--backend llvm), on those (NativeModel.h),
// with the same run options and CSV as `qdot run`. Exit codes as `qdot run`: 0, 2 (bad
// command line), 3 (the run failed). Linked from the static library qdot_exe_main.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cstdint>
#include <iostream>
#include <span>
#include <string>

#include "exe/Embedded.h"
#include "exe/NativeModel.h"
#include "sim/Names.h"
#include "sim/Run.h"
#include "vm/Vm.h"

namespace {

using namespace qdot;

rt::ExperimentDefaults embeddedExperiment() {
  rt::ExperimentDefaults e;
  std::optional<double>* fields[4] = {&e.start, &e.stop, &e.interval, &e.tolerance};
  for (int i = 0; i < 4; ++i)
    if (qdot_experiment_given[i]) *fields[i] = qdot_experiment_values[i];
  return e;
}

// "Parameters" section of --help: name = default, description (defaults evaluated with nothing
// overridden, so a default depending on another parameter shows its value).
std::string parameterHelp(const QdotModel& model) {
  if (model.nParameters == 0) return "";
  std::vector<double> given(model.nParameters, 0.0), p(model.nParameters, 0.0);
  std::vector<uint8_t> overridden(model.nParameters, 0);
  bool ok = model.parameters(&model, given.data(), overridden.data(), p.data()) == 0;
  std::size_t width = 0;
  std::vector<std::string> heads;
  for (uint32_t i = 0; i < model.nParameters; ++i) {
    std::string head = ok ? fmt::format("{} = {:g}", model.parameterNames[i], p[i]) : model.parameterNames[i];
    width = std::max(width, head.size());
    heads.push_back(head);
  }
  std::string text = "Parameters (change with -p NAME=VALUE; defaults shown):\n";
  for (uint32_t i = 0; i < model.nParameters; ++i) {
    const char* description = model.parameterDescriptions ? model.parameterDescriptions[i] : "";
    text += fmt::format("  {:<{}}  {}\n", heads[i], width, description ? description : "");
  }
  return text;
}

// The Integer parameters the executable was built with: shown by --help; -p cannot change them.
std::string structuralHelp(const std::vector<std::string>& fixed) {
  if (fixed.empty()) return "";
  std::string text = "\nFixed when built (Integer parameters size the model; rebuild with qdot build -p NAME=VALUE):\n";
  for (const auto& f : fixed) text += "  " + f + "\n";
  return text;
}

// A -p naming one of them: a usage error that says why and what to do, or "".
std::string structuralAssignment(const std::vector<std::string>& fixed, const std::vector<std::string>& assignments) {
  for (const auto& a : assignments)
    for (const auto& f : fixed) {
      std::string name = f.substr(0, f.find(" = "));
      if (a.substr(0, a.find('=')) == name)
        return "-p " + a + ": '" + name + "' is an Integer parameter that sizes the model, fixed when this executable "
               "was built (" + f + "); rebuild it with qdot build -p " + a;
    }
  return "";
}

}  // namespace

int main(int argc, char** argv) {
  std::span<const uint8_t> bytes(qdot_model_bytes, qdot_model_size);
  // Native code for the programs that run per step, or none (built with --backend bytecode).
  bool native = std::any_of(qdot_native_programs, qdot_native_programs + kModelProgramCount,
                            [](qdot_program_fn f) { return f != nullptr; });
  Result<ModelPtr> created = native
                                 ? exe::createNativeModel(bytes, qdot_native_programs, qdot_native_spill)
                                 : vm::createModelFromBytes(bytes);
  if (!created) {
    std::cerr << "error: the embedded model is invalid: " << created.error() << "\n";
    return toInt(ExitCode::Internal);
  }
  QdotModel* model = created->get();
  CLI::App app{fmt::format("{}: a qdot model; simulates it with SUNDIALS IDA and writes the results as CSV",
                           model->name ? model->name : "model")};
  rt::RunOptions options;
  rt::addRunOptions(app, options);
  Result<bc::Module> module = bc::deserialize(bytes);
  std::vector<std::string> fixed = module ? module->description.structuralParameters : std::vector<std::string>{};
  app.footer(parameterHelp(*model) + structuralHelp(fixed));
  int code = 0;
  try {
    app.parse(argc, argv);
    if (std::string why = structuralAssignment(fixed, options.parameters); !why.empty()) {
      std::cerr << "error: " << why << "\n";
      return toInt(ExitCode::Usage);
    }
    code = toInt(rt::runModel(*model, options, embeddedExperiment(), std::cout, std::cerr));
  } catch (const CLI::CallForHelp& e) {
    code = app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);
    code = toInt(ExitCode::Usage);
  } catch (const std::exception& e) {
    std::cerr << "error: internal error: " << e.what() << "\n";
    code = toInt(ExitCode::Internal);
  }
  return code;
}
