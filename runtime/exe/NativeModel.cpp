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
  bc::Module module;        // names and pattern the table points into
  QdotModel* vm = nullptr;  // the same module on the VM, for the diagnosis of failures
  std::array<qdot_program_fn, bc::kFunctionCount> programs{};
  mutable std::array<std::vector<double>, bc::kFunctionCount> spill;

  NativeModel() = default;
  NativeModel(const NativeModel&) = delete;
  ~NativeModel() {
    if (vm) vm->destroy(vm);
  }

  int run(ModelProgram program, const ModelCall& c, double* out) const {
    auto i = static_cast<size_t>(program);
    const double tcj[2] = {c.t, c.cj};
    programs[i](tcj, c.y, c.yp, c.p, c.given, c.overridden, out, spill[i].data());
    size_t count = programOutputCount(*this, program);
    if (std::all_of(out, out + count, [](double x) { return std::isfinite(x); })) return 0;
    std::vector<double> scratch(count);  // the VM fails the same way and says where
    error = callProgram(*vm, program, c, scratch.data()) != 0 ? vm->lastError(vm) : "a value is not finite";
    return 1;
  }
};

}  // namespace

QdotModel* createNativeModel(std::span<const uint8_t> bytes, const qdot_program_fn programs[6],
                             const uint32_t spill[6], std::string& error) {
  auto m = std::make_unique<NativeModel>();
  if (!bc::deserialize(bytes, m->module, error) || !(m->vm = vm::createModel(m->module, error))) return nullptr;
  for (size_t i = 0; i < bc::kFunctionCount; ++i) {
    m->programs[i] = programs[i];
    m->spill[i].assign(spill[i], 0.0);
  }
  ModelAdapter<NativeModel>::install(*m, m->module);
  return m.release();
}

}  // namespace qdot::exe
