// M, C, K of the Euler–Lagrange rows by symbolic differentiation, evaluated at an operating point
// found by Newton's method on the static rows (velocities and accelerations zero).
#include "linear/Linearize.h"

#include <cmath>
#include <limits>

namespace qdot::linear {
namespace {

using sym::Expr;

// The symbols of coordinate j: q, q̇ (its velocity variable's y) and q̈ (that variable's y').
struct CoordinateSymbols {
  Expr q = nullptr, v = nullptr, a = nullptr;
  int qVar = -1, vVar = -1;
};

std::string findCoordinates(const dae::Dae& d, std::vector<CoordinateSymbols>& out) {
  for (const auto& v : d.variables)
    if (v.role == dae::UnknownRole::Multiplier)
      return "the model has constraints (multiplier " + v.name + "); modes need an unconstrained model";
  for (int qi : d.coordinates) {
    CoordinateSymbols c;
    c.q = d.variables[qi].y;
    c.qVar = qi;
    std::string velocity = "der(" + d.variables[qi].name + ")";
    for (size_t j = 0; j < d.variables.size(); ++j)
      if (d.variables[j].name == velocity && d.variables[j].yp) c.vVar = static_cast<int>(j);
    if (c.vVar < 0)
      return "coordinate " + d.variables[qi].name + " has no inertia (no acceleration in its equation of motion)";
    c.v = d.variables[c.vVar].y;
    c.a = d.variables[c.vVar].yp;
    out.push_back(c);
  }
  if (out.empty()) return "the model has no coordinates";
  return "";
}

// The rows and their partial derivatives with respect to a, v, q, evaluated together.
class RowJacobians {
 public:
  RowJacobians(const dae::Dae& d, sym::Context& ctx, const std::vector<CoordinateSymbols>& cs) : cs_(cs) {
    size_t n = cs.size();
    for (size_t i = 0; i < n; ++i) roots_.push_back(d.equations[i].residual);
    for (auto pick : {&CoordinateSymbols::a, &CoordinateSymbols::v, &CoordinateSymbols::q})
      for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) roots_.push_back(ctx.diff(d.equations[i].residual, cs[j].*pick));
  }

  /// Evaluates everything at `values`; false if a value is not finite (a row depends on something
  /// that is not a coordinate, velocity, parameter or time, or the point is singular).
  bool evaluate(std::span<const double> values, Eigen::VectorXd& F, Eigen::MatrixXd& M, Eigen::MatrixXd& C,
                Eigen::MatrixXd& K) const {
    size_t n = cs_.size();
    std::vector<double> out(roots_.size());
    sym::evaluate(roots_, values, out);
    F.resize(n), M.resize(n, n), C.resize(n, n), K.resize(n, n);
    for (size_t i = 0; i < n; ++i) F(i) = out[i];
    Eigen::MatrixXd* mats[3] = {&M, &C, &K};
    for (size_t m = 0; m < 3; ++m)
      for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) (*mats[m])(i, j) = out[n + m * n * n + i * n + j];
    for (double x : out)
      if (!std::isfinite(x)) return false;
    return true;
  }

 private:
  const std::vector<CoordinateSymbols>& cs_;
  std::vector<Expr> roots_;
};

struct Point {
  std::vector<double> values;  ///< by symbol id
  const std::vector<CoordinateSymbols>* cs;
  void set(const Eigen::VectorXd& q, const Eigen::VectorXd& v, const Eigen::VectorXd& a) {
    for (size_t j = 0; j < cs->size(); ++j) {
      values[(*cs)[j].q->symbolId] = q(j);
      values[(*cs)[j].v->symbolId] = v(j);
      values[(*cs)[j].a->symbolId] = a(j);
    }
  }
};

// Newton on F(q, 0, 0) = 0 with K as the Jacobian, halving steps that do not reduce |F|.
std::string findEquilibrium(const RowJacobians& rows, Point& p, Eigen::VectorXd& q, int& iterations) {
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(q.size()), F, Fn;
  Eigen::MatrixXd M, C, K;
  for (iterations = 0; iterations < 100; ++iterations) {
    p.set(q, zero, zero);
    if (!rows.evaluate(p.values, F, M, C, K)) return "the equations of motion are not finite at q = start";
    double scale = std::max(1.0, K.cwiseAbs().maxCoeff() * (1 + q.cwiseAbs().maxCoeff()));
    if (F.cwiseAbs().maxCoeff() <= 1e-13 * scale) return "";
    Eigen::FullPivLU<Eigen::MatrixXd> lu(K);
    if (!lu.isInvertible())
      return "no isolated static equilibrium near the start values (the stiffness matrix is singular there); "
             "--at start linearizes about the start state";
    Eigen::VectorXd step = lu.solve(-F);
    double t = 1;
    for (int halvings = 0; halvings < 40; ++halvings, t /= 2) {
      p.set(q + t * step, zero, zero);
      if (rows.evaluate(p.values, Fn, M, C, K) && Fn.norm() < F.norm()) break;
    }
    q += t * step;
    if (step.cwiseAbs().maxCoeff() * t <= 1e-15 * (1 + q.cwiseAbs().maxCoeff())) return "";
  }
  return "Newton's method found no static equilibrium from the start values in 100 iterations; "
         "try --at start";
}

}  // namespace

Linearization linearize(const dae::Dae& d, sym::Context& ctx, const ModelValues& values, OperatingPoint at) {
  Linearization out;
  std::vector<CoordinateSymbols> cs;
  if (out.error = findCoordinates(d, cs); !out.error.empty()) return out;
  RowJacobians rows(d, ctx, cs);
  Point p{std::vector<double>(ctx.symbolCount(), std::numeric_limits<double>::quiet_NaN()), &cs};
  for (size_t k = 0; k < d.parameters.size(); ++k) p.values[d.parameters[k].symbol->symbolId] = values.parameters[k];
  p.values[d.time->symbolId] = values.time;
  size_t n = cs.size();
  Eigen::VectorXd q(n), v = Eigen::VectorXd::Zero(n), a = Eigen::VectorXd::Zero(n), F;
  for (size_t j = 0; j < n; ++j) q(j) = values.start[cs[j].qVar];
  SecondOrderSystem& s = out.system;
  if (at == OperatingPoint::Equilibrium) {
    if (out.error = findEquilibrium(rows, p, q, s.newtonIterations); !out.error.empty()) return out;
    s.equilibrium = true;
  } else {
    for (size_t j = 0; j < n; ++j) v(j) = values.start[cs[j].vVar];
    p.set(q, v, a);  // the rows are linear in a: a = -M⁻¹ F(q, v, 0)
    if (rows.evaluate(p.values, F, s.M, s.C, s.K)) a = s.M.fullPivLu().solve(-F);
  }
  p.set(q, v, a);
  if (!rows.evaluate(p.values, F, s.M, s.C, s.K)) {
    out.error = "the equations of motion depend on something other than coordinates, velocities, parameters "
                "and time (an algebraic unknown), or are not finite at the operating point";
    return out;
  }
  // T = ½ q̇ᵀ M q̇ must be positive for every motion: a zero or negative mass or inertia is the
  // user's mistake, not a mode.
  if (Eigen::LLT<Eigen::MatrixXd> llt(0.5 * (s.M + s.M.transpose())); llt.info() != Eigen::Success) {
    out.error = "the mass matrix is not positive definite at the operating point: check the masses and inertias "
                "(the kinetic energy must be positive for every motion)";
    return out;
  }
  for (size_t j = 0; j < n; ++j) s.coordinates.push_back(d.variables[cs[j].qVar].name);
  s.point.assign(q.data(), q.data() + n);
  s.time = values.time;
  return out;
}

}  // namespace qdot::linear
