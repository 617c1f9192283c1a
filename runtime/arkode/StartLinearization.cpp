// startEigenvalues and lowestStartFrequency: dense eigenvalues of dg/dy = −A⁻¹ F_y at the start.
#include "arkode/StartLinearization.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <vector>

#include "arkode/ExplicitForm.h"

namespace qdot::rt {

std::optional<Eigen::VectorXcd> startEigenvalues(const QdotModel& model, std::span<const double> p, double start) {
  if (!explicitFormObstacle(model).empty()) return std::nullopt;
  uint32_t n = model.nVariables;
  std::vector<double> y(n, 0.0), yp(n, 0.0), nominal(n, 0.0);
  if (model.initialValues(&model, p.data(), start, y.data(), yp.data(), nominal.data()) != 0) return std::nullopt;
  ExplicitForm form(model, p, false);
  Eigen::MatrixXd jacobian;
  if (form.rhs(start, y.data(), yp.data()) || form.denseJacobian(start, y.data(), yp.data(), jacobian))
    return std::nullopt;
  if (!jacobian.allFinite()) return std::nullopt;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(jacobian, false);
  if (solver.info() != Eigen::Success) return std::nullopt;
  return solver.eigenvalues();
}

std::optional<double> lowestStartFrequency(const QdotModel& model, std::span<const double> p, double start) {
  if (model.nVariables == 0 || model.nVariables > kLargestWithFrequency) return std::nullopt;
  auto eigenvalues = startEigenvalues(model, p, start);
  if (!eigenvalues) return std::nullopt;
  double largest = eigenvalues->cwiseAbs().maxCoeff();
  for (const std::complex<double>& lambda : *eigenvalues)
    if (lambda.real() > kZeroFrequencyFraction * largest) return std::nullopt;  // a growing mode: no amplitude to scale
  double lowest = INFINITY;
  for (const std::complex<double>& lambda : *eigenvalues)
    if (std::abs(lambda) > kZeroFrequencyFraction * largest) lowest = std::min(lowest, std::abs(lambda));
  if (!std::isfinite(lowest) || lowest <= 0) return std::nullopt;
  return lowest;
}

TimeScale modelTimeScale(const QdotModel& model, std::span<const double> p, double start) {
  TimeScale timeScale;
  timeScale.positionOf = velocityPositions({model.variableNames, model.nVariables});
  bool hasVelocity = std::any_of(timeScale.positionOf.begin(), timeScale.positionOf.end(), [](int32_t q) { return q >= 0; });
  if (hasVelocity) timeScale.frequency = lowestStartFrequency(model, p, start).value_or(0.0);
  return timeScale;
}

}  // namespace qdot::rt
