// startEigenvalues and the lowest frequency: dense eigenvalues of dg/dy = −A⁻¹ F_y at the start.
#include "arkode/StartLinearization.h"

#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>

#include "arkode/ExplicitForm.h"

namespace qdot::rt {
namespace {

std::optional<std::vector<std::complex<double>>> eigenvaluesOf(const Eigen::MatrixXd& jacobian) {
  if (!jacobian.allFinite()) return std::nullopt;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(jacobian, false);
  if (solver.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXcd& values = solver.eigenvalues();
  return std::vector<std::complex<double>>(values.data(), values.data() + values.size());
}

}  // namespace

std::optional<std::vector<std::complex<double>>> startEigenvalues(const QdotModel& model, std::span<const double> p,
                                                                  double start) {
  if (!explicitFormObstacle(model).empty()) return std::nullopt;
  uint32_t n = model.nVariables;
  std::vector<double> y(n, 0.0), yp(n, 0.0), nominal(n, 0.0);
  if (model.initialValues(&model, p.data(), start, y.data(), yp.data(), nominal.data()) != 0) return std::nullopt;
  ExplicitForm form(model, p, false);
  Eigen::MatrixXd jacobian;
  if (form.rhs(start, y.data(), yp.data()) || form.denseJacobian(start, y.data(), yp.data(), jacobian))
    return std::nullopt;
  return eigenvaluesOf(jacobian);
}

std::optional<double> lowestFrequency(std::span<const std::complex<double>> eigenvalues) {
  double largest = 0;
  for (const std::complex<double>& lambda : eigenvalues) largest = std::max(largest, std::abs(lambda));
  double lowest = INFINITY;
  for (const std::complex<double>& lambda : eigenvalues) {
    if (lambda.real() > kZeroFrequencyFraction * largest) return std::nullopt;  // a growing mode: no amplitude to scale
    if (std::abs(lambda) > kZeroFrequencyFraction * largest) lowest = std::min(lowest, std::abs(lambda));
  }
  if (!std::isfinite(lowest) || lowest <= 0) return std::nullopt;
  return lowest;
}

std::optional<double> lowestStartFrequency(const QdotModel& model, std::span<const double> p, double start) {
  if (model.nVariables == 0 || model.nVariables > kLargestWithFrequency) return std::nullopt;
  auto eigenvalues = startEigenvalues(model, p, start);
  return eigenvalues ? lowestFrequency(*eigenvalues) : std::nullopt;
}

std::optional<double> lowestStartFrequency(std::span<const double> y0, const DenseResidual& residual,
                                           const DenseJacobian& jacobian) {
  const std::size_t n = y0.size();
  if (n == 0 || n > kLargestWithFrequency) return std::nullopt;
  auto size = static_cast<Eigen::Index>(n);
  Eigen::VectorXd yp = Eigen::VectorXd::Zero(size), F(size);
  Eigen::MatrixXd at0 = Eigen::MatrixXd::Zero(size, size), at1 = Eigen::MatrixXd::Zero(size, size);
  residual(y0.data(), yp.data(), F.data());
  jacobian(0.0, y0.data(), yp.data(), at0.data());
  jacobian(1.0, y0.data(), yp.data(), at1.data());
  Eigen::FullPivLU<Eigen::MatrixXd> mass(at1 - at0);  // dF/dy', as ExplicitForm: F linear in y'
  if (!mass.isInvertible()) return std::nullopt;
  yp = -mass.solve(F);
  at0.setZero();
  jacobian(0.0, y0.data(), yp.data(), at0.data());  // dF/dy at (y0, g(y0))
  auto eigenvalues = eigenvaluesOf(-mass.solve(at0));
  return eigenvalues ? lowestFrequency(*eigenvalues) : std::nullopt;
}

TimeScale modelTimeScale(const QdotModel& model, std::span<const double> p, double start) {
  TimeScale timeScale;
  if (model.nVariables > kLargestWithFrequency) return timeScale;  // no frequency: nothing to pair up
  timeScale.positionOf = velocityPositions({model.variableNames, model.nVariables});
  bool hasVelocity = std::any_of(timeScale.positionOf.begin(), timeScale.positionOf.end(), [](int32_t q) { return q >= 0; });
  if (hasVelocity) timeScale.frequency = lowestStartFrequency(model, p, start).value_or(0.0);
  return timeScale;
}

}  // namespace qdot::rt
