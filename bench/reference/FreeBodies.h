// n free rigid bodies under gravity written by hand, as bench/rigid_bench.py generates them for
// qdot (`body b<i>(mass = m_i, inertia = {0.1, 0.2, 0.25}, r(start = …), v(start = …),
// omega(start = …))`, no contacts): per body the unknowns q (4), r, v, omega (3 each) and rows
//   F_q = q' − ½ Ω(ω) q − ½ k (1 − |q|²) q,  k = √(ω·ω + 1)   (quaternion kinematics, as qdot's)
//   F_r = r' − v,   F_v = m v' − m g,   F_ω = I ω' + ω × (I ω)   (I diagonal).
// The Jacobian is block diagonal (46 nonzeros per body), CSC for KLU.
#pragma once

#include "reference/ReferenceModel.h"

namespace qdot::bench {

class FreeBodies final : public ReferenceModel {
 public:
  explicit FreeBodies(int bodies);

  uint32_t size() const override { return 13 * static_cast<uint32_t>(n_); }
  std::vector<std::string> variableNames() const override;
  std::vector<double> startValues() const override;
  void residual(const double* y, const double* yp, double* F) const override;
  bool sparse() const override { return true; }
  uint32_t jacobianNonzeros() const override { return 46 * static_cast<uint32_t>(n_); }
  void sparseJacobian(double cj, const double* y, const double* yp, int64_t* columnStarts, int64_t* rowIndices,
                      double* values) const override;

  /// The body's mass and start values, shared with the generated .qd text (rigid_bench.py).
  static double mass(int i) { return 1 + 0.01 * i; }

 private:
  int n_;
};

}  // namespace qdot::bench
