// ModelDescription: the descriptive data of a compiled model (names, per-variable flags, the
// Jacobian's sparsity pattern), as opposed to its programs. Filled once by the kernel stage,
// carried unchanged by the bytecode module (and its serialised form), and pointed at by every
// backend's QdotModel table (qdot/model_table.hpp). Plain data; sizes are the name vectors' lengths.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "qdot/csc_pattern.hpp"
#include "qdot/programs.hpp"

namespace qdot {

/// Values of ModelDescription::fixed: a guess, fixed by default (a state's start), fixed as written
/// (`fixed = true`, or set by an initial equation). Any non-zero value is fixed.
inline constexpr int32_t kStartGuess = 0, kFixedByDefault = 1, kFixedAsWritten = 2;

struct ModelDescription {
  std::string name;
  std::vector<std::string> variableNames;          ///< [nVariables], in result order
  std::vector<std::string> parameterNames;         ///< [nParameters]
  std::vector<std::string> parameterDescriptions;  ///< [nParameters], "" if none
  std::vector<std::string> outputNames, invariantNames;
  std::vector<int32_t> outputKinds;  ///< [nOutputs]: 0 plain, 1 angle, 2 first of a z-x-z triple (model_abi.h)
  std::vector<int32_t> isDifferential;  ///< [nVariables]: 1 if y' of the variable appears
  std::vector<int32_t> fixed;           ///< [nVariables]: start value fixed during initialisation (kFixed…)
  std::vector<int32_t> jacobianColumnStarts, jacobianRowIndices;  ///< CSC, column j = variable j
  /// The Integer parameters, as "n = 8": they size the model, so they are fixed in what was
  /// compiled (an executable's --help shows them; qdot build -p n=3 changes them).
  std::vector<std::string> structuralParameters;
  /// Index reduction (empty for a model of index ≤ 1). Triplets (row, variable, derivative): row
  /// says der(variable) = derivative. Per differentiated equation (differentiatedRowStarts, size
  /// count + 1, into differentiatedRows): its rows e, e', e'', … The residual then has
  /// residualCount() rows; the run time keeps all but dummyDerivativeCount() links.
  std::vector<int32_t> derivativeLinks;
  std::vector<int32_t> differentiatedRowStarts, differentiatedRows;
  /// Rows of F that hold only at t0 (initial equations that are not start values), the last rows,
  /// with a label each for messages ("initial equation x + der(x) = 3").
  std::vector<int32_t> initialRows;
  std::vector<std::string> initialRowLabels;

  size_t variableCount() const { return variableNames.size(); }
  size_t parameterCount() const { return parameterNames.size(); }
  size_t jacobianNonzeros() const { return jacobianRowIndices.size(); }
  size_t differentiatedEquationCount() const {
    return differentiatedRowStarts.empty() ? 0 : differentiatedRowStarts.size() - 1;
  }
  /// Derivatives of equations in the system: as many links are dropped (dummy derivatives).
  size_t dummyDerivativeCount() const { return differentiatedRows.size() - differentiatedEquationCount(); }
  /// Rows of F: one per variable, plus one per dummy derivative, plus the initial rows.
  size_t residualCount() const { return variableCount() + dummyDerivativeCount() + initialRows.size(); }

  /// How many values program `p` writes for this model (initialValues: y0, yp0 and nominal).
  size_t outputCount(ModelProgram p) const {
    switch (p) {
      case ModelProgram::Parameters: return parameterCount();
      case ModelProgram::InitialValues: return 3 * variableCount();
      case ModelProgram::Residual: return residualCount();
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
    if (auto problem = indexReductionInconsistency(); !problem.empty()) return problem;
    const auto& starts = jacobianColumnStarts;
    const auto& rows = jacobianRowIndices;
    if (starts.size() != n + 1 || starts[0] != 0 || static_cast<size_t>(starts[n]) != rows.size())
      return "Jacobian column starts are inconsistent";
    size_t rowsEnd = residualCount();
    if (cscPatternValid(starts.data(), rows.data(), n, rows.size(), rowsEnd)) return "";
    for (size_t j = 0; j < n; ++j) {  // which problem, for the message
      if (starts[j] > starts[j + 1]) return "Jacobian column starts decrease";
      if (static_cast<size_t>(starts[j + 1]) > rows.size()) return "Jacobian column starts exceed the nonzeros";
      for (int32_t k = starts[j]; k < starts[j + 1]; ++k)
        if (rows[k] < 0 || static_cast<size_t>(rows[k]) >= rowsEnd || (k > starts[j] && rows[k] <= rows[k - 1]))
          return "Jacobian row indices out of range or not ascending in column " + std::to_string(j);
    }
    return "";
  }

  /// What is inconsistent in the index reduction tables, "" if nothing.
  std::string indexReductionInconsistency() const {
    if (derivativeLinks.size() % 3 != 0) return "derivative links are not triplets";
    const auto& starts = differentiatedRowStarts;
    if (!starts.empty() && (starts[0] != 0 || static_cast<size_t>(starts.back()) != differentiatedRows.size()))
      return "differentiated row starts are inconsistent";
    for (size_t k = 0; k + 1 < starts.size(); ++k)
      if (starts[k + 1] - starts[k] < 2) return "a differentiated equation has fewer than two rows";
    size_t rowsEnd = residualCount();
    if (initialRowLabels.size() != initialRows.size()) return "initial rows and their labels differ in number";
    if (outputKinds.size() != outputNames.size()) return "output kinds and output names differ in number";
    for (size_t k = 0; k < outputKinds.size(); ++k)
      if (outputKinds[k] < 0 || outputKinds[k] > 2 || (outputKinds[k] == 2 && k + 2 >= outputKinds.size()))
        return "an output kind is out of range";
    for (size_t k = 0; k < initialRows.size(); ++k)
      if (static_cast<size_t>(initialRows[k]) != residualCount() - initialRows.size() + k)
        return "the initial rows are not the last rows";
    for (int32_t r : differentiatedRows)
      if (r < 0 || static_cast<size_t>(r) >= rowsEnd) return "a differentiated row is out of range";
    for (size_t k = 0; k < derivativeLinks.size(); k += 3)
      if (derivativeLinks[k] < 0 || static_cast<size_t>(derivativeLinks[k]) >= rowsEnd || derivativeLinks[k + 1] < 0 ||
          static_cast<size_t>(derivativeLinks[k + 1]) >= variableCount() || derivativeLinks[k + 2] < 0 ||
          static_cast<size_t>(derivativeLinks[k + 2]) >= variableCount())
        return "a derivative link is out of range";
    return "";
  }
};

/// The one ModelDescription of a compiled model, shared by what carries it: the kernels, the bytecode
/// module made from them, and the models built from either. A model of 10⁶ masses has about 140 MB
/// of names, flags and pattern; the tiered run keeps the kernels (for the background JIT) and the
/// VM's module alive together, and with copies it held two. Copying shares; edit() copies first if
/// the description is shared (so a copy edited, as tests do, never changes another's), and is for
/// whoever builds a module, before it is handed on: not thread-safe against concurrent copies.
class SharedDescription {
 public:
  SharedDescription() : d_(std::make_shared<ModelDescription>()) {}
  explicit SharedDescription(ModelDescription d) : d_(std::make_shared<ModelDescription>(std::move(d))) {}
  const ModelDescription& operator*() const { return *d_; }
  const ModelDescription* operator->() const { return d_.get(); }
  operator const ModelDescription&() const { return *d_; }  // NOLINT: reads as the description itself
  /// The description to change: this holder's own (copied first if another holder shares it).
  ModelDescription& edit() {
    if (d_.use_count() > 1) d_ = std::make_shared<ModelDescription>(*d_);
    return *d_;
  }
  /// Whether two holders share one description (tests; what the tiered run relies on).
  bool sharesWith(const SharedDescription& other) const { return d_ == other.d_; }

 private:
  std::shared_ptr<ModelDescription> d_;
};

}  // namespace qdot
