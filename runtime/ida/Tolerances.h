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
#include <string_view>
#include <vector>

namespace qdot::rt {

/// What the tolerance vector ended up being, for `--stats`.
struct ToleranceSummary {
  double rtol = 0;            ///< relative tolerance (scalar, same for all unknowns)
  double solverRtol = 0;      ///< the rtol handed to IDA (calibrated without --atol)
  double atolUser = 0;        ///< the user's --atol, or solverRtol when none was given (the automatic base)
  bool atolGiven = false;     ///< whether --atol was given (then atol_i = atol, or atol * nominal_i)
  double atolMin = 0;         ///< smallest atol_i (these three: filled by summarize)
  double atolMedian = 0;      ///< median atol_i
  double atolMax = 0;         ///< largest atol_i
  std::size_t count = 0;      ///< number of unknowns
  std::size_t automatic = 0;  ///< unknowns without a nominal value (scale automatic, or 1 with --atol)
  double frequency = 0;       ///< the model's lowest linearized frequency [1/s] the velocities follow; 0: none
  std::size_t velocities = 0; ///< automatic velocity scales that follow it (position scale x frequency)
};

/// The model's time scale, for the scales of its velocities: a velocity v = der(q) of a position
/// of scale s_q moves at about s_q * frequency in the model's slowest mode (a pendulum's angle of
/// 1 rad at sqrt(g/l)), whatever the start values — which are often 0 for velocities.
struct TimeScale {
  double frequency = 0;              ///< lowest nonzero |eigenvalue| of the linearization at the start [1/s]; 0: none
  std::vector<int32_t> positionOf;   ///< per unknown: the index of q when it is der(q), else -1 (empty: none)
};

/// positionOf for a TimeScale: unknown i named "der(NAME)" is the velocity of the unknown NAME.
std::vector<int32_t> velocityPositions(std::span<const char* const> names);

/// The absolute tolerances handed to IDASVtolerances, their scales and the summary.
struct ToleranceVector {
  std::vector<double> atol;   ///< atol_i = atolUser * scale_i, always positive and finite
  std::vector<double> scale;  ///< scale_i: nominal_i; else automatic, or 1 when --atol was given
  double solverRtol = 0;      ///< the rtol handed to IDA: calibratedRtol(rtol) without --atol, else rtol
  ToleranceSummary summary;
  bool summarized = false;  ///< summary.atolMin, atolMedian, atolMax are those of atol (see summarize)
};

/// The summary with its figures of the atol in use (min, median, max), computed when first asked
/// for after atol changed: only `--stats` reads them, after the run.
const ToleranceSummary& summarize(ToleranceVector& t);

/// The rtol handed to IDA when no --atol is given, so that the global error of a run stays within
/// 10x of rtol: IDA controls the error of each step, and the error at the end of a run grows as
/// about rtol^0.82 (measured with `qdot wp` on the examples, docs/accuracy.md), so
///   solverRtol = 0.5 * rtol^1.15,  not below min(rtol, 2e-11): tighter, IDA fails in round-off on some examples (the
///   forced oscillator at 1e-13, the car axis at 1.6e-12, and — with the simplified equations of
///   issue 14 — at 1e-11 from the consistent start of rtol 1e-10: Newton failures at t = 2.275).
/// With --atol the user speaks SUNDIALS' language and both tolerances go to IDA as given.
/// The calibration of one method: solverRtol = factor * rtol^exponent, not below min(rtol, floor).
struct RtolCalibration {
  double factor, exponent, floor;
};
inline constexpr double kCalibrationFactor = 0.5, kCalibrationExponent = 1.15, kSolverRtolFloor = 2e-11;
inline constexpr RtolCalibration kIdaCalibration{kCalibrationFactor, kCalibrationExponent, kSolverRtolFloor};
/// ARKODE's ESDIRK4(3)7L[2]SA, measured the same way (`qdot wp --solver arkode`, docs/accuracy.md):
/// with rtol as given its global error grew as rtol^0.80…0.87 (error/rtol 32–2500 over 1e-3…1e-10
/// on the damped oscillator, the double pendulum and the governor), so exponent 1.2 ≈ 1/0.84, and
/// the factor brings error/rtol to about 1. Floor: below 1e-13 its Newton iteration stalls in round-off.
inline constexpr RtolCalibration kArkodeCalibration{0.03, 1.2, 1e-13};
double calibratedRtol(double rtol, const RtolCalibration& calibration = kIdaCalibration);

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
/// A velocity v = der(q) without a nominal, given a time scale with frequency ω > 0, gets
///   scale_v = max(|y_v|, floor_k, scale_q * ω)
/// (the floor keeps a near-zero ω, a pendulum released at 90°, from making it tighter than before).
std::vector<double> toleranceScales(std::span<const double> y, std::span<const double> nominal,
                                    std::span<const int32_t> isDifferential, std::span<const double> start = {},
                                    const TimeScale& timeScale = {});

/// The tolerance vector with its summary. With atol: atol_i = atol * nominal_i for an unknown with
/// a nominal, else atol (absolute), and rtol as given. Without: solverRtol = calibratedRtol(rtol)
/// and atol_i = solverRtol * toleranceScales(...)_i. Sizes of y,
/// nominal, isDifferential (and start, if not empty) must agree.
ToleranceVector buildTolerances(double rtol, std::optional<double> atol, std::span<const double> y,
                                std::span<const double> nominal, std::span<const int32_t> isDifferential,
                                std::span<const double> start = {}, const TimeScale& timeScale = {});

/// Undoes the calibration (no-op with --atol): solverRtol = rtol, automatic atol_i = rtol *
/// scale_i, the summary to match. For IDACalcIC, a first step that fails at the calibrated
/// tolerances, and ARKODE (the calibration is measured for IDA's BDF only).
void useAsGiven(ToleranceVector& tolerances);

/// What buildTolerances gives for the same scales (y, start values and nominals unchanged), from
/// tolerances made so or changed by useAsGiven: solverRtol = calibratedRtol(rtol), the automatic
/// atol_i = solverRtol * scale_i computed as buildTolerances computes them, the summary to match;
/// no-op with --atol. Spares computing the scales again (at 2·10⁶ unknowns, 0.05 s).
void useCalibrated(ToleranceVector& tolerances);

/// atol_i = base * scale_i (base where the product is not a positive finite number) and the
/// summary's solverRtol, atolUser and count (its minimum, median and maximum: summarize).
void fillAtol(ToleranceVector& tolerances, double base);

/// Recalibrates automatic tolerances for another method (no-op with --atol): solverRtol =
/// calibratedRtol(rtol, calibration), the automatic atol_i = solverRtol * scale_i, the summary to match.
void useCalibration(ToleranceVector& tolerances, const RtolCalibration& calibration);

}  // namespace qdot::rt
