// The hand-written models the runtime tests integrate, each with its closed form or reference
// named where it is used, plus MemorySink (a ResultSink that keeps the rows for inspection) and
// a finite-difference check of each model's analytic Jacobian.
#pragma once

#include <cmath>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "HandModel.h"
#include "output/ResultSink.h"

namespace qdot::rt::test {

/// Keeps everything written to it.
struct MemorySink : ResultSink {
  std::vector<std::string> names;
  std::vector<double> times;
  std::vector<std::vector<double>> rows;
  bool finished = false;
  void begin(std::span<const std::string> columns) override { names.assign(columns.begin(), columns.end()); }
  void row(double t, std::span<const double> values) override {
    times.push_back(t);
    rows.emplace_back(values.begin(), values.end());
  }
  void finish() override { finished = true; }
};

/// Harmonic oscillator x'' = -omega^2 x as x' = v, v' = -omega^2 x; x(0) = 1, v(0) = 0, so
/// x = cos(omega t), v = -omega sin(omega t). Parameter omega (default given); output "a"
/// (acceleration -omega^2 x); invariant "E" = v^2/2 + omega^2 x^2/2.
inline HandModel oscillator(double omega) {
  HandModel m;
  m.name = "oscillator";
  m.variables = {"x", "v"};
  m.differential = {1, 1};
  m.parameterNames = {"omega"};
  m.parameterDefaults = {omega};
  m.outputNames = {"a"};
  m.invariantNames = {"E"};
  m.start = {1.0, 0.0};
  m.entries = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  m.residual = [](double, const double* y, const double* yp, const double* p, double* F) {
    F[0] = yp[0] - y[1];
    F[1] = yp[1] + p[0] * p[0] * y[0];
    return 0;
  };
  m.jacobian = [](double, const double*, const double*, const double* p, double cj, JacobianValues& J) {
    J(0, 0) = cj;
    J(0, 1) = -1;
    J(1, 0) = p[0] * p[0];
    J(1, 1) = cj;
    return 0;
  };
  m.outputs = [](double, const double* y, const double*, const double* p, double* out) {
    out[0] = -p[0] * p[0] * y[0];
    return 0;
  };
  m.invariants = [](double, const double* y, const double*, const double* p, double* out) {
    out[0] = 0.5 * y[1] * y[1] + 0.5 * p[0] * p[0] * y[0] * y[0];
    return 0;
  };
  return m;
}

/// Index-1 DAE y1' = -y1 + y2, 0 = y2 - y1^2/2 with y1(0) = 1 and an inconsistent y2(0) = 0.
/// Eliminating y2 gives the Bernoulli equation y1' = -y1 + y1^2/2; with u = 1/y1, u' = u - 1/2,
/// so y1 = 2 / (1 + e^t) and y2 = y1^2 / 2 (consistent y2(0) = 1/2).
inline HandModel bernoulliDae() {
  HandModel m;
  m.name = "bernoulli";
  m.variables = {"y1", "y2"};
  m.differential = {1, 0};
  m.start = {1.0, 0.0};
  m.entries = {{0, 0}, {0, 1}, {1, 0}, {1, 1}};
  m.residual = [](double, const double* y, const double* yp, const double*, double* F) {
    F[0] = yp[0] + y[0] - y[1];
    F[1] = y[1] - 0.5 * y[0] * y[0];
    return 0;
  };
  m.jacobian = [](double, const double* y, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj + 1;
    J(0, 1) = -1;
    J(1, 0) = -y[0];
    J(1, 1) = 1;
    return 0;
  };
  return m;
}

/// Robertson's chemical kinetics as the DAE of the SUNDIALS IDA examples:
/// y1' = -0.04 y1 + 1e4 y2 y3, y2' = 0.04 y1 - 1e4 y2 y3 - 3e7 y2^2, 0 = y1 + y2 + y3 - 1,
/// y(0) = (1, 0, 0). y2 gets a nominal of 1e-5 (its peak), as a modeller would give it.
inline HandModel robertson() {
  HandModel m;
  m.name = "robertson";
  m.variables = {"y1", "y2", "y3"};
  m.differential = {1, 1, 0};
  m.start = {1.0, 0.0, 0.0};
  m.nominal = {0.0, 1e-5, 0.0};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      m.entries.emplace_back(r, c);
  m.residual = [](double, const double* y, const double* yp, const double*, double* F) {
    F[0] = yp[0] + 0.04 * y[0] - 1e4 * y[1] * y[2];
    F[1] = yp[1] - 0.04 * y[0] + 1e4 * y[1] * y[2] + 3e7 * y[1] * y[1];
    F[2] = y[0] + y[1] + y[2] - 1;
    return 0;
  };
  m.jacobian = [](double, const double* y, const double*, const double*, double cj, JacobianValues& J) {
    J(0, 0) = cj + 0.04;
    J(0, 1) = -1e4 * y[2];
    J(0, 2) = -1e4 * y[1];
    J(1, 0) = -0.04;
    J(1, 1) = cj + 1e4 * y[2] + 6e7 * y[1];
    J(1, 2) = 1e4 * y[1];
    J(2, 0) = J(2, 1) = J(2, 2) = 1;
    return 0;
  };
  return m;
}

/// Heat conduction along a chain of n cells: y_i' = k (y_{i-1} - 2 y_i + y_{i+1}), y_0 = y_{n+1}
/// = 0, k = (n+1)^2, y_i(0) = sin(pi i h), h = 1/(n+1). The start is an eigenvector of the
/// tridiagonal matrix, so y_i(t) = exp(-lambda t) sin(pi i h) with lambda = 4 k sin^2(pi h / 2)
/// exactly (the discrete sine transform); the stiffness ratio is about 4 (n+1)^2 / pi^2.
inline HandModel heatChain(int n) {
  HandModel m;
  m.name = "chain";
  double h = 1.0 / (n + 1);
  for (int i = 0; i < n; ++i) {
    m.variables.push_back("T[" + std::to_string(i + 1) + "]");
    m.differential.push_back(1);
    m.start.push_back(std::sin(std::numbers::pi * (i + 1) * h));
    for (int j = std::max(0, i - 1); j <= std::min(n - 1, i + 1); ++j)
      m.entries.emplace_back(i, j);
  }
  double k = 1.0 / (h * h);
  m.residual = [n, k](double, const double* y, const double* yp, const double*, double* F) {
    for (int i = 0; i < n; ++i) {
      double left = i > 0 ? y[i - 1] : 0, right = i + 1 < n ? y[i + 1] : 0;
      F[i] = yp[i] - k * (left - 2 * y[i] + right);
    }
    return 0;
  };
  m.jacobian = [n, k](double, const double*, const double*, const double*, double cj, JacobianValues& J) {
    for (int i = 0; i < n; ++i) {
      J(i, i) = cj + 2 * k;
      if (i > 0) J(i, i - 1) = -k;
      if (i + 1 < n) J(i, i + 1) = -k;
    }
    return 0;
  };
  return m;
}

/// Largest |analytic - finite difference| of J = dF/dy + cj dF/dy' at (t, y, yp), relative to
/// max(1, |entry|), over ALL n x n entries (so entries missing from the pattern count too).
inline double jacobianMismatch(HandModel& model, double t, std::vector<double> y, std::vector<double> yp,
                               std::vector<double> p, double cj) {
  const QdotModel& m = model.abi();
  std::size_t n = m.nVariables;
  std::vector<double> values(m.jacobianNonzeros), dense(n * n, 0.0);
  m.jacobian(&m, t, y.data(), yp.data(), p.data(), cj, values.data());
  for (std::size_t c = 0; c < n; ++c)
    for (int32_t k = m.jacobianColumnStarts[c]; k < m.jacobianColumnStarts[c + 1]; ++k)
      dense[m.jacobianRowIndices[k] * n + c] = values[k];
  double worst = 0;
  std::vector<double> plus(n), minus(n);
  for (std::size_t c = 0; c < n; ++c) {
    double step = 1e-6 * std::max(1.0, std::abs(y[c]));
    auto shifted = [&](double sign, std::vector<double>& F) {
      std::vector<double> ys = y, yps = yp;
      ys[c] += sign * step;
      yps[c] += sign * cj * step;  // d/dy + cj d/dy' as one directional derivative
      m.residual(&m, t, ys.data(), yps.data(), p.data(), F.data());
    };
    shifted(1, plus);
    shifted(-1, minus);
    for (std::size_t r = 0; r < n; ++r) {
      double fd = (plus[r] - minus[r]) / (2 * step);
      worst = std::max(worst, std::abs(fd - dense[r * n + c]) / std::max(1.0, std::abs(fd)));
    }
  }
  return worst;
}

}  // namespace qdot::rt::test
