// Linearize: the DAE F(t, y, y', p, u) = 0 about an operating point. E = ∂F/∂y', A = ∂F/∂y and
// ∂F/∂u are taken symbolically and evaluated at the point; the algebraic unknowns are eliminated
// (index 1) to give the state-space form ẋ = A x + B u, y = C x + D u. When every state is a
// coordinate or its velocity, also M q̈ + C q̇ + K q = 0 for the coordinates. And the natural
// frequencies, damping ratios and mode shapes of the result (Eigen).
#pragma once

#include <Eigen/Dense>
#include <iosfwd>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "dae/Dae.h"
#include "symbolic/Expr.h"

namespace qdot::linear {

/// Where to linearize: the static equilibrium nearest the start values (velocities and state
/// derivatives zero), or the start state itself.
enum class OperatingPoint { Equilibrium, Start };

/// Values of the model's inputs: parameters (in dae.parameters order, the model's `input`s
/// among them), start values of every DAE variable (in dae.variables order), and the time.
struct ModelValues {
  std::vector<double> parameters, start;
  double time = 0;
};

/// M q̈ + C q̇ + K q = 0 for the coordinates that are states, the algebraic unknowns eliminated.
struct SecondOrderSystem {
  Eigen::MatrixXd M, C, K;
};

/// ẋ = A x + B u, y = C x + D u in deviations from the operating point. States in the DAE's
/// variable order, inputs the model's `input` parameters, outputs its `output` definitions.
struct StateSpace {
  std::vector<std::string> states, inputs, outputs;
  Eigen::MatrixXd A, B, C, D;
};

/// The model linearized about a point.
struct LinearModel {
  StateSpace stateSpace;
  std::vector<double> statePoint;        ///< x*, in stateSpace.states order
  std::vector<std::string> coordinates;  ///< the coordinates that are states (mode shapes are named by them)
  std::vector<int> coordinateStates;     ///< their positions in stateSpace.states
  std::vector<double> point;             ///< their values q*
  /// When every state is a coordinate or its velocity and the algebraic unknowns can be eliminated
  /// from the Euler–Lagrange rows (for a model without algebraic unknowns: those rows' M, C, K).
  std::optional<SecondOrderSystem> mechanical;
  bool equilibrium = false;  ///< the point is a static equilibrium (else the start state)
  double time = 0;           ///< the time of the point (forces that depend on time take their values then)
  int newtonIterations = 0;  ///< to find the equilibrium (0 for the start state)
};

/// The linearization, or why there is none (a sentence for the user).
struct Linearization {
  LinearModel model;
  std::string error;
};

/// Linearizes `dae` about `at`. Refused with a reason: constraints (multipliers), no states, no
/// isolated equilibrium, a mass matrix that is not positive definite, an index above 1 (the
/// state derivatives and algebraic unknowns not determined by the states). `ctx` is the Context
/// of the DAE's expressions.
Linearization linearize(const dae::Dae& dae, sym::Context& ctx, const ModelValues& values, OperatingPoint at);

/// One mode. Oscillatory: ω = |λ|, ζ = −Re λ / |λ|; a real eigenvalue λ (overdamped, rigid-body or
/// unstable motion) has omega = 0 and rate = λ.
struct Mode {
  double omega = 0;  ///< natural (undamped) frequency [rad/s]
  double zeta = 0;   ///< damping ratio
  double rate = 0;   ///< the real eigenvalue of a non-oscillating mode [1/s]
  bool oscillating = true;
  std::vector<double> shape;  ///< over the coordinates (all states if none), the largest component +1
};

/// The modes of `m`, by increasing frequency (non-oscillating ones last). Undamped symmetric
/// mechanical systems (C = 0) use the symmetric generalized eigenproblem K v = ω² M v; others the
/// eigenvalues of the first-order form.
std::vector<Mode> modes(const LinearModel& m);

/// `qdot modes`: a table, or JSON for tools.
void printModes(std::ostream& os, const LinearModel& m, const std::vector<Mode>& modes);
void printModesJson(std::ostream& os, const LinearModel& m, const std::vector<Mode>& modes);

/// `qdot linearize`: CSV blocks (point, A, B, C, D; each a header row of names), or JSON.
void printStateSpace(std::ostream& os, const LinearModel& m);
void printStateSpaceJson(std::ostream& os, const LinearModel& m);

}  // namespace qdot::linear
