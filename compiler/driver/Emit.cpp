// The printers behind --emit, one per stage, each owned by its stage.
#include "driver/Emit.h"

#include "ast/ASTPrinter.h"
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
    {EmitStage::Kernel, "kernel", Stage::Kernel},
    {EmitStage::Bytecode, "bytecode", Stage::Bytecode},
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
    case EmitStage::Kernel: kernel::printKernels(os, *c.kernels, &c.sources); return true;
    case EmitStage::Bytecode: vm::disassemble(os, *c.bytecode); return true;
  }
  return false;
}

}  // namespace qdot::driver
