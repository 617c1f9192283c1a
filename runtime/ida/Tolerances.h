// Per-variable absolute tolerances for IDA. IDA's error test is a weighted RMS over all unknowns,
// so a single scalar atol means very different things for a position in metres and a force in
// kilonewtons; here atol_i = atol_user * scale_i with scale_i from `nominal` or chosen from y0.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace qdot::rt {

/// What the tolerance vector ended up being, for `--stats`.
struct ToleranceSummary {
  double rtol = 0;            ///< relative tolerance (scalar, same for all unknowns)
  double atolUser = 0;        ///< the user's --atol, or rtol when none was given
  bool atolGiven = false;     ///< whether --atol was given
  double atolMin = 0;         ///< smallest atol_i
  double atolMedian = 0;      ///< median atol_i
  double atolMax = 0;         ///< largest atol_i
  std::size_t count = 0;      ///< number of unknowns
  std::size_t automatic = 0;  ///< unknowns without a nominal value (scale chosen automatically)
};

/// The absolute tolerances handed to IDASVtolerances, their scales and the summary.
struct ToleranceVector {
  std::vector<double> atol;   ///< atol_i = atolUser * scale_i, always positive and finite
  std::vector<double> scale;  ///< scale_i (nominal_i, or automatic)
  ToleranceSummary summary;
};

/// The factor between the largest magnitude of a kind and the floor of an automatic scale.
inline constexpr double kAutomaticScaleFloorFactor = 1e-3;

/// Scales per unknown. nominal_i > 0 (finite) is used as given. Otherwise the scale is automatic:
///   scale_i = max(|y0_i|, floor_k),  floor_k = 1e-3 * M_k,
/// where m_j = nominal_j if given, else |y0_j|, M_k = max m_j over the unknowns of the same kind k
/// (differential or algebraic) and M = max m_j over all unknowns. A kind that is zero or
/// negligible (M_k <= 1e-3 M) uses floor = 1e-3 M instead; if everything is zero, floor = 1 (the
/// unit of the variable). Non-finite start values count as 0.
std::vector<double> toleranceScales(std::span<const double> y0, std::span<const double> nominal,
                                    std::span<const int32_t> isDifferential);

/// atol_i = atol.value_or(rtol) * scale_i, with the summary. Sizes of y0, nominal and
/// isDifferential must agree.
ToleranceVector buildTolerances(double rtol, std::optional<double> atol, std::span<const double> y0,
                                std::span<const double> nominal, std::span<const int32_t> isDifferential);

}  // namespace qdot::rt
