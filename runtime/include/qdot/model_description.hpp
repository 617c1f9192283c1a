// ModelDescription: the descriptive data of a compiled model (names, per-variable flags, the
// Jacobian's sparsity pattern), as opposed to its programs. Filled once by the kernel stage,
// carried unchanged by the bytecode module (and its serialised form), and pointed at by every
// backend's QdotModel table (qdot/model_table.hpp). Plain data; sizes are the name vectors' lengths.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "qdot/programs.hpp"

namespace qdot {

struct ModelDescription {
  std::string name;
  std::vector<std::string> variableNames;          ///< [nVariables], in result order
  std::vector<std::string> parameterNames;         ///< [nParameters]
  std::vector<std::string> parameterDescriptions;  ///< [nParameters], "" if none
  std::vector<std::string> outputNames, invariantNames;
  std::vector<int32_t> isDifferential;  ///< [nVariables]: 1 if y' of the variable appears
  std::vector<int32_t> fixed;           ///< [nVariables]: start value fixed during initialisation
  std::vector<int32_t> jacobianColumnStarts, jacobianRowIndices;  ///< CSC, column j = variable j
  /// The Integer parameters, as "n = 8": they size the model, so they are fixed in what was
  /// compiled (an executable's --help shows them; qdot build -p n=3 changes them).
  std::vector<std::string> structuralParameters;

  size_t variableCount() const { return variableNames.size(); }
  size_t parameterCount() const { return parameterNames.size(); }
  size_t jacobianNonzeros() const { return jacobianRowIndices.size(); }

  /// How many values program `p` writes for this model (initialValues: y0, yp0 and nominal).
  size_t outputCount(ModelProgram p) const {
    switch (p) {
      case ModelProgram::Parameters: return parameterCount();
      case ModelProgram::InitialValues: return 3 * variableCount();
      case ModelProgram::Residual: return variableCount();
      case ModelProgram::Jacobian: return jacobianNonzeros();
      case ModelProgram::Outputs: return outputNames.size();
      case ModelProgram::Invariants: return invariantNames.size();
    }
    return 0;
  }

  /// What is inconsistent (per-variable tables, parameter descriptions, the CSC pattern), "" if
  /// nothing: backends check this before pointing a QdotModel at the description.
  std::string inconsistency() const {
    size_t n = variableCount();
    if (isDifferential.size() != n || fixed.size() != n) return "per-variable tables have the wrong size";
    if (parameterDescriptions.size() != parameterCount()) return "parameter descriptions have the wrong size";
    const auto& starts = jacobianColumnStarts;
    const auto& rows = jacobianRowIndices;
    if (starts.size() != n + 1 || starts[0] != 0 || static_cast<size_t>(starts[n]) != rows.size())
      return "Jacobian column starts are inconsistent";
    for (size_t j = 0; j < n; ++j) {
      if (starts[j] > starts[j + 1]) return "Jacobian column starts decrease";
      for (int32_t k = starts[j]; k < starts[j + 1]; ++k)
        if (rows[k] < 0 || static_cast<size_t>(rows[k]) >= n || (k > starts[j] && rows[k] <= rows[k - 1]))
          return "Jacobian row indices out of range or not ascending in column " + std::to_string(j);
    }
    return "";
  }
};

}  // namespace qdot
