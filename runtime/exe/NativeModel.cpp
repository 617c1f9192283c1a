// NativeModel: `run` calls the native program and checks its outputs; everything else of the ABI
// is ModelAdapter's, as for the VM and the JIT.
#include "exe/NativeModel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "qdot/bytecode.h"
#include "qdot/model_adapter.hpp"
#include "vm/Vm.h"

namespace qdot::exe {
namespace {

struct NativeModel : AdaptedModel {
  ModelPtr vm;                   // the same module on the VM: the programs that run once, the diagnosis of failures
  const bc::Module* module = nullptr;  // the VM's: names and pattern the table points into, index tables
  PerProgram<qdot_program_fn> programs{};
  mutable PerProgram<std::vector<double>> spill;

  int run(ModelProgram program, const ModelCall& c, double* out) const {
    size_t i = programIndex(program);
    if (!programs[i]) {  // a program that runs once (parameters, start values): the VM's
      int status = callProgram(*vm, program, c, out);
      if (status != 0) error = vm->lastError(vm.get());
      return status;
    }
    ModelCall call = c;
    call.indexTable = module->functions[i].indexTable.data();  // the native code reads it through the call
    programs[i](&call, out, spill[i].data());
    size_t count = module->description->outputCount(program);
    if (std::all_of(out, out + count, [](double x) { return std::isfinite(x); })) return 0;
    std::vector<double> scratch(count);  // the VM fails the same way and says where
    error = callProgram(*vm, program, c, scratch.data()) != 0 ? vm->lastError(vm.get()) : "a value is not finite";
    return 1;
  }
};

}  // namespace

Result<ModelPtr> createNativeModel(std::span<const uint8_t> bytes, const qdot_program_fn programs[kModelProgramCount],
                                   const uint32_t spill[kModelProgramCount]) {
  auto m = std::make_unique<NativeModel>();
  Result<ModelPtr> vm = vm::createModelFromBytes(bytes);
  if (!vm) return Error{vm.error()};
  m->vm = std::move(vm).value();
  m->module = &vm::moduleOf(*m->vm);
  for (size_t i = 0; i < kModelProgramCount; ++i) {
    m->programs[i] = programs[i];
    m->spill[i].assign(spill[i], 0.0);
  }
  ModelAdapter<NativeModel>::install(*m, m->module->description);
  return ModelPtr(m.release());
}

const bc::Module& moduleOf(const QdotModel& model) { return *static_cast<const NativeModel&>(model).module; }

}  // namespace qdot::exe
