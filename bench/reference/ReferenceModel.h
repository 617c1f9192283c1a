// The interface of the hand-written reference models (bench/reference/): the residual and the
// analytic Jacobian of a DAE F(y, y') = 0 written by hand, in qdot's formulation (unknowns:
// coordinates, then velocities; rows: Euler–Lagrange rows, then kinematic rows q' − v = 0).
// Plain arrays only, so the IDA harness and the cross-check against qdot share the same code.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qdot::bench {

class ReferenceModel {
 public:
  virtual ~ReferenceModel() = default;

  /// Number of unknowns (and equations).
  virtual uint32_t size() const = 0;
  /// Names as qdot writes them, e.g. "x[1]" and "der(x[1])".
  virtual std::vector<std::string> variableNames() const = 0;
  /// y0 (y'0 is zero, as qdot's start values are).
  virtual std::vector<double> startValues() const = 0;
  /// F(y, y'): the model is autonomous.
  virtual void residual(const double* y, const double* yp, double* F) const = 0;

  /// Whether the Jacobian is sparse (CSC, KLU) rather than dense.
  virtual bool sparse() const = 0;
  /// Nonzeros of the CSC pattern (sparse models only).
  virtual uint32_t jacobianNonzeros() const { return 0; }
  /// Dense models: J = dF/dy + cj dF/dy' into a zeroed column-major size() x size() array.
  virtual void denseJacobian(double cj, const double* y, const double* yp, double* J) const {}
  /// Sparse models: the CSC pattern (columnStarts[size()+1], rowIndices[nnz]) and its values.
  virtual void sparseJacobian(double cj, const double* y, const double* yp, int64_t* columnStarts, int64_t* rowIndices,
                              double* values) const {}
};

}  // namespace qdot::bench
