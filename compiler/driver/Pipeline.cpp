// Pipeline: parse → check → flatten → derive (Euler–Lagrange) → DAE → kernels → bytecode or
// native code, timing each stage. Each step is one function taking the Compilation and returning
// whether the stage succeeded; continueTo runs the ones not run yet.
#include "driver/Pipeline.h"

#include <chrono>
#include <iostream>
#include <iterator>

#include "bytecode/Emitter.h"
#include "syntax/Parser.h"

namespace qdot::driver {
namespace {

template <class F> auto timed(double& seconds, F&& f) {
  auto t0 = std::chrono::steady_clock::now();
  auto result = f();
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return result;
}

void reportMissingModel(Compilation& c, uint32_t file) {
  const std::string& model = c.options.model;
  if (model.empty()) {
    c.diags.error({file, 0, 0}, DiagCode::E0200, "this file declares no model", "declare one: model Name ... end Name;");
    return;
  }
  std::string names;
  for (const auto& cls : c.ast->classes)
    if (cls->kind == ast::ClassKind::Model) names += (names.empty() ? "" : ", ") + cls->name;
  c.diags.error({}, DiagCode::E0200, "there is no model named '" + model + "' in " + c.sources.name(file),
                names.empty() ? "the file declares no model" : "the file declares: " + names);
}

bool parse(Compilation& c, uint32_t file) {
  c.ast = timed(c.times.parse, [&] { return syntax::parse(c.sources, file, c.diags); });
  return c.ast && !c.diags.hasErrors();
}

bool check(Compilation& c) {
  c.checked = timed(c.times.check, [&] { return sema::checkModel(*c.ast, c.options.model, c.diags); });
  if (!c.checked) reportMissingModel(c, c.ast->file);
  return c.checked && !c.diags.hasErrors();
}

bool flatten(Compilation& c) {
  c.flat = timed(c.times.flatten, [&] { return flat::flatten(*c.checked, c.ctx, c.diags, c.options.limits); });
  return c.flat && !c.diags.hasErrors();
}

bool derive(Compilation& c) {
  c.eom = timed(c.times.derive, [&] { return mech::deriveEquationsOfMotion(*c.flat, c.ctx, c.diags); });
  return c.eom && !c.diags.hasErrors();
}

bool buildDae(Compilation& c) {
  c.dae = timed(c.times.dae, [&] { return dae::buildDae(*c.flat, *c.eom, c.ctx, c.diags); });
  return c.dae && !c.diags.hasErrors();
}

bool buildKernels(Compilation& c) {
  c.kernels = timed(c.times.kernel, [&] {
    return std::make_shared<const kernel::KernelModule>(kernel::buildKernels(*c.dae, c.ctx, c.diags));
  });
  return !c.diags.hasErrors();
}

bool emitBytecode(Compilation& c) {
  c.bytecode = timed(c.times.bytecode, [&] { return bytecode::emitBytecode(*c.kernels, c.sources); });
  return true;
}

// A JIT failure is not an error in the model: c.internalError says what failed.
bool compileNative(Compilation& c) {
  Result<ModelPtr> model =
      timed(c.times.native, [&] { return llvmbackend::createJitModel(*c.kernels, c.sources, c.options.jit, &c.jitStats); });
  if (!model) {
    c.internalError = "the LLVM JIT failed: " + model.error();
    return false;
  }
  c.native = std::move(model).value();
  return true;
}

// Runs stage `s` (whose predecessors have run).
bool runStage(Compilation& c, Stage s) {
  switch (s) {
    case Stage::Parse: return true;  // done by compileFile/compileSource
    case Stage::Check: return check(c);
    case Stage::Flatten: return flatten(c);
    case Stage::Derive: return derive(c);
    case Stage::Dae: return buildDae(c);
    case Stage::Kernel: return buildKernels(c);
    case Stage::Bytecode: return emitBytecode(c);
    case Stage::Native: return compileNative(c);
  }
  return false;
}

bool startFrom(Compilation& c, uint32_t file, Stage until) {
  c.ok = parse(c, file);
  c.reached = Stage::Parse;
  return continueTo(c, until);
}

}  // namespace

bool continueTo(Compilation& c, Stage until) {
  while (c.ok && c.reached < until) {
    Stage next = static_cast<Stage>(static_cast<int>(c.reached) + 1);
    if (next == Stage::Bytecode && until == Stage::Native) next = Stage::Native;  // the other backend
    c.ok = runStage(c, next);
    if (c.ok) c.reached = next;
  }
  if (c.ok && until == Stage::Bytecode && !c.bytecode) c.ok = emitBytecode(c);  // reached Native before
  return c.ok;
}

bool compileFile(Compilation& c, const std::string& path, Stage until) {
  uint32_t file = 0;
  if (path == kStandardInput) {
    std::string text(std::istreambuf_iterator<char>(std::cin), {});
    file = c.sources.addBuffer("<stdin>", std::move(text));
  } else if (std::string error; !c.sources.addFile(path, file, error)) {
    c.diags.error({}, DiagCode::E0001, error, "check the path of the model file");
    return c.ok = false;
  }
  return startFrom(c, file, until);
}

bool compileSource(Compilation& c, std::string name, std::string text, Stage until) {
  return startFrom(c, c.sources.addBuffer(std::move(name), std::move(text)), until);
}

bool compileFile(Compilation& c, const std::string& path, std::string_view model, Stage until) {
  c.options.model = model;
  return compileFile(c, path, until);
}

bool compileSource(Compilation& c, std::string name, std::string text, std::string_view model, Stage until) {
  c.options.model = model;
  return compileSource(c, std::move(name), std::move(text), until);
}

}  // namespace qdot::driver
