// The results of a work–precision study and their presentation: the table, the CSV, the SVG
// diagram, and the analysis of tolerance proportionality (fitted slope, round-off floor).
#pragma once

#include <cstddef>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "ida/IdaSession.h"

namespace qdot::driver {

enum class ErrorMeasure { MaxAbs, Final, Scd };

/// One run of the ladder.
struct WpPoint {
  double rtol = 0;
  std::optional<double> atol;  ///< --atol, or none (automatic scales)
  bool success = false;
  std::string failure;         ///< why the run failed
  double error = 0;            ///< MaxAbs/Final: absolute error; Scd: max relative error at the final time
  double compileSeconds = 0, setupSeconds = 0, solveSeconds = 0;
  rt::SolverStats stats;
  double wholeSeconds() const { return compileSeconds + setupSeconds + solveSeconds; }
};

/// How the error follows the tolerance over one configuration's ladder.
struct Proportionality {
  double slope = 0;              ///< least-squares slope of log10(error) on log10(rtol), points above the floor
  std::size_t fitted = 0;        ///< points in the fit (the slope means nothing below 2)
  std::optional<double> floor;   ///< the error where it stops falling (none: it fell down the whole ladder)
  double floorRtol = 0;          ///< the loosest rtol at the floor
};

/// A configuration's ladder, loosest rtol first.
struct WpSeries {
  std::string label;  ///< "llvm/ida"
  std::string backend, solver;
  std::vector<WpPoint> points;
  Proportionality fit;
};

struct WpStudy {
  std::string model, file;  ///< model name and file
  ErrorMeasure measure = ErrorMeasure::MaxAbs;
  std::string errorDefinition;  ///< a sentence: what the error is, over which columns
  std::string reference;        ///< a sentence: what the reference is
  double start = 0, stop = 0;
  std::size_t outputTimes = 0;
  std::vector<WpSeries> series;
};

/// The error "stops falling" at the first rtol where it falls by less than a quarter of the decades
/// the tolerance fell (10× tighter rtol, < 1.78× smaller error); the floor is the smallest error
/// from the point before on, and the slope is fitted over the points up to that one.
Proportionality fitProportionality(const std::vector<WpPoint>& points);

/// The table, a header stating the error measure and reference, and the proportionality lines.
void printTable(const WpStudy& study, std::ostream& out);
/// One row per run: configuration, tolerances, error, times, counters, status.
std::string studyCsv(const WpStudy& study);
/// Error (x) against whole-process time (y), log–log, one line per configuration.
std::string studySvg(const WpStudy& study);

}  // namespace qdot::driver
