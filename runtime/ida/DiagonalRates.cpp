#include "ida/DiagonalRates.h"

#include <cmath>

#include "qdot/two_halves.hpp"

namespace qdot::rt {

template <class Index>
std::optional<DiagonalRates> diagonalRates(std::span<const Index> columnStarts, std::span<const Index> rowIndices,
                                           std::span<const double> at0, std::span<const double> at1) {
  size_t n = columnStarts.size() - 1;
  constexpr uint32_t kNone = UINT32_MAX;
  DiagonalRates r{std::vector<uint32_t>(n, kNone), std::vector<double>(n, 0.0)};
  // Column c's one nonzero entry of J(cj = 1) − J(cj = 0), if it has exactly one and sees every entry.
  auto columnEntry = [&](size_t c) {
    for (Index k = columnStarts[c]; k < columnStarts[c + 1]; ++k) {
      if (at0[k] + 1.0 == at0[k] || !std::isfinite(at0[k])) return false;  // the entry is unseen
      double entry = at1[k] - at0[k];
      if (entry == 0) continue;
      if (r.rowOf[c] != kNone || !std::isfinite(entry)) return false;
      r.rowOf[c] = static_cast<uint32_t>(rowIndices[k]), r.d[c] = entry;
    }
    return true;
  };
  bool found[2] = {true, true};  // per half of the columns (two threads from 65 536 columns)
  inTwoHalves(n, [&](size_t first, size_t last) {
    bool& good = found[first == 0 ? 0 : 1];
    for (size_t c = first; c < last && good; ++c) good = columnEntry(c);
  });
  if (!found[0] || !found[1]) return std::nullopt;
  // one entry per row too: the columns' rows are all different (a pass after, rather than a
  // lookup per entry)
  std::vector<char> taken(n, 0);
  for (uint32_t row : r.rowOf) {
    if (row >= n || taken[row]) return std::nullopt;  // kNone: a column without its entry
    taken[row] = 1;
  }
  return r;
}

template std::optional<DiagonalRates> diagonalRates<int32_t>(std::span<const int32_t>, std::span<const int32_t>,
                                                             std::span<const double>, std::span<const double>);
template std::optional<DiagonalRates> diagonalRates<int64_t>(std::span<const int64_t>, std::span<const int64_t>,
                                                             std::span<const double>, std::span<const double>);

void stepRates(const DiagonalRates& rates, std::span<const double> F, std::span<double> yp) {
  for (size_t c = 0; c < yp.size(); ++c) yp[c] -= F[rates.rowOf[c]] / rates.d[c];
}

bool ratesConverged(const DiagonalRates& rates, std::span<const double> F, std::span<const double> y, double rtol,
                    std::span<const double> atol, double span) {
  constexpr double kIcNewtonTolerance = 0.33 * 0.01;  // IDA's epsNewt: 0.33 x IDASetNonlinConvCoefIC's 0.01
  double sum = 0;
  for (size_t c = 0; c < y.size(); ++c) {
    double correction = F[rates.rowOf[c]] / rates.d[c] * span / (rtol * std::abs(y[c]) + atol[c]);
    sum += correction * correction;
  }
  return y.empty() || std::sqrt(sum / static_cast<double>(y.size())) <= kIcNewtonTolerance;
}

}  // namespace qdot::rt
