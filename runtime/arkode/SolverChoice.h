// Which integrator runs a model: IDA (BDF, any DAE) or ARKODE (an L-stable ESDIRK method on the
// explicit form y' = g(t, y)), as the user asked (--solver) or chosen from the linearization at the
// start (auto).
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "qdot/model_abi.h"

namespace qdot::rt {

enum class SolverKind { Ida, Arkode, Auto };

/// "ida", "arkode" or "auto".
std::string_view solverName(SolverKind kind);
/// Inverse of solverName; nullopt for anything else.
std::optional<SolverKind> parseSolver(std::string_view text);

/// What auto picked (never Auto) and one sentence why.
struct SolverChoice {
  SolverKind kind = SolverKind::Ida;
  std::string reason;
};

/// A mode whose damping ratio ζ = −Re λ/|λ| is at most this lies outside BDF5's stability wedge
/// (51° from the negative real axis; cos 51° ≈ 0.63): BDF of order above 2 is unstable there for
/// large h|λ|, so IDA must keep its step near the mode's period or drop to order 1–2.
inline constexpr double kOscillatoryDampingRatio = 0.63;
/// A mode that decays by e^−1000 over the run is stiff: the solution's time scale is far longer.
inline constexpr double kStiffDecay = 1000;
/// Largest model analysed by dense eigenvalues (n³ work at the start).
inline constexpr unsigned kLargestAnalysed = 400;

/// auto: ARKODE when the model is an ODE in y' (explicitFormObstacle is empty) and the
/// linearization dg/dy at the start has an eigenvalue with ζ ≤ kOscillatoryDampingRatio and
/// |Re λ|·(stop − start) ≥ kStiffDecay (a fast oscillation that dies out long before the end);
/// IDA otherwise. p: parameter values.
SolverChoice chooseSolver(const QdotModel& model, std::span<const double> p, double start, double stop);

}  // namespace qdot::rt
