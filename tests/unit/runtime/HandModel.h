// HandModel: a QdotModel written by hand in C++ for the runtime tests (no compiler involved).
// A test fills in names, start values, the Jacobian pattern as (row, column) entries and lambdas
// for the residual and the analytic Jacobian; abi() then hands out the C table.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot::rt::test {

/// Writes Jacobian values by (row, column) into the CSC slots of a HandModel's pattern.
class JacobianValues {
 public:
  JacobianValues(const std::vector<int32_t>& starts, const std::vector<int32_t>& rows, double* values)
      : starts_(starts), rows_(rows), values_(values) {}
  /// The slot of entry (row, column); throws if the pattern lacks it.
  double& operator()(int row, int column) {
    auto begin = rows_.begin() + starts_[column], end = rows_.begin() + starts_[column + 1];
    auto it = std::lower_bound(begin, end, row);
    if (it == end || *it != row) throw std::logic_error("Jacobian entry outside the pattern");
    return values_[it - rows_.begin()];
  }

 private:
  const std::vector<int32_t>& starts_;
  const std::vector<int32_t>& rows_;
  double* values_;
};

class HandModel {
 public:
  using Residual = std::function<int(double t, const double* y, const double* yp, const double* p, double* F)>;
  using Jacobian =
      std::function<int(double t, const double* y, const double* yp, const double* p, double cj, JacobianValues& J)>;
  using Extra = std::function<int(double t, const double* y, const double* yp, const double* p, double* out)>;

  std::string name = "hand";
  std::vector<std::string> variables;
  std::vector<int32_t> differential;
  std::vector<std::string> parameterNames;
  std::vector<double> parameterDefaults;
  std::vector<std::string> outputNames;
  std::vector<std::string> invariantNames;
  std::vector<double> start;                 ///< y0 (y'0 = 0)
  std::vector<double> nominal;               ///< empty = all 0 (automatic)
  std::vector<int32_t> fixed;                ///< empty = differential fixed, algebraic free
  std::vector<std::pair<int, int>> entries;  ///< Jacobian pattern as (row, column)
  Residual residual;
  Jacobian jacobian;
  Extra outputs;
  Extra invariants;
  std::string lastError;
  uint32_t abiVersion = QDOT_MODEL_ABI_VERSION;

  /// The C table (built on first use; the HandModel must stay put and outlive it).
  const QdotModel& abi() {
    if (!built_) build();
    return table_.abi;
  }

  const std::vector<int32_t>& columnStarts() const { return starts_; }
  const std::vector<int32_t>& rowIndices() const { return rows_; }

 private:
  struct Table {
    QdotModel abi;
    HandModel* owner;
  };

  static HandModel& self(const QdotModel* m) { return *reinterpret_cast<const Table*>(m)->owner; }

  static std::vector<const char*> pointers(const std::vector<std::string>& names) {
    std::vector<const char*> out;
    for (const auto& n : names)
      out.push_back(n.c_str());
    return out;
  }

  void buildPattern() {
    std::vector<std::pair<int, int>> byColumn;
    for (auto [r, c] : entries)
      byColumn.emplace_back(c, r);
    std::sort(byColumn.begin(), byColumn.end());
    byColumn.erase(std::unique(byColumn.begin(), byColumn.end()), byColumn.end());
    starts_.assign(variables.size() + 1, 0);
    rows_.clear();
    for (auto [c, r] : byColumn) {
      ++starts_[c + 1];
      rows_.push_back(r);
    }
    for (std::size_t c = 0; c < variables.size(); ++c)
      starts_[c + 1] += starts_[c];
  }

  void build() {
    built_ = true;
    buildPattern();
    varPtrs_ = pointers(variables);
    parPtrs_ = pointers(parameterNames);
    parDescriptions_.assign(parameterNames.size(), "");
    outPtrs_ = pointers(outputNames);
    invPtrs_ = pointers(invariantNames);
    QdotModel& m = table_.abi;
    m = QdotModel{};
    table_.owner = this;
    m.abiVersion = abiVersion;
    m.name = name.c_str();
    m.nVariables = static_cast<uint32_t>(variables.size());
    m.nParameters = static_cast<uint32_t>(parameterNames.size());
    m.nOutputs = static_cast<uint32_t>(outputNames.size());
    m.nInvariants = static_cast<uint32_t>(invariantNames.size());
    m.variableNames = varPtrs_.data();
    m.isDifferential = differential.data();
    m.parameterNames = parPtrs_.data();
    m.parameterDescriptions = parDescriptions_.data();
    m.outputNames = outPtrs_.data();
    m.invariantNames = invPtrs_.data();
    m.jacobianNonzeros = static_cast<uint32_t>(rows_.size());
    m.jacobianColumnStarts = starts_.data();
    m.jacobianRowIndices = rows_.data();
    m.parameters = [](const QdotModel* s, const double* given, const uint8_t* overridden, double* p) {
      auto& h = self(s);
      for (std::size_t i = 0; i < h.parameterDefaults.size(); ++i)
        p[i] = overridden[i] ? given[i] : h.parameterDefaults[i];
      return 0;
    };
    m.initialValues = [](const QdotModel* s, const double*, double, double* y0, double* yp0, double* nominal) {
      auto& h = self(s);
      for (std::size_t i = 0; i < h.variables.size(); ++i) {
        y0[i] = h.start[i];
        yp0[i] = 0;
        nominal[i] = h.nominal.empty() ? 0 : h.nominal[i];
      }
      return 0;
    };
    m.fixedStarts = [](const QdotModel* s, int32_t* fixed) {
      auto& h = self(s);
      for (std::size_t i = 0; i < h.variables.size(); ++i)
        fixed[i] = h.fixed.empty() ? h.differential[i] : h.fixed[i];
      return 0;
    };
    m.residual = [](const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* F) {
      return self(s).residual(t, y, yp, p, F);
    };
    m.jacobian = [](const QdotModel* s, double t, const double* y, const double* yp, const double* p, double cj,
                    double* values) {
      auto& h = self(s);
      std::fill(values, values + h.rows_.size(), 0.0);
      JacobianValues J(h.starts_, h.rows_, values);
      return h.jacobian(t, y, yp, p, cj, J);
    };
    m.outputs = [](const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
      return self(s).outputs(t, y, yp, p, out);
    };
    m.invariants = [](const QdotModel* s, double t, const double* y, const double* yp, const double* p, double* out) {
      return self(s).invariants(t, y, yp, p, out);
    };
    m.lastError = [](const QdotModel* s) { return self(s).lastError.c_str(); };
    m.destroy = [](QdotModel*) {};
  }

  bool built_ = false;
  Table table_{};
  std::vector<int32_t> starts_, rows_;
  std::vector<const char*> varPtrs_, parPtrs_, parDescriptions_, outPtrs_, invPtrs_;
};

}  // namespace qdot::rt::test
