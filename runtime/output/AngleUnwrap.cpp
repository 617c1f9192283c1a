#include "output/AngleUnwrap.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace qdot::rt {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// value + period·k nearest to previous (k integer).
double nearest(double value, double previous, double period, long* k = nullptr) {
  double steps = std::round((previous - value) / period);
  if (k) *k = static_cast<long>(steps);
  return value + steps * period;
}

}  // namespace

AngleUnwrapper::AngleUnwrapper(std::span<const int32_t> kinds) {
  if (std::any_of(kinds.begin(), kinds.end(), [](int32_t k) { return k != 0; })) kinds_.assign(kinds.begin(), kinds.end());
}

void AngleUnwrapper::apply(std::span<double> out) {
  if (kinds_.empty() || out.size() != kinds_.size()) return;
  if (!first_) {
    for (size_t i = 0; i < out.size(); ++i) {
      if (kinds_[i] == 1 && std::isfinite(out[i])) out[i] = nearest(out[i], previous_[i], kTwoPi);
      if (kinds_[i] != 2 || i + 2 >= out.size()) continue;
      double a = 0.5 * (out[i] + out[i + 2]), b = 0.5 * (out[i] - out[i + 2]);
      double aPrev = 0.5 * (previous_[i] + previous_[i + 2]), bPrev = 0.5 * (previous_[i] - previous_[i + 2]);
      long flips = 0;
      a = nearest(a, aPrev, kTwoPi);
      b = nearest(b, bPrev, std::numbers::pi, &flips);
      if (!std::isfinite(a) || !std::isfinite(b)) continue;
      out[i] = a + b;
      out[i + 1] = flips % 2 != 0 ? -out[i + 1] : out[i + 1];
      out[i + 2] = a - b;
      i += 2;
    }
  }
  previous_.assign(out.begin(), out.end());
  first_ = false;
}

}  // namespace qdot::rt
