// Per-variable absolute tolerances: the user's atol as given (times nominal), or automatic scales
// from nominal values or the start values, grouped by kind (differential / algebraic) so a zero
// start value gets a floor tied to its neighbours, and velocities from the model's time scale. The
// rule is documented in Tolerances.h and docs/accuracy.md.
#include "ida/Tolerances.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "qdot/two_halves.hpp"

namespace qdot::rt {
namespace {

bool hasNominal(double nominal) { return std::isfinite(nominal) && nominal > 0; }

double magnitude(double y0, double nominal) {
  if (hasNominal(nominal)) return nominal;
  return std::isfinite(y0) ? std::abs(y0) : 0.0;
}

double floorFor(double kindLargest, double allLargest) {
  if (allLargest <= 0) return 1.0;
  // A kind whose values are all zero or negligible (roundoff such as 1e-30 left by IDACalcIC)
  // would give an absurdly small floor: it borrows the overall magnitude instead.
  bool kindCounts = kindLargest > kAutomaticScaleFloorFactor * allLargest;
  return kAutomaticScaleFloorFactor * (kindCounts ? kindLargest : allLargest);
}

/// Whether unknown i is a velocity whose automatic scale follows the time scale.
bool followsTimeScale(const TimeScale& timeScale, std::span<const double> nominal, std::size_t i) {
  return timeScale.frequency > 0 && std::isfinite(timeScale.frequency) && i < timeScale.positionOf.size() &&
         timeScale.positionOf[i] >= 0 && !hasNominal(nominal[i]);
}

/// The automatic tolerances with another solver rtol (atol_i = solverRtol * scale_i throughout).
void rescale(ToleranceVector& t, double solverRtol) {
  ToleranceSummary& s = t.summary;
  double factor = solverRtol / t.solverRtol;
  for (double& a : t.atol) a *= factor;
  t.summarized = false;
  s.atolUser = t.solverRtol = s.solverRtol = solverRtol;
}

/// The largest magnitude of the algebraic (kind 0) and of the differential (kind 1) unknowns, in one
/// pass (the largest of all is the larger of the two).
std::pair<double, double> largestMagnitudes(std::span<const double> y0, std::span<const double> nominal,
                                            std::span<const int32_t> isDifferential) {
  double largest[2][2] = {{0, 0}, {0, 0}};  // per half (two threads from 65 536 unknowns: a maximum is exact in any order)
  inTwoHalves(y0.size(), [&](size_t first, size_t last) {
    double* l = largest[first == 0 ? 0 : 1];
    for (std::size_t i = first; i < last; ++i) {
      double& kind = l[isDifferential[i] != 0 ? 1 : 0];
      kind = std::max(kind, magnitude(y0[i], nominal[i]));
    }
  });
  return {std::max(largest[0][0], largest[1][0]), std::max(largest[0][1], largest[1][1])};
}

double finiteOrZero(double v) { return std::isfinite(v) ? v : 0.0; }

}  // namespace

double calibratedRtol(double rtol, const RtolCalibration& c) {
  return std::max(c.factor * std::pow(rtol, c.exponent), std::min(rtol, c.floor));
}

std::vector<int32_t> velocityPositions(std::span<const char* const> names) {
  std::unordered_map<std::string_view, int32_t> index;
  for (std::size_t i = 0; i < names.size(); ++i) index.emplace(names[i], static_cast<int32_t>(i));
  std::vector<int32_t> positionOf(names.size(), -1);
  for (std::size_t i = 0; i < names.size(); ++i) {
    std::string_view name = names[i];
    if (name.size() < 6 || !name.starts_with("der(") || !name.ends_with(")")) continue;
    auto found = index.find(name.substr(4, name.size() - 5));
    if (found != index.end()) positionOf[i] = found->second;
  }
  return positionOf;
}

std::vector<double> toleranceScales(std::span<const double> y, std::span<const double> nominal,
                                    std::span<const int32_t> isDifferential, std::span<const double> start,
                                    const TimeScale& timeScale) {
  if (start.empty()) start = y;
  auto [algebraic, differential] = largestMagnitudes(start, nominal, isDifferential);
  double all = finiteOrZero(std::max(algebraic, differential));
  double floors[2] = {floorFor(finiteOrZero(algebraic), all), floorFor(finiteOrZero(differential), all)};
  std::vector<double> scales(y.size());
  inTwoHalves(y.size(), [&](size_t first, size_t last) {
    for (std::size_t i = first; i < last; ++i)
      scales[i] = hasNominal(nominal[i]) ? nominal[i] : std::max(magnitude(y[i], 0.0), floors[isDifferential[i] != 0 ? 1 : 0]);
  });
  // Velocities after their positions: scale_q is final above (a position is never itself der(...)
  // of another unknown in a mechanics model; if it were, it keeps the value computed above).
  for (std::size_t i = 0; i < y.size(); ++i)
    if (followsTimeScale(timeScale, nominal, i))
      scales[i] = std::max(scales[i], scales[timeScale.positionOf[i]] * timeScale.frequency);
  return scales;
}

ToleranceVector buildTolerances(double rtol, std::optional<double> atol, std::span<const double> y,
                                std::span<const double> nominal, std::span<const int32_t> isDifferential,
                                std::span<const double> start, const TimeScale& timeScale) {
  ToleranceVector result;
  if (atol) {
    result.scale.resize(y.size());
    for (std::size_t i = 0; i < y.size(); ++i) result.scale[i] = hasNominal(nominal[i]) ? nominal[i] : 1.0;
  } else {
    result.scale = toleranceScales(y, nominal, isDifferential, start, timeScale);
    for (std::size_t i = 0; i < y.size(); ++i) result.summary.velocities += followsTimeScale(timeScale, nominal, i);
    if (result.summary.velocities > 0) result.summary.frequency = timeScale.frequency;
  }
  result.solverRtol = atol ? rtol : calibratedRtol(rtol);
  ToleranceSummary& s = result.summary;
  s.rtol = rtol;
  s.atolGiven = atol.has_value();
  s.automatic =
      static_cast<std::size_t>(std::count_if(nominal.begin(), nominal.end(), [](double v) { return !hasNominal(v); }));
  fillAtol(result, atol.value_or(result.solverRtol));  // automatic: the calibrated rtol, relative and absolute alike
  return result;
}

// atol_i = base * scale_i. The summary's figures of it (smallest, median, largest: a selection over
// 2·10⁶ values at 10⁶ masses, 15-25 ms) wait until someone asks for them (summarize), after the run.
void fillAtol(ToleranceVector& t, double base) {
  t.atol.resize(t.scale.size());
  inTwoHalves(t.scale.size(), [&](size_t first, size_t last) {
    for (std::size_t i = first; i < last; ++i) {
      double value = base * t.scale[i];
      // Guard against overflow or underflow of the product: IDA rejects a zero or infinite weight.
      if (!std::isfinite(value) || value <= 0) value = base;
      t.atol[i] = value;
    }
  });
  ToleranceSummary& s = t.summary;
  s.solverRtol = t.solverRtol;
  s.atolUser = base;
  s.count = t.atol.size();
  t.summarized = false;
}

const ToleranceSummary& summarize(ToleranceVector& t) {
  if (t.summarized) return t.summary;
  ToleranceSummary& s = t.summary;
  s.atolMin = s.atolMedian = s.atolMax = 0;
  if (!t.atol.empty()) {
    std::vector<double> values = t.atol;
    auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    s.atolMin = *lo, s.atolMax = *hi;
    auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    double upper = *middle, lower = values.size() % 2 == 0 ? *std::max_element(values.begin(), middle) : upper;
    s.atolMedian = 0.5 * (lower + upper);
  }
  t.summarized = true;
  return s;
}

void useCalibrated(ToleranceVector& t) {
  if (t.summary.atolGiven) return;  // as built: solverRtol = rtol, atol the user's
  t.solverRtol = calibratedRtol(t.summary.rtol);
  fillAtol(t, t.solverRtol);
}

void useAsGiven(ToleranceVector& t) {
  if (t.summary.atolGiven || t.solverRtol >= t.summary.rtol) return;
  rescale(t, t.summary.rtol);
}

void useCalibration(ToleranceVector& t, const RtolCalibration& calibration) {
  if (!t.summary.atolGiven) rescale(t, calibratedRtol(t.summary.rtol, calibration));
}

}  // namespace qdot::rt
