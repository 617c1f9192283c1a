// The main of a standalone model executable (`qdot build`): the model is linked in as serialised
// bytecode (qdot_model_bytes, written by `qdot build` into a generated source file) and run on
// the VM, or, when the build linked compiled programs (--backend llvm), on those (NativeModel.h),
// with the same run options and CSV as `qdot run`. Exit codes as `qdot run`: 0, 2 (bad
// command line), 3 (the run failed). Linked from the static library qdot_exe_main.
#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "exe/Embedded.h"
#include "exe/NativeModel.h"
#include "sim/MemoryReuse.h"
#include "sim/Names.h"
#include "sim/Run.h"
#include "vm/Runs.h"
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

// Parameter names as templates and numbers (the serialised form's split, vm/Runs.h): name i is
// template templateOf[i] with the numbers from first[i] on.
struct SplitNames {
  bc::runs::StringTemplates t;
  std::vector<size_t> first;

  explicit SplitNames(const QdotModel& model)
      : t(bc::runs::splitStrings(std::vector<std::string>(model.parameterNames, model.parameterNames + model.nParameters))) {
    for (size_t i = 0, at = 0; i < t.templateOf.size(); at += t.templates[t.templateOf[i++]].size() - 1) first.push_back(at);
  }
  const bc::runs::StringTemplates::Template& parts(size_t i) const { return t.templates[t.templateOf[i]]; }
  uint32_t number(size_t i, size_t k) const { return t.numbers[first[i] + k]; }

  // The one number in which name j follows name i (j's is i's + step, the rest alike), or -1.
  int followingNumber(size_t i, size_t j, uint32_t step) const {
    if (t.templateOf[i] != t.templateOf[j]) return -1;
    int k = -1;
    for (size_t n = 0; n + 1 < parts(i).size(); ++n) {
      if (number(i, n) == number(j, n)) continue;
      if (k >= 0 || number(j, n) != number(i, n) + step) return -1;
      k = static_cast<int>(n);
    }
    return k;
  }
};

// "Parameters" section of --help: name = default, description (defaults evaluated with nothing
// overridden, so a default depending on another parameter shows its value). Runs of three or more
// that differ in one number only, counting up, with one default and one description (the
// members of a component array: `links[2].k`, …, `links[n].k`) are one line, `links[2..n].k = 1000`:
// a model of 10⁵ parts would otherwise list 4·10⁵ lines.
std::string parameterHelp(const QdotModel& model) {
  if (model.nParameters == 0) return "";
  std::vector<double> given(model.nParameters, 0.0), p(model.nParameters, 0.0);
  std::vector<uint8_t> overridden(model.nParameters, 0);
  bool ok = model.parameters(&model, given.data(), overridden.data(), p.data()) == 0;
  auto description = [&](uint32_t i) -> std::string_view {
    const char* d = model.parameterDescriptions ? model.parameterDescriptions[i] : "";
    return d ? d : "";
  };
  auto sameDefault = [&](uint32_t i, uint32_t j) { return !ok || p[i] == p[j] || (std::isnan(p[i]) && std::isnan(p[j])); };
  std::vector<std::pair<std::string, std::string_view>> lines;  // head, description
  SplitNames names(model);
  for (uint32_t i = 0; i < model.nParameters;) {
    int k = i + 1 < model.nParameters ? names.followingNumber(i, i + 1, 1) : -1;
    uint32_t j = i + 1;
    while (k >= 0 && j < model.nParameters && names.followingNumber(i, j, j - i) == k && sameDefault(i, j) &&
           description(j) == description(i))
      ++j;
    if (j - i < 3) j = i + 1;
    std::string name(model.parameterNames[i]);
    if (j - i > 1) {  // the varying number as first..last
      const auto& parts = names.parts(i);
      name = parts[0];
      for (size_t n = 0; n + 1 < parts.size(); ++n) {
        uint32_t v = names.number(i, n);
        name += static_cast<int>(n) == k ? fmt::format("{}..{}", v, v + (j - i - 1)) : std::to_string(v);
        name += parts[n + 1];
      }
    }
    lines.emplace_back(ok ? fmt::format("{} = {:g}", name, p[i]) : name, description(i));
    i = j;
  }
  std::size_t width = 0;
  for (const auto& line : lines) width = std::max(width, line.first.size());
  std::string text = "Parameters (change with -p NAME=VALUE; defaults shown):\n";
  for (const auto& [head, what] : lines) text += fmt::format("  {:<{}}  {}\n", head, width, what);
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
  rt::reuseFreedMemory();  // reading the module frees what the solver then needs (sim/MemoryReuse.h)
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
  // The module the model already read (not a second copy: a large model's is most of the process).
  const bc::Module& module = native ? exe::moduleOf(*model) : vm::moduleOf(*model);
  const std::vector<std::string>& fixed = module.description->structuralParameters;
  app.footer([&] {  // made for --help only; CLI11 adds a newline after it
    std::string help = parameterHelp(*model) + structuralHelp(fixed);
    if (help.ends_with('\n')) help.pop_back();
    return help;
  });
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
