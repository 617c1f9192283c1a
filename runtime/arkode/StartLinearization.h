// The linearization of a model written as y' = g(t, y) (ExplicitForm) at its start values: the
// eigenvalues of dg/dy, for the solver choice (SolverChoice.h) and the time scale a velocity's
// tolerance follows (ida/Tolerances.h).
#pragma once

#include <Eigen/Core>

#include <optional>
#include <span>

#include "ida/Tolerances.h"
#include "qdot/model_abi.h"

namespace qdot::rt {

/// Eigenvalues of dg/dy at the start values (Eigen's dense EigenSolver, n³ work), or nullopt when
/// the model is not of the explicit form, cannot be evaluated at the start, or the solver fails.
/// p: parameter values.
std::optional<Eigen::VectorXcd> startEigenvalues(const QdotModel& model, std::span<const double> p, double start);

/// Eigenvalues at most this fraction of the largest in size count as zero (a free body's rigid
/// mode, or its round-off): the lowest frequency is the lowest of the others.
inline constexpr double kZeroFrequencyFraction = 1e-9;
/// Largest model whose lowest frequency is computed for the tolerance scales (dense eigenvalues at
/// the start cost about 10 n³ flops: 1e-3 s at n = 50, 0.1 s at n = 200).
inline constexpr unsigned kLargestWithFrequency = 200;

/// The lowest frequency of the linearization at the start, min |λ| over the eigenvalues of dg/dy
/// that are not zero (|λ| > kZeroFrequencyFraction × max |λ|), in 1/s; for a mechanical system
/// the lowest natural frequency ω (an undamped mode's λ = ±iω; a damped one's |λ| = ω too).
/// nullopt when there is none: not the explicit form, more than kLargestWithFrequency unknowns,
/// every eigenvalue zero, or a growing mode (Re λ > kZeroFrequencyFraction × max |λ|): a start near
/// an unstable equilibrium (a pendulum released near the top) moves away from it by a deviation
/// of unknown size, not by an oscillation of its positions' size, so ω says nothing about its velocities.
std::optional<double> lowestStartFrequency(const QdotModel& model, std::span<const double> p, double start);

/// The time scale the automatic tolerance scales of the model's velocities follow: its lowest
/// start frequency and which unknown is der(which). frequency 0 (today's floors only) without one.
TimeScale modelTimeScale(const QdotModel& model, std::span<const double> p, double start);

}  // namespace qdot::rt
