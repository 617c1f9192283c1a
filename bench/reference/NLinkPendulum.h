// The N-link pendulum of examples/pendulum/nlink.qd written by hand: n point masses m on massless
// rods of length l. Unknowns θ_1..θ_n, ω_1..ω_n (ω = der(θ)); rows
//   F_i     = Σ_j A_ij (cos(θ_i − θ_j) ω'_j + sin(θ_i − θ_j) ω_j²) + G_i sin θ_i,
//   F_{n+i} = θ'_i − ω_i,
// with A_ij = m l² (n − max(i,j) + 1) and G_i = m g l (n − i + 1) (1-based i, j).
#pragma once

#include <vector>

#include "reference/ReferenceModel.h"

namespace qdot::bench {

class NLinkPendulum final : public ReferenceModel {
 public:
  /// The model's defaults: m = 1 kg, l = 1 m, g = 9.81 m/s², θ(0) = 0.3 rad, ω(0) = 0.
  explicit NLinkPendulum(int links, double m = 1, double l = 1, double g = 9.81);

  uint32_t size() const override { return 2 * static_cast<uint32_t>(n_); }
  std::vector<std::string> variableNames() const override;
  std::vector<double> startValues() const override;
  void residual(const double* y, const double* yp, double* F) const override;
  bool sparse() const override { return false; }
  void denseJacobian(double cj, const double* y, const double* yp, double* J) const override;

 private:
  double inertia(int i, int j) const;  ///< A_ij (0-based)
  void sinCos(const double* theta) const;

  int n_;
  double m_, l_, g_;
  mutable std::vector<double> sin_, cos_;  // sin θ_i, cos θ_i of the current evaluation
};

}  // namespace qdot::bench
