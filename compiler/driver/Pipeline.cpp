// Pipeline: parse → check → flatten → derive (Euler–Lagrange) → DAE, timing each stage.
#include "driver/Pipeline.h"

#include <chrono>

#include "flatten/Flatten.h"
#include "syntax/Parser.h"

namespace qdot::driver {
namespace {

template <class F> auto timed(double& seconds, F&& f) {
  auto t0 = std::chrono::steady_clock::now();
  auto result = f();
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

bool runStages(Compilation& c, uint32_t file, std::string_view model, Stage until) {
  c.ast = timed(c.times.parse, [&] { return syntax::parse(c.sources, file, c.diags); });
  if (c.diags.hasErrors() || until == Stage::Parse) return !c.diags.hasErrors();
  c.checked = timed(c.times.check, [&] { return sema::checkModel(*c.ast, model, c.diags); });
  if (!c.checked) {
    if (model.empty()) {
      c.diags.error({file, 0, 0}, DiagCode::E0200, "this file declares no model", "declare one: model Name ... end Name;");
    } else {
      std::string names;
      for (const auto& cls : c.ast->classes)
        if (cls->kind == ast::ClassKind::Model) names += (names.empty() ? "" : ", ") + cls->name;
      c.diags.error({}, DiagCode::E0200, "there is no model named '" + std::string(model) + "' in " + c.sources.name(file),
                    names.empty() ? "the file declares no model" : "the file declares: " + names);
    }
    return false;
  }
  if (c.diags.hasErrors() || until == Stage::Check) return !c.diags.hasErrors();
  c.flat = timed(c.times.flatten, [&] { return flat::flatten(*c.checked, c.ctx, c.diags, c.limits); });
  if (!c.flat || until == Stage::Flatten) return c.flat.has_value() && !c.diags.hasErrors();
  c.eom = timed(c.times.derive, [&] { return mech::deriveEquationsOfMotion(*c.flat, c.ctx, c.diags); });
  if (!c.eom || until == Stage::Derive) return c.eom.has_value() && !c.diags.hasErrors();
  c.dae = timed(c.times.dae, [&] { return dae::buildDae(*c.flat, *c.eom, c.ctx, c.diags); });
  return c.dae.has_value() && !c.diags.hasErrors();
}

}  // namespace

bool compileFile(Compilation& c, const std::string& path, std::string_view model, Stage until) {
  uint32_t file = 0;
  std::string error;
  if (!c.sources.addFile(path, file, error)) {
    c.diags.error({}, DiagCode::E0001, error, "check the path of the model file");
    return false;
  }
  return runStages(c, file, model, until);
}

bool compileSource(Compilation& c, std::string name, std::string text, std::string_view model, Stage until) {
  uint32_t file = c.sources.addBuffer(std::move(name), std::move(text));
  return runStages(c, file, model, until);
}

}  // namespace qdot::driver
