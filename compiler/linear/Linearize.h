// Linearize: the equations of motion about an operating point, M q̈ + C q̇ + K q = 0, with M, C and
// K the partial derivatives of the Euler–Lagrange rows with respect to the accelerations,
// velocities and coordinates, taken symbolically and evaluated at the point; and the natural
// frequencies, damping ratios and mode shapes of that system (Eigen).
#pragma once

#include <Eigen/Dense>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "dae/Dae.h"
#include "symbolic/Expr.h"

namespace qdot::linear {

/// Where to linearize: the static equilibrium nearest the start values (velocities zero), or the
/// start state itself.
enum class OperatingPoint { Equilibrium, Start };

/// Values of the model's inputs: parameters (in dae.parameters order), start values of every DAE
/// variable (in dae.variables order), and the time.
struct ModelValues {
  std::vector<double> parameters, start;
  double time = 0;
};

/// M q̈ + C q̇ + K q = 0 about q*, named by coordinate.
struct SecondOrderSystem {
  std::vector<std::string> coordinates;
  std::vector<double> point;  ///< q* (velocities are zero at an equilibrium)
  Eigen::MatrixXd M, C, K;
  bool equilibrium = false;   ///< q* is a static equilibrium (else the start state)
  double time = 0;            ///< the time of the point (forces that depend on time take their values then)
  int newtonIterations = 0;   ///< to find it
};

/// The linearization, or why there is none (a sentence for the user).
struct Linearization {
  SecondOrderSystem system;
  std::string error;
};

/// Linearizes the Euler–Lagrange rows of `dae` (the first dae.coordinates.size() equations). Models
/// with constraints, algebraic unknowns in those rows, coordinates without inertia or a mass matrix
/// that is not positive definite are refused with a reason. `ctx` is the Context of the DAE's expressions.
Linearization linearize(const dae::Dae& dae, sym::Context& ctx, const ModelValues& values, OperatingPoint at);

/// One mode. Oscillatory: ω = |λ|, ζ = −Re λ / |λ|; a real eigenvalue λ (overdamped, rigid-body or
/// unstable motion) has omega = 0 and rate = λ.
struct Mode {
  double omega = 0;  ///< natural (undamped) frequency [rad/s]
  double zeta = 0;   ///< damping ratio
  double rate = 0;   ///< the real eigenvalue of a non-oscillating mode [1/s]
  bool oscillating = true;
  std::vector<double> shape;  ///< normalised: the largest component is +1
};

/// The modes of `s`, by increasing frequency (non-oscillating ones last). Undamped systems (C = 0)
/// use the symmetric generalized eigenproblem K v = ω² M v; damped ones the eigenvalues of the
/// first-order form.
std::vector<Mode> modes(const SecondOrderSystem& s);

/// `qdot modes`: a table, or JSON for tools.
void printModes(std::ostream& os, const SecondOrderSystem& s, const std::vector<Mode>& modes);
void printModesJson(std::ostream& os, const SecondOrderSystem& s, const std::vector<Mode>& modes);

}  // namespace qdot::linear
