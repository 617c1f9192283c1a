// The spring–damper chain of examples/vibration/spring_chain.qd written by hand: n masses m,
// springs k and dampers c between neighbours, the first tied to a wall, the last free.
// Unknowns x_1..x_n, v_1..v_n (v = der(x)); rows (x_0 = v_0 = 0 at the wall, no right
// neighbour for the last mass)
//   F_i     = m v'_i + k (x_i − x_{i−1}) − k (x_{i+1} − x_i) + c (v_i − v_{i−1}) − c (v_{i+1} − v_i),
//   F_{n+i} = x'_i − v_i.
// The Jacobian is sparse (CSC, 8n − 4 nonzeros) in the same pattern qdot emits.
#pragma once

#include "reference/ReferenceModel.h"

namespace qdot::bench {

class SpringChain final : public ReferenceModel {
 public:
  /// The model's defaults: m = 1 kg, k = 1000 N/m, c = 0.5 N s/m, x_i(0) = 0.01 i m, v(0) = 0.
  /// Needs masses >= 2.
  explicit SpringChain(int masses, double m = 1, double k = 1000, double c = 0.5);

  uint32_t size() const override { return 2 * static_cast<uint32_t>(n_); }
  std::vector<std::string> variableNames() const override;
  std::vector<double> startValues() const override;
  void residual(const double* y, const double* yp, double* F) const override;
  bool sparse() const override { return true; }
  uint32_t jacobianNonzeros() const override { return 8 * static_cast<uint32_t>(n_) - 4; }
  void sparseJacobian(double cj, const double* y, const double* yp, int64_t* columnStarts, int64_t* rowIndices,
                      double* values) const override;

 private:
  int n_;
  double m_, k_, c_;
};

}  // namespace qdot::bench
