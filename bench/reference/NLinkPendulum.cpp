// Hand-coded residual and analytic Jacobian of the N-link pendulum (see NLinkPendulum.h). The
// differences θ_i − θ_j enter only through sin θ and cos θ of each angle:
// cos(θ_i − θ_j) = c_i c_j + s_i s_j and sin(θ_i − θ_j) = s_i c_j − c_i s_j.
#include "reference/NLinkPendulum.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace qdot::bench {

NLinkPendulum::NLinkPendulum(int links, double m, double l, double g)
    : n_(links), m_(m), l_(l), g_(g), sin_(links), cos_(links) {}

std::vector<std::string> NLinkPendulum::variableNames() const {
  std::vector<std::string> names;
  for (int i = 1; i <= n_; ++i) names.push_back("th[" + std::to_string(i) + "]");
  for (int i = 1; i <= n_; ++i) names.push_back("der(th[" + std::to_string(i) + "])");
  return names;
}

std::vector<double> NLinkPendulum::startValues() const {
  std::vector<double> y(size(), 0.0);
  std::fill(y.begin(), y.begin() + n_, 0.3);
  return y;
}

double NLinkPendulum::inertia(int i, int j) const { return m_ * l_ * l_ * (n_ - std::max(i, j)); }

void NLinkPendulum::sinCos(const double* theta) const {
  for (int i = 0; i < n_; ++i) {
    sin_[i] = std::sin(theta[i]);
    cos_[i] = std::cos(theta[i]);
  }
}

void NLinkPendulum::residual(const double* y, const double* yp, double* F) const {
  const double* omega = y + n_;
  const double* alpha = yp + n_;  // ω'
  sinCos(y);
  for (int i = 0; i < n_; ++i) {
    double row = m_ * g_ * l_ * (n_ - i) * sin_[i] + inertia(i, i) * alpha[i];
    for (int j = 0; j < n_; ++j) {
      if (j == i) continue;
      double cosD = cos_[i] * cos_[j] + sin_[i] * sin_[j];
      double sinD = sin_[i] * cos_[j] - cos_[i] * sin_[j];
      row += inertia(i, j) * (cosD * alpha[j] + sinD * omega[j] * omega[j]);
    }
    F[i] = row;
  }
  for (int i = 0; i < n_; ++i) F[n_ + i] = yp[i] - omega[i];
}

// Column-major N x N (N = 2n). Column θ_k: ∂F_i/∂θ_k = A_ik (sin(θ_i − θ_k) ω'_k − cos(θ_i − θ_k) ω_k²)
// for i ≠ k, the diagonal G_i cos θ_i minus the others of its row, and cj in row n + k.
// Column ω_k: 2 A_ik sin(θ_i − θ_k) ω_k + cj A_ik cos(θ_i − θ_k), and −1 in row n + k.
void NLinkPendulum::denseJacobian(double cj, const double* y, const double* yp, double* J) const {
  const int N = 2 * n_;
  const double* omega = y + n_;
  const double* alpha = yp + n_;
  sinCos(y);
  for (int k = 0; k < n_; ++k) {
    double* theta = J + static_cast<std::ptrdiff_t>(k) * N;
    double* velocity = J + static_cast<std::ptrdiff_t>(n_ + k) * N;
    for (int i = 0; i < n_; ++i) {
      double a = inertia(i, k);
      if (i == k) {  // θ_i − θ_i = 0: the diagonal of the θ block is completed below
        velocity[i] = cj * a;
        continue;
      }
      double cosD = cos_[i] * cos_[k] + sin_[i] * sin_[k];
      double sinD = sin_[i] * cos_[k] - cos_[i] * sin_[k];
      double entry = a * (sinD * alpha[k] - cosD * omega[k] * omega[k]);
      theta[i] = entry;
      J[static_cast<std::ptrdiff_t>(i) * N + i] -= entry;  // accumulates the diagonal of row i
      velocity[i] = 2 * a * sinD * omega[k] + cj * a * cosD;
    }
    theta[n_ + k] = cj;
    velocity[n_ + k] = -1;
  }
  for (int i = 0; i < n_; ++i) J[static_cast<std::ptrdiff_t>(i) * N + i] += m_ * g_ * l_ * (n_ - i) * cos_[i];
}

}  // namespace qdot::bench
