// ExplicitForm: g(t, y) = −A⁻¹ F(t, y, 0) and dg/dy = −A⁻¹ F_y through the model's residual and
// Jacobian (two Jacobian calls give A = J(1) − J(0) exactly, since J is linear in cj).
#include "arkode/ExplicitForm.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "ida/ModelCheck.h"

namespace qdot::rt {

std::string explicitFormObstacle(const QdotModel& model) {
  uint32_t n = model.nVariables;
  if (model.nResiduals > n)
    return "its index was reduced (constraints differentiated, dummy derivatives): it is a DAE, not an ODE";
  if (model.nInitialRows > 0) return "it has initial equations that are not start values";
  std::vector<std::string> algebraic;
  auto names = nameList(model.variableNames, n);
  for (uint32_t i = 0; i < n; ++i)
    if (!model.isDifferential[i]) algebraic.emplace_back(names[i]);
  if (algebraic.empty()) return "";
  std::string list;
  for (std::size_t i = 0; i < algebraic.size() && i < 4; ++i) list += (i ? ", " : "") + algebraic[i];
  if (algebraic.size() > 4) list += fmt::format(", … ({} more)", algebraic.size() - 4);
  return fmt::format("it has algebraic unknowns ({}) whose derivatives appear in no equation", list);
}

namespace {

// A matrix in the model's CSC pattern, so that valuePtr()[k] is the model's k-th Jacobian value.
Eigen::SparseMatrix<double> patternMatrix(const QdotModel& model) {
  uint32_t n = model.nVariables;
  Eigen::SparseMatrix<double> m(n, n);
  std::vector<int> perColumn(n);
  for (uint32_t c = 0; c < n; ++c)
    perColumn[c] = model.jacobianColumnStarts[c + 1] - model.jacobianColumnStarts[c];
  m.reserve(perColumn);
  for (uint32_t c = 0; c < n; ++c)
    for (int32_t k = model.jacobianColumnStarts[c]; k < model.jacobianColumnStarts[c + 1]; ++k)
      m.insert(model.jacobianRowIndices[k], c) = 0.0;
  m.makeCompressed();
  return m;
}

}  // namespace

ExplicitForm::ExplicitForm(const QdotModel& model, std::span<const double> p, bool sparse)
    : model_(model),
      p_(p.begin(), p.end()),
      n_(model.nVariables),
      sparse_(sparse),
      zeros_(n_, 0.0),
      residual_(n_),
      at0_(model.jacobianNonzeros),
      at1_(model.jacobianNonzeros),
      mass_(patternMatrix(model)),
      stiffness_(mass_) {
  if (sparse_) {
    sparseLu_ = std::make_unique<Eigen::SparseLU<Eigen::SparseMatrix<double>>>();
    sparseLu_->analyzePattern(mass_);
  }
}

ExplicitForm::~ExplicitForm() = default;

int ExplicitForm::fail(std::string message) {
  error_ = std::move(message);
  return 1;
}

int ExplicitForm::evaluate(double t, const double* y, const double* yp, double cj, std::vector<double>& values) {
  if (model_.jacobian(&model_, t, y, yp, p_.data(), cj, values.data()) != 0)
    return fail(fmt::format("the model's Jacobian failed: {}", modelLastError(model_)));
  for (std::size_t k = 0; k < values.size(); ++k)
    if (!std::isfinite(values[k])) return fail(fmt::format("a Jacobian entry evaluated to {}", values[k]));
  return 0;
}

// A = J(cj = 1) − J(cj = 0) at y' = 0; factored again only when a value changed.
int ExplicitForm::factorMassMatrix(double t, const double* y) {
  if (evaluate(t, y, zeros_.data(), 0.0, at0_) || evaluate(t, y, zeros_.data(), 1.0, at1_)) return 1;
  for (std::size_t k = 0; k < at0_.size(); ++k)
    at1_[k] -= at0_[k];
  if (factored_ && at1_ == massValues_) return 0;
  massValues_ = at1_;
  std::copy(at1_.begin(), at1_.end(), mass_.valuePtr());
  ++factorizations_;
  factored_ = false;
  bool regular = true;
  if (sparse_) {
    sparseLu_->factorize(mass_);
    regular = sparseLu_->info() == Eigen::Success;
  } else {
    // rows equilibrated first (a pendulum of 1e-9 m has m l² = 1e-18 in one row and 1 in the next):
    // the pivots then measure dependence, not units
    Eigen::MatrixXd scaled(mass_);
    rowScale_ = scaled.rowwise().lpNorm<Eigen::Infinity>().cwiseMax(1e-300).cwiseInverse();
    denseLu_.compute(rowScale_.asDiagonal() * scaled);
    double smallest = denseLu_.matrixLU().diagonal().cwiseAbs().minCoeff();
    regular = std::isfinite(smallest) && smallest > 1e-14;
  }
  if (!regular)
    return fail(fmt::format("the matrix dF/dy' (the mass matrix) is singular at t = {:.10g}: the equations do not "
                            "determine every derivative (a mass or moment of inertia of 0?)",
                            t));
  factored_ = true;
  return 0;
}

int ExplicitForm::rhs(double t, const double* y, double* yp) {
  if (model_.residual(&model_, t, y, zeros_.data(), p_.data(), residual_.data()) != 0)
    return fail(fmt::format("the model's residual failed: {}", modelLastError(model_)));
  for (uint32_t i = 0; i < n_; ++i)
    if (!std::isfinite(residual_[i])) return fail(fmt::format("residual F[{}] evaluated to {}", i, residual_[i]));
  if (factorMassMatrix(t, y)) return 1;
  Eigen::Map<const Eigen::VectorXd> f(residual_.data(), n_);
  Eigen::Map<Eigen::VectorXd> out(yp, n_);
  out = sparse_ ? Eigen::VectorXd(sparseLu_->solve(-f)) : Eigen::VectorXd(denseLu_.solve(-(rowScale_.asDiagonal() * f)));
  return 0;
}

// F_y = J(cj = 0) at the actual y' (the mass matrix's dependence on y multiplies y').
int ExplicitForm::stiffnessMatrix(double t, const double* y, const double* yp) {
  if (factorMassMatrix(t, y)) return 1;
  if (evaluate(t, y, yp, 0.0, at0_)) return 1;
  std::copy(at0_.begin(), at0_.end(), stiffness_.valuePtr());
  return 0;
}

int ExplicitForm::denseJacobian(double t, const double* y, const double* yp, Eigen::MatrixXd& out) {
  if (stiffnessMatrix(t, y, yp)) return 1;
  Eigen::MatrixXd fy(stiffness_);
  out = sparse_ ? Eigen::MatrixXd(sparseLu_->solve(-fy)) : Eigen::MatrixXd(denseLu_.solve(-(rowScale_.asDiagonal() * fy)));
  return 0;
}

int ExplicitForm::sparseJacobian(double t, const double* y, const double* yp, Eigen::SparseMatrix<double>& out) {
  if (stiffnessMatrix(t, y, yp)) return 1;
  Eigen::SparseMatrix<double> minusFy = -stiffness_;
  out = sparseLu_ ? Eigen::SparseMatrix<double>(sparseLu_->solve(minusFy))
                  : Eigen::MatrixXd(denseLu_.solve(rowScale_.asDiagonal() * Eigen::MatrixXd(minusFy))).sparseView();
  out.prune(0.0);
  out.makeCompressed();
  return 0;
}

}  // namespace qdot::rt
