// Validation of a QdotModel table: version, required functions, name arrays and the CSC pattern
// (monotone column starts, row indices in range and strictly ascending within a column).
#include "ida/ModelCheck.h"

#include <fmt/format.h>

#include <algorithm>

#include "qdot/csc_pattern.hpp"

namespace qdot::rt {
namespace {

std::optional<std::string> checkFunctions(const QdotModel& m) {
  if (!m.parameters) return "it has no parameters function";
  if (!m.initialValues) return "it has no initialValues function";
  if (!m.residual) return "it has no residual function";
  if (!m.jacobian) return "it has no jacobian function";
  if (m.nOutputs > 0 && !m.outputs) return "it declares outputs but has no outputs function";
  if (m.nInvariants > 0 && !m.invariants) return "it declares invariants but has no invariants function";
  return std::nullopt;
}

std::optional<std::string> checkArrays(const QdotModel& m) {
  if (m.nVariables > 0 && (!m.variableNames || !m.isDifferential)) return "its variable arrays are missing";
  if (m.nParameters > 0 && !m.parameterNames) return "its parameter names are missing";
  if (m.nOutputs > 0 && !m.outputNames) return "its output names are missing";
  if (m.nInvariants > 0 && !m.invariantNames) return "its invariant names are missing";
  return std::nullopt;
}

std::optional<std::string> checkColumn(const QdotModel& m, uint32_t column) {
  int32_t begin = m.jacobianColumnStarts[column];
  int32_t end = m.jacobianColumnStarts[column + 1];
  if (begin > end) return fmt::format("Jacobian column {} has a negative length", column);
  if (static_cast<uint32_t>(end) > m.jacobianNonzeros) return fmt::format("Jacobian column {} ends past the nonzeros", column);
  for (int32_t k = begin; k < end; ++k) {
    int32_t row = m.jacobianRowIndices[k];
    if (row < 0 || static_cast<uint32_t>(row) >= std::max(m.nResiduals, m.nVariables))
      return fmt::format("Jacobian column {} has row index {} out of range", column, row);
    if (k > begin && row <= m.jacobianRowIndices[k - 1])
      return fmt::format("Jacobian column {} has row indices that are not strictly ascending", column);
  }
  return std::nullopt;
}

std::optional<std::string> checkPattern(const QdotModel& m) {
  if (m.nVariables == 0) return std::nullopt;
  if (!m.jacobianColumnStarts || (m.jacobianNonzeros > 0 && !m.jacobianRowIndices))
    return "its Jacobian pattern is missing";
  if (m.jacobianColumnStarts[0] != 0 ||
      m.jacobianColumnStarts[m.nVariables] != static_cast<int64_t>(m.jacobianNonzeros))
    return "its Jacobian column starts do not span the nonzeros";
  if (m.nResiduals != 0 && m.nResiduals < m.nVariables) return "it has fewer residuals than variables";
  if (m.nResiduals > m.nVariables + m.nInitialRows && (m.nDerivativeLinks == 0 || m.nDifferentiatedEquations == 0))
    return "it has more residuals than variables but no index reduction tables";
  if (cscPatternValid(m.jacobianColumnStarts, m.jacobianRowIndices, m.nVariables, m.jacobianNonzeros,
                      std::max(m.nResiduals, m.nVariables)))
    return std::nullopt;
  for (uint32_t column = 0; column < m.nVariables; ++column)  // which problem, for the message
    if (auto problem = checkColumn(m, column)) return problem;
  return "its Jacobian column starts exceed the nonzeros";
}

}  // namespace

std::optional<std::string> checkModel(const QdotModel& model) {
  if (model.abiVersion != QDOT_MODEL_ABI_VERSION)
    return fmt::format("the model was compiled for model ABI version {}, this runtime implements version {}",
                       model.abiVersion, QDOT_MODEL_ABI_VERSION);
  for (auto check : {checkFunctions, checkArrays, checkPattern})
    if (auto problem = check(model)) return fmt::format("the model table is invalid: {}", *problem);
  return std::nullopt;
}

std::string modelLastError(const QdotModel& model) {
  if (!model.lastError) return "";
  const char* text = model.lastError(&model);
  return text ? std::string(text) : std::string();
}

std::vector<std::string_view> nameList(const char* const* names, uint32_t count) {
  std::vector<std::string_view> list;
  list.reserve(count);
  for (uint32_t i = 0; i < count; ++i)
    list.emplace_back(names && names[i] ? names[i] : "");
  return list;
}

}  // namespace qdot::rt
