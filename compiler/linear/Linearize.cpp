// The DAE linearized about an operating point found by Newton's method: the state-space form by
// eliminating the algebraic unknowns (index 1), and M, C, K for the coordinates when the model is a
// second-order mechanical one.
#include "linear/Linearize.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "linear/DaeJacobians.h"

namespace qdot::linear {
namespace {

using dae::UnknownRole;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// A square matrix factored once for its solves, and whether it is invertible. Partial pivoting
// (blocked: a model with thousands of coordinates factors in a fraction of a second, where full
// pivoting took seconds); invertible when far from singular, as FullPivLU's rank test has it:
// every pivot above n·ε times the largest, and the reciprocal condition number above n·ε. The
// rare singular case is then looked at with full pivoting (indexReason).
struct Factored {
  explicit Factored(const MatrixXd& a) {
    if (a.rows() != a.cols()) return;
    if (a.rows() == 0) {  // nothing to solve for
      invertible = true;
      return;
    }
    lu.compute(a);
    double threshold = static_cast<double>(a.rows()) * std::numeric_limits<double>::epsilon();
    Eigen::VectorXd pivots = lu.matrixLU().diagonal().cwiseAbs();
    if (!(pivots.minCoeff() > threshold * pivots.maxCoeff())) return;  // a zero pivot (or NaN)
    double rcond = lu.rcond();
    invertible = std::isfinite(rcond) && rcond > threshold;
  }
  Eigen::PartialPivLU<MatrixXd> lu;
  bool invertible = false;
};

std::vector<int> range(size_t n) {
  std::vector<int> out(n);
  for (size_t i = 0; i < n; ++i) out[i] = static_cast<int>(i);
  return out;
}

// Which variables, rows and inputs play which part.
struct Structure {
  std::vector<int> states, algebraic, velocities;  ///< variable indices, in DAE order
  std::vector<int> coordinates;                    ///< the coordinates that are states
  std::vector<int> inputs;                         ///< parameter indices of the model's inputs
  std::vector<int> otherRows;                      ///< all but the kinematic rows q' = der(q)
};

std::string structureOf(const dae::Dae& d, Structure& s) {
  for (size_t j = 0; j < d.variables.size(); ++j) {
    const dae::Variable& v = d.variables[j];
    if (v.role == UnknownRole::Multiplier)
      return "the model has constraints (multiplier " + v.name + "); linearizing it needs an unconstrained model";
    (v.kind == dae::VarKind::State ? s.states : s.algebraic).push_back(static_cast<int>(j));
    if (v.role == UnknownRole::Velocity) s.velocities.push_back(static_cast<int>(j));
    if (v.role == UnknownRole::Coordinate && v.kind == dae::VarKind::State)
      s.coordinates.push_back(static_cast<int>(j));
  }
  for (size_t k = 0; k < d.parameters.size(); ++k)
    if (d.parameters[k].input) s.inputs.push_back(static_cast<int>(k));
  for (size_t i = 0; i < d.equations.size(); ++i)
    if (d.equations[i].origin.kind != flat::OriginKind::Kinematic) s.otherRows.push_back(static_cast<int>(i));
  if (s.states.empty()) return "the model has no states: there is nothing to linearize";
  return "";
}

// One Newton solve: the rows it zeroes, and its unknowns (y of some variables, y' of others);
// everything else at the point stays as it is.
struct NewtonSystem {
  std::vector<int> rows, y, yp;
};

enum class NewtonOutcome { Converged, NotFinite, Singular, NoConvergence };

VectorXd unknownsOf(const PointValues& p, const NewtonSystem& s) {
  VectorXd x(s.y.size() + s.yp.size());
  x << p.y(s.y), p.yp(s.yp);
  return x;
}

void setUnknowns(PointValues& p, const NewtonSystem& s, const VectorXd& x) {
  p.y(s.y) = x.head(s.y.size());
  p.yp(s.yp) = x.tail(s.yp.size());
}

// Newton's method with step halving (steps that do not reduce |F| are halved). The point is left
// at the solution, or where the Jacobian was singular.
NewtonOutcome newton(DaeJacobians& jac, PointValues& p, const NewtonSystem& s, int& iterations) {
  VectorXd x = unknownsOf(p, s);
  JacobianValues J;
  for (iterations = 0; iterations < 100; ++iterations) {
    setUnknowns(p, s, x);
    if (!jac.evaluate(p, J)) return NewtonOutcome::NotFinite;
    VectorXd F = J.F(s.rows);
    MatrixXd jacobian(s.rows.size(), x.size());
    jacobian << J.Y(s.rows, s.y), J.Yp(s.rows, s.yp);
    double scale = std::max(1.0, jacobian.cwiseAbs().maxCoeff() * (1 + x.cwiseAbs().maxCoeff()));
    if (F.cwiseAbs().maxCoeff() <= 1e-13 * scale) return NewtonOutcome::Converged;
    if (jacobian.rows() != jacobian.cols()) return NewtonOutcome::Singular;
    Factored lu(jacobian);
    if (!lu.invertible) return NewtonOutcome::Singular;
    VectorXd step = lu.lu.solve(-F);
    double t = 1;
    for (int halvings = 0; halvings < 40; ++halvings, t /= 2) {
      setUnknowns(p, s, x + t * step);
      if (jac.evaluate(p, J) && J.F(s.rows).norm() < F.norm()) break;
    }
    x += t * step;
    setUnknowns(p, s, x);
    if (step.cwiseAbs().maxCoeff() * t <= 1e-15 * (1 + x.cwiseAbs().maxCoeff())) return NewtonOutcome::Converged;
  }
  return NewtonOutcome::NoConvergence;
}

// Velocities and state derivatives zero; the other rows solved for every other y.
std::string findEquilibrium(DaeJacobians& jac, PointValues& p, const Structure& s, int& iterations) {
  p.yp.setZero();
  p.y(s.velocities).setZero();
  NewtonSystem system{s.otherRows, {}, {}};
  for (int j = 0; j < p.y.size(); ++j)
    if (std::find(s.velocities.begin(), s.velocities.end(), j) == s.velocities.end()) system.y.push_back(j);
  switch (newton(jac, p, system, iterations)) {
    case NewtonOutcome::Converged:
      return "";
    case NewtonOutcome::NotFinite:
      return "the equations are not finite at the start values";
    case NewtonOutcome::Singular:
      return "no isolated static equilibrium near the start values (the Jacobian of the static equations, the "
             "stiffness matrix for a mechanical model, is singular there); --at start linearizes about the start state";
    case NewtonOutcome::NoConvergence:
      break;
  }
  return "Newton's method found no static equilibrium from the start values in 100 iterations; try --at start";
}

// The states at their start values; their derivatives and the algebraic unknowns solved from all
// rows. A singular Jacobian is diagnosed at the point where Newton stopped, by linearize.
std::string solveStartState(DaeJacobians& jac, PointValues& p, const Structure& s, size_t equations, int& iterations) {
  p.yp.setZero();
  switch (newton(jac, p, {range(equations), s.algebraic, s.states}, iterations)) {
    case NewtonOutcome::Converged:
    case NewtonOutcome::Singular:
      return "";
    case NewtonOutcome::NotFinite:
      return "the equations are not finite at the start state";
    case NewtonOutcome::NoConvergence:
      break;
  }
  return "Newton's method found no state derivatives and algebraic unknowns consistent with the start state in "
         "100 iterations";
}

// The velocity variable der(q) of each coordinate that is a state (a state itself, else -1).
int velocityOf(const dae::Dae& d, int q) {
  std::string velocity = "der(" + d.variables[q].name + ")";
  for (size_t j = 0; j < d.variables.size(); ++j)
    if (d.variables[j].name == velocity && d.variables[j].kind == dae::VarKind::State) return static_cast<int>(j);
  return -1;
}

// The Euler–Lagrange row of coordinate variable q, or -1.
int rowOf(const dae::Dae& d, int q) {
  for (size_t i = 0; i < d.equations.size(); ++i)
    if (d.equations[i].origin.kind == flat::OriginKind::EulerLagrange &&
        d.equations[i].origin.variable == d.variables[q].flatVar)
      return static_cast<int>(i);
  return -1;
}

// M, C, K for the coordinates when every state is a coordinate q or its velocity v, each with its
// Euler–Lagrange row, and the other non-kinematic rows determine the algebraic unknowns z: the
// rows read E_a a + A_v v + A_q q + A_z z = 0, and z is eliminated with the other rows (block 2)
// from the coordinates' rows (block 1): M = E_a1 − A_z1 A_z2⁻¹ E_a2, and so on. (A row that uses
// q' means v: the kinematic rows say so.) Without algebraic unknowns these are the rows' own M, C, K.
std::optional<SecondOrderSystem> secondOrderForm(const dae::Dae& d, const Structure& s, const JacobianValues& J) {
  std::vector<int> q = s.coordinates, v, rows1, rows2;
  for (int j : q) {
    v.push_back(velocityOf(d, j));
    rows1.push_back(rowOf(d, j));
    if (v.back() < 0 || rows1.back() < 0) return std::nullopt;
  }
  if (s.states.size() != 2 * q.size()) return std::nullopt;  // other states: a first-order part
  for (int i : s.otherRows)
    if (std::find(rows1.begin(), rows1.end(), i) == rows1.end()) rows2.push_back(i);
  const std::vector<int>& z = s.algebraic;
  if (rows2.size() != z.size()) return std::nullopt;
  auto blocks = [&](const std::vector<int>& rows) {
    return std::array<MatrixXd, 3>{J.Yp(rows, v), J.Y(rows, v) + J.Yp(rows, q), J.Y(rows, q)};
  };
  std::array<MatrixXd, 3> mck = blocks(rows1);
  if (!z.empty()) {
    Factored lu(J.Y(rows2, z));
    if (!lu.invertible) return std::nullopt;
    MatrixXd eliminate = J.Y(rows1, z) * lu.lu.inverse();
    std::array<MatrixXd, 3> second = blocks(rows2);
    for (size_t k = 0; k < 3; ++k) mck[k] -= eliminate * second[k];
  }
  return SecondOrderSystem{mck[0], mck[1], mck[2]};
}

bool positiveDefinite(const MatrixXd& M) {
  Eigen::LLT<MatrixXd> llt(0.5 * (M + M.transpose()));
  return llt.info() == Eigen::Success;
}

// The matrix of the linear equations for (ẋ, z) given x and u: column j is ∂F/∂y'_j for a state,
// ∂F/∂y_j for an algebraic unknown.
MatrixXd derivativeMatrix(const dae::Dae& d, const JacobianValues& J) {
  MatrixXd P(J.Y.rows(), J.Y.cols());
  for (size_t j = 0; j < d.variables.size(); ++j)
    P.col(j) = d.variables[j].kind == dae::VarKind::State ? J.Yp.col(j) : J.Y.col(j);
  return P;
}

// Why P is singular, naming the unknowns of one combination that the equations leave free.
std::string indexReason(const dae::Dae& d, const MatrixXd& P) {
  Eigen::FullPivLU<MatrixXd> lu(P);
  std::string names;
  if (lu.rows() == lu.cols()) {
    VectorXd free = lu.kernel().col(0);
    for (int j = 0, listed = 0; j < free.size() && listed < 4; ++j)
      if (std::fabs(free(j)) > 1e-8 * free.cwiseAbs().maxCoeff()) {
        const dae::Variable& v = d.variables[j];
        names += (listed++ ? ", " : "") + (v.kind == dae::VarKind::State ? "der(" + v.name + ")" : v.name);
      }
  }
  return "the DAE is not of index 1 at the operating point: its equations do not determine the state derivatives "
         "and algebraic unknowns from the states" +
         (names.empty() ? "" : " (not determined: " + names + ")") +
         ", so it has no state-space form without index reduction (a constraint between coordinates, or an "
         "algebraic unknown whose equations vanish there, such as a force through a lever of length zero)";
}

// ẋ = A x + B u, y = C x + D u from the Jacobians at the point, with P = [∂F/∂x' ∂F/∂z] invertible:
// (δẋ, δz) = −P⁻¹ (∂F/∂x δx + ∂F/∂u δu), and δy = ∂g/∂y δy + ∂g/∂y' δy'.
StateSpace stateSpaceOf(const dae::Dae& d, const Structure& s, const JacobianValues& J,
                        const Factored& P) {
  const std::vector<int>& x = s.states;
  size_t nx = x.size(), nu = s.inputs.size(), n = J.Y.rows();
  MatrixXd rhs(n, nx + nu);
  rhs << J.Y(Eigen::all, x), J.U;
  MatrixXd W = -P.lu.solve(rhs);  // row j: δẋ_j (a state) or δz_j (algebraic) per unit δx, δu
  StateSpace ss;
  ss.A = W(x, Eigen::seqN(0, nx));
  ss.B = W(x, Eigen::seqN(nx, nu));
  MatrixXd CD = J.GY(Eigen::all, s.algebraic) * W(s.algebraic, Eigen::all) + J.GYp(Eigen::all, x) * W(x, Eigen::all);
  CD.leftCols(nx) += J.GY(Eigen::all, x);
  CD.rightCols(nu) += J.GU;
  ss.C = CD.leftCols(nx);
  ss.D = CD.rightCols(nu);
  for (int j : x) ss.states.push_back(d.variables[j].name);
  for (int k : s.inputs) ss.inputs.push_back(d.parameters[k].name);
  for (const auto& o : d.outputs) ss.outputs.push_back(o.name);
  return ss;
}

// The names and values of the point, and where the coordinates are among the states.
void describePoint(const dae::Dae& d, const Structure& s, const PointValues& p, LinearModel& m) {
  for (int j : s.states) m.statePoint.push_back(p.y(j));
  for (int q : s.coordinates) {
    m.coordinates.push_back(d.variables[q].name);
    m.point.push_back(p.y(q));
    m.coordinateStates.push_back(static_cast<int>(std::find(s.states.begin(), s.states.end(), q) - s.states.begin()));
  }
}

}  // namespace

Linearization linearize(const dae::Dae& d, sym::Context& ctx, const ModelValues& values, OperatingPoint at) {
  Linearization out;
  Structure s;
  if (out.error = structureOf(d, s); !out.error.empty()) return out;
  DaeJacobians jac(d, ctx, s.inputs);
  PointValues p(d, ctx, values.parameters, values.time);
  for (size_t j = 0; j < d.variables.size(); ++j) p.y(j) = values.start[j];
  LinearModel& m = out.model;
  m.equilibrium = at == OperatingPoint::Equilibrium;
  m.time = values.time;
  int startIterations = 0;  // not reported: newtonIterations counts the search for an equilibrium
  out.error = m.equilibrium ? findEquilibrium(jac, p, s, m.newtonIterations)
                            : solveStartState(jac, p, s, d.equations.size(), startIterations);
  if (!out.error.empty()) return out;
  JacobianValues J;
  if (!jac.evaluate(p, J)) {
    out.error = "the equations or their derivatives are not finite at the operating point";
    return out;
  }
  // T = ½ q̇ᵀ M q̇ must be positive for every motion: a zero or negative mass or inertia is the
  // user's mistake, not a mode.
  m.mechanical = secondOrderForm(d, s, J);
  if (m.mechanical && !positiveDefinite(m.mechanical->M)) {
    out.error =
        "the mass matrix is not positive definite at the operating point: check the masses and inertias "
        "(the kinetic energy must be positive for every motion)";
    return out;
  }
  MatrixXd matrix = derivativeMatrix(d, J);
  Factored P(matrix);
  if (!P.invertible) {
    out.error = indexReason(d, matrix);
    return out;
  }
  m.stateSpace = stateSpaceOf(d, s, J, P);
  describePoint(d, s, p, m);
  return out;
}

}  // namespace qdot::linear
