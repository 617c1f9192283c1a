// fillModelTable: the descriptive half of a QdotModel (name, sizes, variable/parameter/output/
// invariant names, id vector, Jacobian pattern) filled from a backend's module. Shared by the
// bytecode VM and the LLVM JIT (and the standalone executables after them), so they cannot drift.
// `Module` is any type with the fields used below (bc::Module and kernel::KernelModule have them).
#pragma once

#include <string>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot {

/// The C-string arrays a QdotModel points into; lives beside the model (and its module).
struct ModelNameTable {
  std::vector<const char*> variables, parameters, parameterDescriptions, outputs, invariants;
};

/// Points `m` at the names and pattern of `module`, which (like `names`) must outlive `m`.
template <class Module>
void fillModelTable(QdotModel& m, ModelNameTable& names, const Module& module) {
  auto cStrings = [](const std::vector<std::string>& strings) {
    std::vector<const char*> out;
    out.reserve(strings.size());
    for (const auto& s : strings) out.push_back(s.c_str());
    return out;
  };
  names = {cStrings(module.variableNames), cStrings(module.parameterNames), cStrings(module.parameterDescriptions),
           cStrings(module.outputNames), cStrings(module.invariantNames)};
  m.abiVersion = QDOT_MODEL_ABI_VERSION;
  m.name = module.name.c_str();
  m.nVariables = static_cast<uint32_t>(module.variableNames.size());
  m.nParameters = static_cast<uint32_t>(module.parameterNames.size());
  m.nOutputs = static_cast<uint32_t>(module.outputNames.size());
  m.nInvariants = static_cast<uint32_t>(module.invariantNames.size());
  m.variableNames = names.variables.data();
  m.isDifferential = module.isDifferential.data();
  m.parameterNames = names.parameters.data();
  m.parameterDescriptions = names.parameterDescriptions.data();
  m.outputNames = names.outputs.data();
  m.invariantNames = names.invariants.data();
  m.jacobianNonzeros = static_cast<uint32_t>(module.jacobianRowIndices.size());
  m.jacobianColumnStarts = module.jacobianColumnStarts.data();
  m.jacobianRowIndices = module.jacobianRowIndices.data();
}

}  // namespace qdot
