// chooseSolver: eigenvalues of dg/dy = −A⁻¹ F_y at the start values (Eigen's dense EigenSolver).
#include "arkode/SolverChoice.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>

#include <cmath>
#include <complex>
#include <vector>

#include "arkode/ExplicitForm.h"

namespace qdot::rt {

std::string_view solverName(SolverKind kind) {
  switch (kind) {
    case SolverKind::Ida:
      return "ida";
    case SolverKind::Arkode:
      return "arkode";
    case SolverKind::Auto:
      return "auto";
  }
  return "ida";
}

std::optional<SolverKind> parseSolver(std::string_view text) {
  for (auto kind : {SolverKind::Ida, SolverKind::Arkode, SolverKind::Auto})
    if (text == solverName(kind)) return kind;
  return std::nullopt;
}

namespace {

/// The eigenvalues of dg/dy at the start, or nullopt when the model cannot be evaluated there.
std::optional<Eigen::VectorXcd> startEigenvalues(const QdotModel& model, std::span<const double> p, double start) {
  uint32_t n = model.nVariables;
  std::vector<double> y(n, 0.0), yp(n, 0.0), nominal(n, 0.0);
  if (model.initialValues(&model, p.data(), start, y.data(), yp.data(), nominal.data()) != 0) return std::nullopt;
  ExplicitForm form(model, p, false);
  Eigen::MatrixXd jacobian;
  if (form.rhs(start, y.data(), yp.data()) || form.denseJacobian(start, y.data(), yp.data(), jacobian))
    return std::nullopt;
  Eigen::EigenSolver<Eigen::MatrixXd> solver(jacobian, false);
  if (solver.info() != Eigen::Success) return std::nullopt;
  return solver.eigenvalues();
}

std::string ida(std::string why) { return "chose ida: " + why; }

}  // namespace

SolverChoice chooseSolver(const QdotModel& model, std::span<const double> p, double start, double stop) {
  std::string obstacle = explicitFormObstacle(model);
  if (!obstacle.empty()) return {SolverKind::Ida, ida(obstacle + ", which only IDA integrates")};
  if (model.nVariables > kLargestAnalysed)
    return {SolverKind::Ida, ida(fmt::format("the model has {} unknowns, more than the {} whose linearization is "
                                             "analysed at the start",
                                             model.nVariables, kLargestAnalysed))};
  auto eigenvalues = startEigenvalues(model, p, start);
  if (!eigenvalues) return {SolverKind::Ida, ida("the linearization at the start could not be evaluated")};
  double span = stop - start;
  std::complex<double> critical;
  double largestDecay = 0;
  for (const std::complex<double>& lambda : *eigenvalues) {
    double size = std::abs(lambda), decay = -lambda.real() * span;
    bool oscillatory = lambda.imag() != 0 && lambda.real() < 0 && -lambda.real() <= kOscillatoryDampingRatio * size;
    if (oscillatory && decay >= kStiffDecay && decay > largestDecay) largestDecay = decay, critical = lambda;
  }
  if (largestDecay == 0)
    return {SolverKind::Ida,
            ida("the linearization at the start has no fast damped oscillation (an eigenvalue near the imaginary axis "
                "that decays long before the stop time)")};
  double zeta = -critical.real() / std::abs(critical);
  return {SolverKind::Arkode,
          fmt::format("chose arkode: the linearization at the start has eigenvalues {:.3g} ± {:.3g}i (damping ratio "
                      "{:.2g}; |Re λ|·(stop − start) = {:.3g}, so it dies out long before the stop time) near the imaginary axis, where BDF of order above 2 "
                      "is unstable and IDA needs steps near the period; an L-stable ESDIRK method does not",
                      critical.real(), std::abs(critical.imag()), zeta, largestDecay)};
}

}  // namespace qdot::rt
