// Newton on the initialization system (see InitialSystem.h), dense: a model with initial
// equations that are not start values is solved once, at t0.
#include "ida/InitialSystem.h"

#include <Eigen/Dense>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "ida/ModelCheck.h"

namespace qdot::rt {
namespace {

constexpr int kMaxIterations = 100;
constexpr uint32_t kMaxDense = 4000;  ///< unknowns; the dense QR is O(n^3)

class InitialSystem {
 public:
  InitialSystem(const QdotModel& m, const std::vector<char>& keptRow, const int32_t* isDifferential,
                const int32_t* fixed, const double* p, double t0)
      : m_(m), p_(p), t0_(t0), n_(m.nVariables), F_(m.nResiduals), J0_(m.jacobianNonzeros), J1_(m.jacobianNonzeros) {
    for (uint32_t r = 0; r < m.nResiduals; ++r)
      if (r >= m.nResiduals - m.nInitialRows || keptRow[r]) rowOf_.push_back(static_cast<int>(r));
    rowIndex_.assign(m.nResiduals, -1);
    for (size_t k = 0; k < rowOf_.size(); ++k) rowIndex_[rowOf_[k]] = static_cast<int>(k);
    columnOfDerivative_.assign(n_, -1);
    for (uint32_t j = 0; j < n_; ++j)
      if (isDifferential[j]) columnOfDerivative_[j] = static_cast<int>(n_ + derivatives_.size()), derivatives_.push_back(j);
    for (uint32_t j = 0; j < n_; ++j)
      if (fixed[j]) fixedVariables_.push_back(j);
  }

  InitialSystemResult solve(double* y, double* yp) {
    if (n_ > kMaxDense)
      throw std::runtime_error(fmt::format("the initialization system has {} unknowns, more than the dense solver "
                                           "takes ({}): give the start values instead of initial equations", n_, kMaxDense));
    start_.assign(y, y + n_);
    Eigen::VectorXd z = pack(y, yp);
    Eigen::VectorXd G = conditions(z);
    InitialSystemResult result;
    while (result.iterations < kMaxIterations && G.lpNorm<Eigen::Infinity>() > tolerance(z)) {
      ++result.iterations;
      Eigen::VectorXd step = jacobian(z).colPivHouseholderQr().solve(-G);
      double lambda = 1;  // damped: accept the first halving that decreases |G|
      Eigen::VectorXd next = z + step, Gnext = conditions(next);
      while (Gnext.norm() >= G.norm() && lambda > 1e-4) {
        lambda /= 2;
        next = z + lambda * step;
        Gnext = conditions(next);
      }
      if (Gnext.norm() >= G.norm()) break;
      z = next, G = Gnext;
    }
    result.residual = G.lpNorm<Eigen::Infinity>();
    if (result.residual > 1e3 * tolerance(z)) fail(G, result.iterations);
    unpack(z, y, yp);
    return result;
  }

 private:
  double tolerance(const Eigen::VectorXd& z) const { return 1e-10 * std::max(1.0, z.head(n_).lpNorm<Eigen::Infinity>()); }

  Eigen::VectorXd pack(const double* y, const double* yp) const {
    Eigen::VectorXd z(n_ + derivatives_.size());
    for (uint32_t j = 0; j < n_; ++j) z[j] = y[j];
    for (size_t k = 0; k < derivatives_.size(); ++k) z[n_ + k] = yp[derivatives_[k]];
    return z;
  }
  void unpack(const Eigen::VectorXd& z, double* y, double* yp) const {
    for (uint32_t j = 0; j < n_; ++j) y[j] = z[j];
    for (size_t k = 0; k < derivatives_.size(); ++k) yp[derivatives_[k]] = z[n_ + k];
  }
  void load(const Eigen::VectorXd& z) {
    y_.assign(n_, 0.0), yp_.assign(n_, 0.0);
    unpack(z, y_.data(), yp_.data());
  }

  // The rows used, then one per fixed start: y_j - start_j.
  Eigen::VectorXd conditions(const Eigen::VectorXd& z) {
    load(z);
    if (m_.residual(&m_, t0_, y_.data(), yp_.data(), p_, F_.data()) != 0)
      throw std::runtime_error("the residual cannot be evaluated at the start: " + modelLastError(m_));
    Eigen::VectorXd G(rowOf_.size() + fixedVariables_.size());
    for (size_t k = 0; k < rowOf_.size(); ++k) G[k] = F_[rowOf_[k]];
    for (size_t k = 0; k < fixedVariables_.size(); ++k)
      G[rowOf_.size() + k] = z[fixedVariables_[k]] - start_[fixedVariables_[k]];
    if (!G.allFinite()) throw std::runtime_error("a condition at the start is not finite: " + modelLastError(m_));
    return G;
  }

  Eigen::MatrixXd jacobian(const Eigen::VectorXd& z) {
    load(z);
    if (m_.jacobian(&m_, t0_, y_.data(), yp_.data(), p_, 0.0, J0_.data()) != 0 ||
        m_.jacobian(&m_, t0_, y_.data(), yp_.data(), p_, 1.0, J1_.data()) != 0)
      throw std::runtime_error("the Jacobian cannot be evaluated at the start: " + modelLastError(m_));
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rowOf_.size() + fixedVariables_.size()),
                                              static_cast<Eigen::Index>(z.size()));
    for (uint32_t j = 0; j < n_; ++j)
      for (int32_t k = m_.jacobianColumnStarts[j]; k < m_.jacobianColumnStarts[j + 1]; ++k) {
        int row = rowIndex_[m_.jacobianRowIndices[k]];
        if (row < 0) continue;
        A(row, j) = J0_[k];
        if (columnOfDerivative_[j] >= 0) A(row, columnOfDerivative_[j]) = J1_[k] - J0_[k];
      }
    for (size_t k = 0; k < fixedVariables_.size(); ++k) A(static_cast<Eigen::Index>(rowOf_.size() + k), fixedVariables_[k]) = 1;
    return A;
  }

  [[noreturn]] void fail(const Eigen::VectorXd& G, int iterations) const {
    Eigen::Index worst = 0;
    G.cwiseAbs().maxCoeff(&worst);
    std::string what;
    auto k = static_cast<size_t>(worst);
    uint32_t firstInitial = m_.nResiduals - m_.nInitialRows;
    if (k >= rowOf_.size()) what = fmt::format("the fixed start value of {}", m_.variableNames[fixedVariables_[k - rowOf_.size()]]);
    else if (static_cast<uint32_t>(rowOf_[k]) >= firstInitial) what = m_.initialRowLabels[rowOf_[k] - firstInitial];
    else what = fmt::format("equation {} of the model", rowOf_[k] + 1);
    throw std::runtime_error(fmt::format(
        "the initial conditions cannot all hold: {} is off by {:.3g} after {} Newton iterations (the conditions "
        "contradict each other, or the start values are too far from a solution)",
        what, G[worst], iterations));
  }

  const QdotModel& m_;
  const double* p_;
  double t0_;
  uint32_t n_;
  std::vector<int> rowOf_, rowIndex_, columnOfDerivative_;
  std::vector<uint32_t> derivatives_, fixedVariables_;
  std::vector<double> start_, y_, yp_, F_, J0_, J1_;
};

}  // namespace

InitialSystemResult solveInitialSystem(const QdotModel& full, const std::vector<char>& keptRow,
                                       const int32_t* isDifferential, const int32_t* fixed, const double* p,
                                       double t0, double* y, double* yp) {
  return InitialSystem(full, keptRow, isDifferential, fixed, p, t0).solve(y, yp);
}

}  // namespace qdot::rt
