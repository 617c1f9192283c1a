// The linearization of a model written as y' = g(t, y) (ExplicitForm) at its start values: the
// eigenvalues of dg/dy, for the solver choice (SolverChoice.h) and the time scale a velocity's
// tolerance follows (ida/Tolerances.h). No Eigen types here: bench/reference uses the pencil form.
#pragma once

#include <complex>
#include <cstddef>
#include <functional>
#include <optional>
#include <span>
#include <vector>

#include "ida/Tolerances.h"
#include "qdot/model_abi.h"

namespace qdot::rt {

/// Eigenvalues of dg/dy at the start values (Eigen's dense EigenSolver, n³ work), or nullopt when
/// the model is not of the explicit form, cannot be evaluated at the start, or the solver fails.
/// p: parameter values.
std::optional<std::vector<std::complex<double>>> startEigenvalues(const QdotModel& model, std::span<const double> p,
                                                                  double start);

/// Eigenvalues at most this fraction of the largest in size count as zero (a free body's rigid
/// mode, or its round-off): the lowest frequency is the lowest of the others.
inline constexpr double kZeroFrequencyFraction = 1e-9;
/// Largest model whose lowest frequency is computed for the tolerance scales (dense eigenvalues at
/// the start cost about 10 n³ flops: 1e-3 s at n = 50, 0.1 s at n = 200).
inline constexpr unsigned kLargestWithFrequency = 200;

/// The lowest frequency among eigenvalues: min |λ| over those that are not zero (|λ| >
/// kZeroFrequencyFraction × max |λ|), in 1/s; for a mechanical system its lowest natural frequency
/// ω (an undamped mode's λ = ±iω; a damped one's |λ| = ω too). nullopt when every eigenvalue is
/// zero, or when one grows (Re λ > kZeroFrequencyFraction × max |λ|): a start near an unstable
/// equilibrium (a pendulum released near the top) moves away from it by a deviation of unknown
/// size, not by an oscillation of its positions' size, so ω says nothing about its velocities.
std::optional<double> lowestFrequency(std::span<const std::complex<double>> eigenvalues);

/// lowestFrequency of the linearization at the start; nullopt also when the model is not of the
/// explicit form or has more than kLargestWithFrequency unknowns.
std::optional<double> lowestStartFrequency(const QdotModel& model, std::span<const double> p, double start);

/// The same for a model F(y, y') = 0 linear in y' given by functions (programs that are not a
/// QdotModel: bench/reference): residual(y, yp, F) and jacobian(cj, y, yp, J), J = dF/dy + cj dF/dy'
/// dense column-major n × n. Linearized at y0 with y0' = g(y0), as startEigenvalues.
using DenseResidual = std::function<void(const double* y, const double* yp, double* F)>;
using DenseJacobian = std::function<void(double cj, const double* y, const double* yp, double* J)>;
std::optional<double> lowestStartFrequency(std::span<const double> y0, const DenseResidual& residual,
                                           const DenseJacobian& jacobian);

/// The time scale the automatic tolerance scales of the model's velocities follow: its lowest
/// start frequency and which unknown is der(which). frequency 0 (today's floors only) without one.
TimeScale modelTimeScale(const QdotModel& model, std::span<const double> p, double start);

}  // namespace qdot::rt
