// Hand-coded residual and analytic Jacobian of the spring–damper chain (see SpringChain.h): one
// pass over the masses, the wall end and the free end peeled off the loop.
#include "reference/SpringChain.h"

#include <stdexcept>
#include <string>

namespace qdot::bench {

SpringChain::SpringChain(int masses, double m, double k, double c) : n_(masses), m_(m), k_(k), c_(c) {
  if (masses < 2) throw std::invalid_argument("the spring chain needs at least 2 masses");
}

std::vector<std::string> SpringChain::variableNames() const {
  std::vector<std::string> names;
  for (int i = 1; i <= n_; ++i) names.push_back("x[" + std::to_string(i) + "]");
  for (int i = 1; i <= n_; ++i) names.push_back("der(x[" + std::to_string(i) + "])");
  return names;
}

std::vector<double> SpringChain::startValues() const {
  std::vector<double> y(size(), 0.0);
  for (int i = 0; i < n_; ++i) y[i] = 0.01 * (i + 1);
  return y;
}

void SpringChain::residual(const double* y, const double* yp, double* F) const {
  const int n = n_;
  const double* x = y;
  const double* v = y + n;
  const double* a = yp + n;  // v'
  F[0] = m_ * a[0] + k_ * (2 * x[0] - x[1]) + c_ * (2 * v[0] - v[1]);
  for (int i = 1; i < n - 1; ++i)
    F[i] = m_ * a[i] + k_ * (2 * x[i] - x[i - 1] - x[i + 1]) + c_ * (2 * v[i] - v[i - 1] - v[i + 1]);
  F[n - 1] = m_ * a[n - 1] + k_ * (x[n - 1] - x[n - 2]) + c_ * (v[n - 1] - v[n - 2]);
  for (int i = 0; i < n; ++i) F[n + i] = yp[i] - v[i];
}

// Column of x_j: rows j−1, j, j+1 (−k, 2k or k at the free end, −k) and n+j (cj).
// Column of v_j: rows j−1, j, j+1 (−c, 2c + m cj or c + m cj, −c) and n+j (−1).
void SpringChain::sparseJacobian(double cj, const double*, const double*, int64_t* columnStarts, int64_t* rowIndices,
                                 double* values) const {
  const int n = n_;
  int64_t at = 0;
  auto put = [&](int64_t row, double value) {
    rowIndices[at] = row;
    values[at++] = value;
  };
  // One column: the band of the Euler–Lagrange rows around row j, then the kinematic row n + j.
  auto column = [&](int column, int j, double coupling, double interior, double freeEnd, double kinematic) {
    columnStarts[column] = at;
    if (j > 0) put(j - 1, coupling);
    put(j, j == n - 1 ? freeEnd : interior);
    if (j < n - 1) put(j + 1, coupling);
    put(n + j, kinematic);
  };
  double mcj = m_ * cj;
  for (int j = 0; j < n; ++j) column(j, j, -k_, 2 * k_, k_, cj);
  for (int j = 0; j < n; ++j) column(n + j, j, -c_, 2 * c_ + mcj, c_ + mcj, -1.0);
  columnStarts[2 * n] = at;
}

}  // namespace qdot::bench
