// A chain of unequal masses and springs (examples/vibration/nonuniform_chain.qd), whose sums read
// the arrays of parameters m[i] and k[i+1] in loops (ldpl, docs/loops.md), simulated by `qdot run`
// and compared with its modal solution at every output time. Some masses and springs are given with
// -p, so the check also covers values set at run time reaching the loops.
#include <Eigen/Dense>
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// The undamped chain from rest at x(0): M ẍ + K x = 0 with M = diag(m), K = Σ_j k_j d_j d_jᵀ
// (d_1 = e_1: spring 1 to the wall; d_j = e_j − e_(j−1)). With K φ = ω² M φ, Φᵀ M Φ = I (Eigen's
// generalized self-adjoint solver), x(t) = Φ diag(cos ω t) Φᵀ M x(0).
struct ModalChain {
  Eigen::VectorXd omega, modal;  // ω_r and Φᵀ M x(0)
  Eigen::MatrixXd shapes;        // Φ

  ModalChain(const Eigen::VectorXd& m, const Eigen::VectorXd& k, const Eigen::VectorXd& x0) {
    const long n = m.size();
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n, n);
    K(0, 0) = k(0);
    for (long j = 1; j < n; ++j) {
      K(j, j) += k(j), K(j - 1, j - 1) += k(j);
      K(j, j - 1) -= k(j), K(j - 1, j) -= k(j);
    }
    Eigen::MatrixXd M = m.asDiagonal();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> modes(K, M);
    omega = modes.eigenvalues().cwiseSqrt();
    shapes = modes.eigenvectors();
    modal = shapes.transpose() * M * x0;
  }
  double x(long i, double t) const {
    double s = 0;
    for (long r = 0; r < omega.size(); ++r) s += shapes(i, r) * modal(r) * std::cos(omega(r) * t);
    return s;
  }
  // max over coordinates of Σ_r |φ_ir q_r|: no |x_i(t)| exceeds it.
  double amplitude() const { return (shapes.cwiseAbs() * modal.cwiseAbs()).maxCoeff(); }
};

// n = 12, c = 0 (undamped), m[5] = 2.5 and k[3] = 600 given with -p; the other masses
// 1 + 0.5 sin(i), springs 1000, x_i(0) = 0.01 i. Bound: oscillationBound with the amplitude above and
// the shortest period 2π/ω_max (measured max error/bound: see the [measured] lines).
TEST(NonUniformChain, MovesAsTheSumOfItsNormalModes) {
  const long n = 12;
  Eigen::VectorXd m(n), k = Eigen::VectorXd::Constant(n, 1000), x0(n);
  for (long i = 0; i < n; ++i) m(i) = 1 + 0.5 * std::sin(double(i + 1)), x0(i) = 0.01 * double(i + 1);
  m(4) = 2.5, k(2) = 600;
  ModalChain chain(m, k, x0);
  const double period = 2 * M_PI / chain.omega.maxCoeff(), amplitude = chain.amplitude();
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-8}) {
    auto r = runQdot("examples/vibration/nonuniform_chain.qd",
                     {"-p", "n=12", "-p", "c=0", "-p", "m[5]=2.5", "-p", "k[3]=600", "--rtol", num(rtol), "--stop",
                      "0.5", "--interval", "0.01"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 0.5, 0.01);
    double worst = 0;
    for (long i = 0; i < n; ++i) {
      auto d = compareColumn(
          r, "x[" + std::to_string(i + 1) + "]", [&](double t) { return chain.x(i, t); },
          [&](double t) { return oscillationBound(rtol, amplitude, period, t); });
      worst = std::max(worst, d.maxError);
    }
    EXPECT_LT(worst, previous / 10);
    previous = worst;
  }
}

// The uniform chain written through definitions and factors (chain_definitions.qd) and with its
// energies in `for` loops (chain_for_energies.qd), undamped (-p c=0): each moves as the sum of the
// chain's normal modes, with the same bound as above. The definitions' energy output E stays at
// its start value ½ k Σ (0.01)² = 0.04 k (no dissipation: E is conserved to the tolerance).
TEST(UniformChain, WrittenThroughDefinitionsOrLoopsMovesAsItsNormalModes) {
  const long n = 12;
  const double rtol = 1e-8;
  Eigen::VectorXd m = Eigen::VectorXd::Constant(n, 1.5), k = Eigen::VectorXd::Constant(n, 800), x0(n);
  for (long i = 0; i < n; ++i) x0(i) = 0.01 * double(i + 1);
  ModalChain chain(m, k, x0);
  const double period = 2 * M_PI / chain.omega.maxCoeff(), amplitude = chain.amplitude();
  for (const char* model : {"tests/sim/models/chain_definitions.qd", "tests/sim/models/chain_for_energies.qd"}) {
    auto r = runQdot(model, {"-p", "c=0", "--rtol", num(rtol), "--stop", "0.5", "--interval", "0.01"});
    ASSERT_EQ(r.exitCode, 0) << model << "\n" << r.log;
    expectGrid(r, 0, 0.5, 0.01);
    for (long i = 0; i < n; ++i)
      compareColumn(
          r, "x[" + std::to_string(i + 1) + "]", [&](double t) { return chain.x(i, t); },
          [&](double t) { return oscillationBound(rtol, amplitude, period, t); });
    if (r.has("E")) {
      const double e0 = 0.5 * 800 * 12 * 0.01 * 0.01;
      compareColumn(r, "E", [&](double) { return e0; }, [&](double) { return 100 * rtol * e0; });
      compareColumn(r, "P", [](double) { return 0.0; }, [](double) { return 1e-300; });
    }
  }
}

}  // namespace
}  // namespace qdot::simtest
