// The printers behind --emit, one per stage, each owned by its stage.
#include "driver/Emit.h"

#include "ast/ASTPrinter.h"
#include "dae/PrintDae.h"
#include "flatten/FlatPrinter.h"
#include "llvm/PrintIR.h"
#include "mechanics/EomPrinter.h"
#include "vm/Vm.h"

namespace qdot::driver {
namespace {

struct EmitEntry {
  EmitStage stage;
  const char* name;
  Stage needs;
};

constexpr EmitEntry kEmitStages[] = {
    {EmitStage::Ast, "ast", Stage::Parse},
    {EmitStage::Flat, "flat", Stage::Flatten},
    {EmitStage::Eom, "eom", Stage::Derive},
    {EmitStage::Dae, "dae", Stage::Dae},
    {EmitStage::Kernel, "kernel", Stage::Kernel},
    {EmitStage::Bytecode, "bytecode", Stage::Bytecode},
    {EmitStage::Llvm, "llvm", Stage::Kernel},  // printed from the kernels: no JIT needed
};

const EmitEntry& entry(EmitStage stage) {
  for (const auto& e : kEmitStages)
    if (e.stage == stage) return e;
  return kEmitStages[0];
}

}  // namespace

std::optional<EmitStage> parseEmitStage(std::string_view name) {
  for (const auto& e : kEmitStages)
    if (name == e.name) return e.stage;
  return std::nullopt;
}

std::vector<std::string> emitStageNames() {
  std::vector<std::string> names;
  for (const auto& e : kEmitStages) names.emplace_back(e.name);
  return names;
}

std::string emitStageList() {
  std::string list;
  for (const auto& e : kEmitStages) list += (list.empty() ? "" : ", ") + std::string(e.name);
  return list;
}

Stage stageNeeded(EmitStage stage) { return entry(stage).needs; }

bool emit(Compilation& c, EmitStage stage, std::ostream& os) {
  switch (stage) {
    case EmitStage::Ast: ast::printAST(os, *c.ast, c.sources); return true;
    case EmitStage::Flat: flat::printFlatModel(os, *c.flat, c.ctx, c.sources); return true;
    case EmitStage::Eom: mech::printEquationsOfMotion(os, *c.eom, *c.flat, c.ctx, c.sources); return true;
    case EmitStage::Dae: dae::printDae(os, *c.dae, c.ctx, c.sources); return true;
    case EmitStage::Kernel: kernel::printKernels(os, *c.kernels, &c.sources); return true;
    case EmitStage::Bytecode: vm::disassemble(os, *c.bytecode); return true;
    case EmitStage::Llvm:  // the module the JIT and qdot build compile, split as qdot run splits it
      llvmbackend::printIR(os, *c.kernels, c.options.jit.maxInstructionsPerFunction);
      return true;
  }
  return false;
}

}  // namespace qdot::driver
