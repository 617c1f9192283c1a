// The model ABI on top of the interpreter: one register file per function (constants preloaded at
// creation); the entry points come from ModelAdapter, this file only runs a function and, if a
// result is not finite, stores the diagnosis for lastError and returns 1.
#include <algorithm>
#include <cmath>

#include "qdot/model_adapter.hpp"
#include "vm/Interpreter.h"
#include "vm/Vm.h"

namespace qdot::vm {
namespace {

struct VmModel : AdaptedModel {
  bc::Module module;
  mutable std::array<std::vector<double>, bc::kFunctionCount> registers;

  /// Runs one function; a non-finite result is traced to its equation for lastError.
  int run(ModelProgram program, const ModelCall& in, double* out) const {
    auto id = static_cast<bc::FunctionId>(program);
    const bc::Function& f = module.function(id);
    double* r = registers[static_cast<int>(id)].data();
    execute(f, r, in, out);
    for (uint32_t i = 0; i < f.outputCount; ++i)
      if (!std::isfinite(out[i])) {
        error = diagnose(module, id, r, in, out);
        return 1;
      }
    return 0;
  }
};

static_assert(static_cast<int>(bc::FunctionId::Invariants) == static_cast<int>(ModelProgram::Invariants),
              "bc::FunctionId must number the programs in model-ABI order");

}  // namespace

QdotModel* createModel(const bc::Module& module, std::string& error) {
  if (!bc::validate(module, error)) return nullptr;
  auto* m = new VmModel();
  m->module = module;
  for (uint32_t f = 0; f < bc::kFunctionCount; ++f) m->registers[f] = makeRegisters(m->module.functions[f]);
  ModelAdapter<VmModel>::install(*m, m->module);
  return m;
}

QdotModel* createModelFromBytes(std::span<const uint8_t> bytes, std::string& error) {
  bc::Module module;
  if (!bc::deserialize(bytes, module, error)) return nullptr;
  return createModel(module, error);
}

}  // namespace qdot::vm
