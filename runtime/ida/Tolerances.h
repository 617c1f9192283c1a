// Per-variable absolute tolerances for IDA (docs/accuracy.md). A user's --atol is absolute, in each
// variable's units, as in SUNDIALS, SciPy and MATLAB: atol_i = atol, or atol * nominal_i for a
// variable with a `nominal`. Without --atol the scales are automatic — IDA's error test is a
// weighted RMS over all unknowns, so one scalar would mean very different things for a position in
// metres and a force in kilonewtons: atol_i = rtol * scale_i, scale_i from `nominal` or the values.
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
  double solverRtol = 0;      ///< the rtol handed to IDA (calibrated without --atol)
  double atolUser = 0;        ///< the user's --atol, or solverRtol when none was given (the automatic base)
  bool atolGiven = false;     ///< whether --atol was given (then atol_i = atol, or atol * nominal_i)
  double atolMin = 0;         ///< smallest atol_i
  double atolMedian = 0;      ///< median atol_i
  double atolMax = 0;         ///< largest atol_i
  std::size_t count = 0;      ///< number of unknowns
  std::size_t automatic = 0;  ///< unknowns without a nominal value (scale automatic, or 1 with --atol)
};

/// The absolute tolerances handed to IDASVtolerances, their scales and the summary.
struct ToleranceVector {
  std::vector<double> atol;   ///< atol_i = atolUser * scale_i, always positive and finite
  std::vector<double> scale;  ///< scale_i: nominal_i; else automatic, or 1 when --atol was given
  double solverRtol = 0;      ///< the rtol handed to IDA: calibratedRtol(rtol) without --atol, else rtol
  ToleranceSummary summary;
};

/// The rtol handed to IDA when no --atol is given, so that the global error of a run stays within
/// 10x of rtol: IDA controls the error of each step, and the error at the end of a run grows as
/// about rtol^0.82 (measured with `qdot wp` on the examples, docs/accuracy.md), so
///   solverRtol = 0.5 * rtol^1.15,  not below min(rtol, 2e-11): tighter, IDA fails in round-off on some examples (the
///   forced oscillator at 1e-13, the car axis at 1.6e-12, and — with the simplified equations of
///   issue 14 — at 1e-11 from the consistent start of rtol 1e-10: Newton failures at t = 2.275).
/// With --atol the user speaks SUNDIALS' language and both tolerances go to IDA as given.
double calibratedRtol(double rtol);
inline constexpr double kCalibrationFactor = 0.5, kCalibrationExponent = 1.15, kSolverRtolFloor = 2e-11;

/// The factor between the largest magnitude of a kind and the floor of an automatic scale.
inline constexpr double kAutomaticScaleFloorFactor = 1e-3;

/// Automatic scales per unknown. nominal_i > 0 (finite) is used as given. Otherwise
///   scale_i = max(|y_i|, floor_k),  floor_k = 1e-3 * M_k,
/// where m_j = nominal_j if given, else |start_j|, M_k = max m_j over the unknowns of the same kind
/// k (differential or algebraic) and M = max m_j over all unknowns. A kind that is zero or
/// negligible (M_k <= 1e-3 M) uses floor = 1e-3 M instead; if everything is zero, floor = 1 (the
/// unit of the variable). Non-finite values count as 0.
/// `start` are the start values as the model gives them and `y` the values now (the consistent
/// ones after IDACalcIC): the floors come from what the model wrote, so roundoff such as 4e-13 left
/// by IDACalcIC in a model that starts at rest cannot become a scale of 4e-16 (which made such a
/// model fail at t = 0); a consistent value may only raise a scale. Empty `start`: start = y.
std::vector<double> toleranceScales(std::span<const double> y, std::span<const double> nominal,
                                    std::span<const int32_t> isDifferential, std::span<const double> start = {});

/// The tolerance vector with its summary. With atol: atol_i = atol * nominal_i for an unknown with
/// a nominal, else atol (absolute), and rtol as given. Without: solverRtol = calibratedRtol(rtol)
/// and atol_i = solverRtol * toleranceScales(...)_i. Sizes of y,
/// nominal, isDifferential (and start, if not empty) must agree.
ToleranceVector buildTolerances(double rtol, std::optional<double> atol, std::span<const double> y,
                                std::span<const double> nominal, std::span<const int32_t> isDifferential,
                                std::span<const double> start = {});

/// Undoes the calibration (no-op with --atol): solverRtol = rtol, automatic atol_i = rtol *
/// scale_i, the summary to match. For IDACalcIC, a first step that fails at the calibrated
/// tolerances, and ARKODE (the calibration is measured for IDA's BDF only).
void useAsGiven(ToleranceVector& tolerances);

}  // namespace qdot::rt
