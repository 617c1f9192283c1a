// A model F(t, y, y', p) = 0 that is linear in y' with a regular dF/dy', written as the explicit
// ODE y' = g(t, y): F(t, y, y') = F(t, y, 0) + A(t, y) y' with A = dF/dy' = J(cj = 1) − J(cj = 0),
// so g = −A⁻¹ F(t, y, 0), and by the implicit function theorem dg/dy = −A⁻¹ F_y with F_y = J(cj = 0)
// at (y, g). Mechanics models are of this form (q' = v rows and M(q) v' = f rows). ARKODE 6.4's mass
// matrix may depend on t only, not on y, so the solve for y' happens here, inside the right-hand side.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "qdot/model_abi.h"

namespace qdot::rt {

/// Why `model` cannot be written as y' = g(t, y), as the end of a sentence ("it has algebraic
/// unknowns (lambda[1], …)"), or "" when it can (every unknown differential, no index reduction).
/// Whether A is regular is known only at run time (ExplicitForm::rhs fails then).
std::string explicitFormObstacle(const QdotModel& model);

/// g(t, y) and dg/dy of an eligible model. One LU of A per distinct A: the factorisation is kept
/// while A's values stay bit-for-bit the same (a constant mass matrix is factored once per run).
class ExplicitForm {
 public:
  /// sparse: factor A with Eigen's SparseLU (else a dense LU). The model must outlive this.
  ExplicitForm(const QdotModel& model, std::span<const double> p, bool sparse);
  ~ExplicitForm();
  ExplicitForm(const ExplicitForm&) = delete;
  ExplicitForm& operator=(const ExplicitForm&) = delete;

  /// yp = g(t, y). 0 on success; nonzero when the model failed or A is singular (error() says why).
  int rhs(double t, const double* y, double* yp);
  /// Dense dg/dy at (t, y) with yp = g(t, y): out is n × n.
  int denseJacobian(double t, const double* y, const double* yp, Eigen::MatrixXd& out);
  /// Sparse dg/dy (compressed columns, explicit zeros dropped).
  int sparseJacobian(double t, const double* y, const double* yp, Eigen::SparseMatrix<double>& out);
  /// The last failure ("the model reported: …", "dF/dy' is singular …").
  const std::string& error() const { return error_; }
  /// Number of LU factorisations of A so far (a measure of the reuse).
  long factorizations() const { return factorizations_; }

 private:
  int evaluate(double t, const double* y, const double* yp, double cj, std::vector<double>& values);
  int factorMassMatrix(double t, const double* y);
  int fail(std::string message);
  int stiffnessMatrix(double t, const double* y, const double* yp);

  const QdotModel& model_;
  std::vector<double> p_;
  uint32_t n_;
  bool sparse_;
  std::vector<double> zeros_, residual_, at0_, at1_, massValues_;
  Eigen::SparseMatrix<double> mass_, stiffness_;  // A and F_y in the model's pattern
  Eigen::PartialPivLU<Eigen::MatrixXd> denseLu_;  // of diag(rowScale_) · A
  Eigen::VectorXd rowScale_;
  std::unique_ptr<Eigen::SparseLU<Eigen::SparseMatrix<double>>> sparseLu_;
  bool factored_ = false;
  long factorizations_ = 0;
  std::string error_;
};

}  // namespace qdot::rt
