// Natural frequencies, damping ratios and mode shapes of a linearized model: of M q̈ + C q̇ + K q = 0
// when it is a mechanical one, else of its state-space matrix A.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <complex>
#include <ostream>

#include "linear/Linearize.h"

namespace qdot::linear {
namespace {

// Scales v so that its largest component (by magnitude) is +1.
template <class Vector>
std::vector<double> normalised(const Vector& v) {
  Eigen::Index k = 0;
  v.cwiseAbs().maxCoeff(&k);
  std::vector<double> out(v.size());
  for (Eigen::Index i = 0; i < v.size(); ++i) out[i] = std::real(v(i) / v(k));
  return out;
}

bool symmetric(const Eigen::MatrixXd& A) { return (A - A.transpose()).norm() <= 1e-12 * std::max(1.0, A.norm()); }

// C = 0, M and K symmetric: K v = ω² M v.
std::vector<Mode> undampedModes(const SecondOrderSystem& s) {
  Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(s.K, s.M);
  std::vector<Mode> out;
  double scale = std::max(1e-300, es.eigenvalues().cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < es.eigenvalues().size(); ++i) {
    double w2 = es.eigenvalues()(i);
    Mode m;
    m.shape = normalised(Eigen::VectorXd(es.eigenvectors().col(i)));
    if (w2 >= -1e-12 * scale) {
      m.omega = std::sqrt(std::max(0.0, w2));
      m.oscillating = m.omega > 0;
    } else {  // an unstable equilibrium: motion grows as e^(rate t)
      m.oscillating = false;
      m.rate = std::sqrt(-w2);
    }
    out.push_back(m);
  }
  return out;
}

// The eigenvalues of a first-order system x' = A x; shapes over the states `shown`.
std::vector<Mode> firstOrderModes(const Eigen::MatrixXd& A, const std::vector<int>& shown) {
  Eigen::EigenSolver<Eigen::MatrixXd> es(A);
  std::vector<Mode> out;
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    std::complex<double> l = es.eigenvalues()(i);
    double tol = 1e-10 * std::max(1.0, std::abs(l));
    if (l.imag() < -tol) continue;  // the conjugate of an oscillating mode
    Mode m;
    m.shape = normalised(Eigen::VectorXcd(es.eigenvectors().col(i)(shown)));
    if (l.imag() > tol) {
      m.omega = std::abs(l);
      m.zeta = -l.real() / m.omega;
    } else {
      m.oscillating = false;
      m.rate = l.real();
    }
    out.push_back(m);
  }
  return out;
}

// The first-order form [q; q̇]' = [0 I; -M⁻¹K -M⁻¹C] [q; q̇].
std::vector<Mode> dampedModes(const SecondOrderSystem& s) {
  Eigen::Index n = s.M.rows();
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(s.M);  // M is positive definite (linearize checks)
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  A.bottomLeftCorner(n, n) = -lu.solve(s.K);
  A.bottomRightCorner(n, n) = -lu.solve(s.C);
  std::vector<int> coordinates(n);
  for (Eigen::Index i = 0; i < n; ++i) coordinates[i] = static_cast<int>(i);
  return firstOrderModes(A, coordinates);
}

std::vector<Mode> modesOf(const LinearModel& m) {
  if (const auto& s = m.mechanical) {
    bool undamped = s->C.isZero(0) && symmetric(s->M) && symmetric(s->K);
    return undamped ? undampedModes(*s) : dampedModes(*s);
  }
  std::vector<int> shown = m.coordinateStates;
  if (shown.empty())  // a first-order model: shapes over all its states
    for (int i = 0; i < static_cast<int>(m.stateSpace.states.size()); ++i) shown.push_back(i);
  return firstOrderModes(m.stateSpace.A, shown);
}

}  // namespace

std::vector<Mode> modes(const LinearModel& m) {
  std::vector<Mode> out = modesOf(m);
  std::stable_sort(out.begin(), out.end(), [](const Mode& a, const Mode& b) {
    if (a.oscillating != b.oscillating) return a.oscillating;
    return a.oscillating ? a.omega < b.omega : a.rate < b.rate;
  });
  return out;
}

}  // namespace qdot::linear
