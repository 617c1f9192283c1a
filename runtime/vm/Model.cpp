// The model ABI on top of the interpreter: one register file per function (constants preloaded at
// creation); the entry points come from ModelAdapter, this file only runs a function and, if a
// result is not finite, stores the diagnosis (qdot/non_finite.hpp) for lastError and returns 1.
#include <cmath>

#include "qdot/model_adapter.hpp"
#include "qdot/non_finite.hpp"
#include "vm/Interpreter.h"
#include "vm/Vm.h"

namespace qdot::vm {
namespace {

struct VmModel : AdaptedModel {
  bc::Module module;
  mutable PerProgram<std::vector<double>> registers;

  /// Runs one function; a non-finite result is traced to its equation for lastError.
  int run(ModelProgram program, const ModelCall& in, double* out) const {
    const bc::Function& f = module.function(program);
    execute(f, registers[programIndex(program)].data(), in, out);
    for (uint32_t i = 0; i < f.outputCount; ++i)
      if (!std::isfinite(out[i])) {
        error = diagnoseNonFinite(module.description, module.locations, program, traceOf(f), in);
        return 1;
      }
    return 0;
  }
};

// A model of a module that validates.
ModelPtr modelOfValid(bc::Module module) {
  auto m = std::make_unique<VmModel>();
  m->module = std::move(module);
  for (size_t f = 0; f < kModelProgramCount; ++f) m->registers[f] = makeRegisters(m->module.functions[f]);
  ModelAdapter<VmModel>::install(*m, m->module.description);
  return ModelPtr(m.release());
}

}  // namespace

Result<ModelPtr> createModel(bc::Module module) {
  if (Status valid = bc::validate(module); !valid) return Error{valid.error()};
  return modelOfValid(std::move(module));
}

const bc::Module& moduleOf(const QdotModel& model) { return static_cast<const VmModel&>(model).module; }

Result<ModelPtr> createModelFromBytes(std::span<const uint8_t> bytes) {
  Result<bc::Module> module = bc::deserialize(bytes);  // validates (once: a large module's code is long)
  if (!module) return Error{module.error()};
  return modelOfValid(std::move(module).value());
}

}  // namespace qdot::vm
