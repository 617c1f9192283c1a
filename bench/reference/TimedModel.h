// TimedModel: a ReferenceModel that forwards to another one and adds up the wall time spent in
// its residual and Jacobian (reference_sim --breakdown, the counterpart of vm_solve's wrappers).
#pragma once

#include <chrono>

#include "reference/ReferenceModel.h"

namespace qdot::bench {

class TimedModel final : public ReferenceModel {
 public:
  explicit TimedModel(const ReferenceModel& inner) : inner_(inner) {}

  uint32_t size() const override { return inner_.size(); }
  std::vector<std::string> variableNames() const override { return inner_.variableNames(); }
  std::vector<double> startValues() const override { return inner_.startValues(); }
  bool sparse() const override { return inner_.sparse(); }
  uint32_t jacobianNonzeros() const override { return inner_.jacobianNonzeros(); }

  void residual(const double* y, const double* yp, double* F) const override {
    auto t0 = Clock::now();
    inner_.residual(y, yp, F);
    residualSeconds += seconds(t0);
    ++residualCalls;
  }
  void denseJacobian(double cj, const double* y, const double* yp, double* J) const override {
    auto t0 = Clock::now();
    inner_.denseJacobian(cj, y, yp, J);
    jacobianSeconds += seconds(t0);
    ++jacobianCalls;
  }
  void sparseJacobian(double cj, const double* y, const double* yp, int64_t* columnStarts, int64_t* rowIndices,
                      double* values) const override {
    auto t0 = Clock::now();
    inner_.sparseJacobian(cj, y, yp, columnStarts, rowIndices, values);
    jacobianSeconds += seconds(t0);
    ++jacobianCalls;
  }

  mutable double residualSeconds = 0, jacobianSeconds = 0;
  mutable long residualCalls = 0, jacobianCalls = 0;

 private:
  using Clock = std::chrono::steady_clock;
  static double seconds(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

  const ReferenceModel& inner_;
};

}  // namespace qdot::bench
