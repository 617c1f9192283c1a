// fillModelTable: the descriptive half of a QdotModel (name, sizes, variable/parameter/output/
// invariant names, id vector, Jacobian pattern) pointed at a ModelDescription. Shared by the
// bytecode VM, the LLVM JIT and the standalone executables, so they cannot drift.
#pragma once

#include <string>
#include <vector>

#include "qdot/model_abi.h"
#include "qdot/model_description.hpp"

namespace qdot {

/// The C-string arrays a QdotModel points into; lives beside the model (and its description).
struct ModelNameTable {
  std::vector<const char*> variables, parameters, parameterDescriptions, outputs, invariants, initialRows;
};

/// Points `m` at the names and pattern of `d`, which (like `names`) must outlive `m`.
inline void fillModelTable(QdotModel& m, ModelNameTable& names, const ModelDescription& d) {
  auto cStrings = [](const std::vector<std::string>& strings) {
    std::vector<const char*> out;
    out.reserve(strings.size());
    for (const auto& s : strings) out.push_back(s.c_str());
    return out;
  };
  names = {cStrings(d.variableNames), cStrings(d.parameterNames), cStrings(d.parameterDescriptions),
           cStrings(d.outputNames), cStrings(d.invariantNames), cStrings(d.initialRowLabels)};
  m.abiVersion = QDOT_MODEL_ABI_VERSION;
  m.name = d.name.c_str();
  m.nVariables = static_cast<uint32_t>(d.variableNames.size());
  m.nParameters = static_cast<uint32_t>(d.parameterNames.size());
  m.nOutputs = static_cast<uint32_t>(d.outputNames.size());
  m.nInvariants = static_cast<uint32_t>(d.invariantNames.size());
  m.variableNames = names.variables.data();
  m.isDifferential = d.isDifferential.data();
  m.parameterNames = names.parameters.data();
  m.parameterDescriptions = names.parameterDescriptions.data();
  m.outputNames = names.outputs.data();
  m.invariantNames = names.invariants.data();
  m.jacobianNonzeros = static_cast<uint32_t>(d.jacobianRowIndices.size());
  m.jacobianColumnStarts = d.jacobianColumnStarts.data();
  m.jacobianRowIndices = d.jacobianRowIndices.data();
  m.nResiduals = static_cast<uint32_t>(d.residualCount());
  m.nDerivativeLinks = static_cast<uint32_t>(d.derivativeLinks.size() / 3);
  m.derivativeLinks = d.derivativeLinks.data();
  m.nDifferentiatedEquations = static_cast<uint32_t>(d.differentiatedEquationCount());
  m.differentiatedRowStarts = d.differentiatedRowStarts.data();
  m.differentiatedRows = d.differentiatedRows.data();
  m.nInitialRows = static_cast<uint32_t>(d.initialRows.size());
  m.initialRowLabels = names.initialRows.data();
  m.outputKinds = d.outputKinds.data();
}

}  // namespace qdot
