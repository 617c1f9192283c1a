// chooseSolver: from the eigenvalues of dg/dy = −A⁻¹ F_y at the start values (StartLinearization.h).
#include "arkode/SolverChoice.h"

#include <fmt/format.h>

#include <cmath>
#include <complex>
#include <vector>

#include "arkode/ExplicitForm.h"
#include "arkode/StartLinearization.h"

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
