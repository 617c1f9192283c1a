// A log–log line chart as a standalone SVG document (written by hand: no plotting dependency),
// for work–precision diagrams: decade ticks and labels on both axes, one polyline with markers per
// series, a legend. Opens in any browser.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace qdot::driver {

struct ChartSeries {
  std::string name;                              ///< legend entry
  std::vector<std::pair<double, double>> points;  ///< (x, y); points that are not positive and finite are skipped
  std::vector<std::string> pointLabels;          ///< optional text next to each point (same length or empty)
};

struct ChartText {
  std::string title, xLabel, yLabel;
};

/// The whole SVG document. Axes span the decades that hold every plotted point (at least one
/// decade each).
std::string logLogChart(const std::vector<ChartSeries>& series, const ChartText& text);

}  // namespace qdot::driver
