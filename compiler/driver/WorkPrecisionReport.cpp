// Presentation of a work–precision study. Numbers keep 3 significant digits in the table and full
// precision in the CSV.
#include "driver/WorkPrecisionReport.h"

#include <fmt/format.h>

#include <cmath>

#include "driver/SvgChart.h"

namespace qdot::driver {
namespace {

bool usable(const WpPoint& p) { return p.success && std::isfinite(p.error) && p.error > 0; }

double slopeOf(const std::vector<const WpPoint*>& points) {
  double n = static_cast<double>(points.size()), sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const WpPoint* p : points) {
    double x = std::log10(p->rtol), y = std::log10(p->error);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  double d = n * sxx - sx * sx;
  return d == 0 ? 0 : (n * sxy - sx * sy) / d;
}

std::string errorText(ErrorMeasure m, double error) {
  if (m == ErrorMeasure::Scd) return fmt::format("{:.2f}", -std::log10(error));
  return fmt::format("{:.3g}", error);
}

std::string quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string atolText(const WpPoint& p) { return p.atol ? fmt::format("{:g}", *p.atol) : "auto"; }

const char* errorHeader(ErrorMeasure m) {
  switch (m) {
    case ErrorMeasure::MaxAbs: return "max abs error";
    case ErrorMeasure::Final: return "final abs error";
    case ErrorMeasure::Scd: return "scd";
  }
  return "";
}

std::string fitText(const WpSeries& s) {
  std::string text = s.fit.fitted >= 2 ? fmt::format("slope of log(error) on log(rtol) {:.2f} over {} points", s.fit.slope,
                                                     s.fit.fitted)
                                       : "too few points above the floor for a slope";
  if (s.fit.floor)
    text += fmt::format("; round-off floor: error {:.3g} from rtol {:g} on", *s.fit.floor, s.fit.floorRtol);
  else
    text += "; no floor: the error falls down the whole ladder";
  return text;
}

}  // namespace

Proportionality fitProportionality(const std::vector<WpPoint>& points) {
  std::vector<const WpPoint*> used;
  for (const WpPoint& p : points)
    if (usable(p)) used.push_back(&p);
  Proportionality fit;
  std::size_t end = used.size();  // points [0, end) lie above the floor
  for (std::size_t i = 1; i < used.size(); ++i) {
    double decades = std::log10(used[i - 1]->rtol / used[i]->rtol);
    double fell = std::log10(used[i - 1]->error / used[i]->error);
    if (fell >= 0.25 * decades) continue;
    end = i;
    double lowest = used[i - 1]->error;
    for (std::size_t j = i; j < used.size(); ++j) lowest = std::min(lowest, used[j]->error);
    fit.floor = lowest;
    fit.floorRtol = used[i - 1]->rtol;
    break;
  }
  std::vector<const WpPoint*> above(used.begin(), used.begin() + static_cast<std::ptrdiff_t>(end));
  fit.fitted = above.size();
  if (above.size() >= 2) fit.slope = slopeOf(above);
  return fit;
}

void printTable(const WpStudy& s, std::ostream& out) {
  out << fmt::format("work-precision of {} ({}), t in [{:g}, {:g}], {} output times\n", s.model, s.file, s.start, s.stop,
                     s.outputTimes);
  out << "error: " << s.errorDefinition << "\n";
  out << "reference: " << s.reference << "\n";
  out << "time: whole process = compile (once per backend: front end + code generation) + setup + solve, in one "
         "process; solve = the integration alone\n\n";
  out << fmt::format("{:<16} {:>7} {:>7} {:>14} {:>10} {:>10} {:>10} {:>8} {:>10} {:>10}\n", "configuration", "rtol",
                     "atol", errorHeader(s.measure), "error/rtol", "whole [s]", "solve [s]", "steps", "residuals",
                     "Jacobians");
  for (const WpSeries& series : s.series) {
    for (const WpPoint& p : series.points) {
      if (!p.success) {
        out << fmt::format("{:<16} {:>7.0e} {:>7} failed: {}\n", series.label, p.rtol, atolText(p), p.failure);
        continue;
      }
      out << fmt::format("{:<16} {:>7.0e} {:>7} {:>14} {:>10.3g} {:>10.4f} {:>10.4f} {:>8} {:>10} {:>10}\n", series.label,
                         p.rtol, atolText(p), errorText(s.measure, p.error), p.error / p.rtol, p.wholeSeconds(),
                         p.solveSeconds, p.stats.steps, p.stats.residualEvaluations, p.stats.jacobianEvaluations);
    }
  }
  out << "\n";
  for (const WpSeries& series : s.series) out << series.label << ": " << fitText(series) << "\n";
}

std::string studyCsv(const WpStudy& s) {
  std::string csv =
      "configuration,backend,solver,rtol,atol,error_measure,error,error_over_rtol,compile_s,setup_s,solve_s,whole_s,"
      "steps,residual_evaluations,jacobian_evaluations,nonlinear_iterations,error_test_failures,status\n";
  const char* measure = s.measure == ErrorMeasure::MaxAbs ? "maxabs" : s.measure == ErrorMeasure::Final ? "final" : "scd";
  for (const WpSeries& series : s.series) {
    for (const WpPoint& p : series.points) {
      std::string error = p.success ? fmt::format("{:.17g}", s.measure == ErrorMeasure::Scd ? -std::log10(p.error) : p.error) : "";
      std::string ratio = p.success ? fmt::format("{:.6g}", p.error / p.rtol) : "";
      std::string status = p.success ? "ok" : quoted("failed: " + p.failure);
      csv += fmt::format("{},{},{},{:g},{},{},{},{},{:.6f},{:.6f},{:.6f},{:.6f},{},{},{},{},{},{}\n", series.label,
                         series.backend, series.solver, p.rtol, p.atol ? fmt::format("{:g}", *p.atol) : "auto", measure,
                         error, ratio, p.compileSeconds, p.setupSeconds, p.solveSeconds, p.wholeSeconds(),
                         p.stats.steps, p.stats.residualEvaluations, p.stats.jacobianEvaluations,
                         p.stats.nonlinearIterations, p.stats.errorTestFailures, status);
    }
  }
  return csv;
}

std::string studySvg(const WpStudy& s) {
  std::vector<ChartSeries> series;
  for (const WpSeries& ws : s.series) {
    ChartSeries cs{ws.label, {}, {}};
    for (const WpPoint& p : ws.points) {
      if (!p.success) continue;
      cs.points.emplace_back(p.error, p.wholeSeconds());
      cs.pointLabels.push_back(fmt::format("{:.0e}", p.rtol));
    }
    series.push_back(std::move(cs));
  }
  const char* x = s.measure == ErrorMeasure::MaxAbs ? "max abs error over the output grid"
                  : s.measure == ErrorMeasure::Final ? "abs error at the final time"
                                                     : "max relative error at the final time (scd = -log10 of it)";
  return logLogChart(series, {fmt::format("work-precision: {} (points labelled with rtol)", s.model), x,
                              "whole-process time [s]"});
}

}  // namespace qdot::driver
