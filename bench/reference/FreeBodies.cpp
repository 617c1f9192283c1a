// Hand-coded residual and Jacobian of n free bodies (see FreeBodies.h), one 13×13 block per body.
#include "reference/FreeBodies.h"

#include <cmath>
#include <stdexcept>

namespace qdot::bench {
namespace {

constexpr double kI[3] = {0.1, 0.2, 0.25};
constexpr double kG = 9.81;
// Offsets of a body's unknowns (and rows) in its block.
constexpr int kQ = 0, kR = 4, kV = 7, kW = 10;

}  // namespace

FreeBodies::FreeBodies(int bodies) : n_(bodies) {
  if (bodies < 1) throw std::invalid_argument("free bodies: need at least 1 body");
}

std::vector<std::string> FreeBodies::variableNames() const {
  std::vector<std::string> names;
  for (int i = 1; i <= n_; ++i) {
    std::string b = "b" + std::to_string(i) + ".";
    for (int k = 1; k <= 4; ++k) names.push_back(b + "q[" + std::to_string(k) + "]");
    for (const char* v : {"r", "v", "omega"})
      for (int k = 1; k <= 3; ++k) names.push_back(b + v + "[" + std::to_string(k) + "]");
  }
  return names;
}

// Body i (1-based): r = (0, 0, i), v = (0.1 sin i, 0, 0), ω = (1, 0.5, 2 + 0.01 i), q = (1, 0, 0, 0).
std::vector<double> FreeBodies::startValues() const {
  std::vector<double> y(size(), 0.0);
  for (int i = 1; i <= n_; ++i) {
    double* b = y.data() + 13 * (i - 1);
    b[kQ] = 1;
    b[kR + 2] = i;
    b[kV] = 0.1 * std::sin(i);
    b[kW] = 1;
    b[kW + 1] = 0.5;
    b[kW + 2] = 2 + 0.01 * i;
  }
  return y;
}

void FreeBodies::residual(const double* y, const double* yp, double* F) const {
  for (int i = 0; i < n_; ++i) {
    const double* b = y + 13 * i;
    const double* d = yp + 13 * i;
    double* f = F + 13 * i;
    const double a = b[0], x = b[1], yy = b[2], z = b[3], w1 = b[kW], w2 = b[kW + 1], w3 = b[kW + 2];
    const double k = std::sqrt(w1 * w1 + w2 * w2 + w3 * w3 + 1), s = 1 - (a * a + x * x + yy * yy + z * z);
    const double omegaQ[4] = {-w1 * x - w2 * yy - w3 * z, w1 * a + w3 * yy - w2 * z, w2 * a - w3 * x + w1 * z,
                              w3 * a + w2 * x - w1 * yy};
    for (int j = 0; j < 4; ++j) f[kQ + j] = d[kQ + j] - 0.5 * omegaQ[j] - 0.5 * k * s * b[j];
    for (int j = 0; j < 3; ++j) f[kR + j] = d[kR + j] - b[kV + j];
    const double m = mass(i + 1);
    for (int j = 0; j < 3; ++j) f[kV + j] = m * d[kV + j] - (j == 2 ? -m * kG : 0.0);
    f[kW] = kI[0] * d[kW] + (kI[2] - kI[1]) * w2 * w3;
    f[kW + 1] = kI[1] * d[kW + 1] + (kI[0] - kI[2]) * w3 * w1;
    f[kW + 2] = kI[2] * d[kW + 2] + (kI[1] - kI[0]) * w1 * w2;
  }
}

void FreeBodies::sparseJacobian(double cj, const double* y, const double*, int64_t* columnStarts, int64_t* rowIndices,
                                double* values) const {
  int64_t at = 0;
  auto put = [&](int64_t row, double value) {
    rowIndices[at] = row;
    values[at++] = value;
  };
  for (int i = 0; i < n_; ++i) {
    const double* b = y + 13 * i;
    const int64_t base = 13 * i;
    const double q[4] = {b[0], b[1], b[2], b[3]}, w[3] = {b[kW], b[kW + 1], b[kW + 2]};
    const double k = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] + 1);
    const double s = 1 - (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    // Ω(ω) with q' = ½ Ω q.
    const double Om[4][4] = {{0, -w[0], -w[1], -w[2]}, {w[0], 0, w[2], -w[1]}, {w[1], -w[2], 0, w[0]}, {w[2], w[1], -w[0], 0}};
    for (int c = 0; c < 4; ++c) {  // ∂F_q/∂q_c = cj δ − ½ Ω − ½ k (s δ − 2 q q_c)
      columnStarts[base + c] = at;
      for (int r = 0; r < 4; ++r)
        put(base + r, (r == c ? cj : 0.0) - 0.5 * Om[r][c] - 0.5 * k * ((r == c ? s : 0.0) - 2 * q[r] * q[c]));
    }
    for (int c = 0; c < 3; ++c) {
      columnStarts[base + kR + c] = at;
      put(base + kR + c, cj);
    }
    const double m = mass(i + 1);
    for (int c = 0; c < 3; ++c) {
      columnStarts[base + kV + c] = at;
      put(base + kR + c, -1.0);
      put(base + kV + c, m * cj);
    }
    // ∂(Ω q)/∂ω_c, and the Euler rows.
    const double dOm[3][4] = {{-q[1], q[0], q[3], -q[2]}, {-q[2], -q[3], q[0], q[1]}, {-q[3], q[2], -q[1], q[0]}};
    const double dEuler[3][3] = {{kI[0] * cj, (kI[2] - kI[1]) * w[2], (kI[2] - kI[1]) * w[1]},
                                 {(kI[0] - kI[2]) * w[2], kI[1] * cj, (kI[0] - kI[2]) * w[0]},
                                 {(kI[1] - kI[0]) * w[1], (kI[1] - kI[0]) * w[0], kI[2] * cj}};
    for (int c = 0; c < 3; ++c) {
      columnStarts[base + kW + c] = at;
      for (int r = 0; r < 4; ++r) put(base + r, -0.5 * dOm[c][r] - 0.5 * s * q[r] * w[c] / k);
      for (int r = 0; r < 3; ++r) put(base + kW + r, dEuler[r][c]);
    }
  }
  columnStarts[size()] = at;
}

}  // namespace qdot::bench
