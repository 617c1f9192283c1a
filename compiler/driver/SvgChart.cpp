// logLogChart: data coordinates are log10 values mapped linearly into the plot rectangle; all
// text is escaped; colours cycle through a palette that stays distinct in print.
#include "driver/SvgChart.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace qdot::driver {
namespace {

constexpr double kWidth = 760, kHeight = 520;
constexpr double kLeft = 80, kRight = 200, kTop = 40, kBottom = 60;  // margins; the legend sits right
constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b"};

bool plottable(std::pair<double, double> p) {
  return std::isfinite(p.first) && std::isfinite(p.second) && p.first > 0 && p.second > 0;
}

std::string escaped(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

/// Whole decades [lo, hi] (log10) covering the values, at least one decade wide.
struct Decades {
  int lo = 0, hi = 1;
  static Decades of(const std::vector<double>& values) {
    if (values.empty()) return {};
    auto [mn, mx] = std::minmax_element(values.begin(), values.end());
    Decades d{static_cast<int>(std::floor(std::log10(*mn))), static_cast<int>(std::ceil(std::log10(*mx)))};
    if (d.hi <= d.lo) d.hi = d.lo + 1;
    return d;
  }
  double fraction(double v) const { return (std::log10(v) - lo) / (hi - lo); }
};

class Plot {
 public:
  Plot(Decades x, Decades y) : x_(x), y_(y) {}
  double px(double v) const { return kLeft + x_.fraction(v) * (kWidth - kLeft - kRight); }
  double py(double v) const { return kHeight - kBottom - y_.fraction(v) * (kHeight - kTop - kBottom); }

  void axes(std::string& out) const {
    double x0 = kLeft, x1 = kWidth - kRight, y0 = kHeight - kBottom, y1 = kTop;
    out += fmt::format(R"svg(<rect x="{}" y="{}" width="{}" height="{}" fill="none" stroke="#444"/>)svg" "\n", x0, y1,
                       x1 - x0, y0 - y1);
    int xStep = std::max(1, (x_.hi - x_.lo + 9) / 10), yStep = std::max(1, (y_.hi - y_.lo + 9) / 10);
    for (int d = x_.lo; d <= x_.hi; d += xStep) {
      double x = px(std::pow(10.0, d));
      out += fmt::format(R"svg(<line x1="{0:.1f}" y1="{1}" x2="{0:.1f}" y2="{2}" stroke="#ddd"/>)svg" "\n", x, y0, y1);
      out += fmt::format(R"svg(<text x="{:.1f}" y="{}" text-anchor="middle">{}</text>)svg" "\n", x, y0 + 20, power(d));
    }
    for (int d = y_.lo; d <= y_.hi; d += yStep) {
      double y = py(std::pow(10.0, d));
      out += fmt::format(R"svg(<line x1="{0}" y1="{1:.1f}" x2="{2}" y2="{1:.1f}" stroke="#ddd"/>)svg" "\n", x0, y, x1);
      out += fmt::format(R"svg(<text x="{}" y="{:.1f}" text-anchor="end">{}</text>)svg" "\n", x0 - 6, y + 4, power(d));
    }
  }

 private:
  static std::string power(int d) { return fmt::format(R"svg(10<tspan dy="-7" font-size="10">{}</tspan>)svg", d); }
  Decades x_, y_;
};

void polyline(std::string& out, const Plot& plot, const ChartSeries& s, const char* colour) {
  std::string points;
  for (auto p : s.points)
    if (plottable(p)) points += fmt::format("{:.1f},{:.1f} ", plot.px(p.first), plot.py(p.second));
  out += fmt::format(R"svg(<polyline fill="none" stroke="{}" stroke-width="2" points="{}"/>)svg" "\n", colour, points);
  for (std::size_t i = 0; i < s.points.size(); ++i) {
    if (!plottable(s.points[i])) continue;
    double x = plot.px(s.points[i].first), y = plot.py(s.points[i].second);
    out += fmt::format(R"svg(<circle cx="{:.1f}" cy="{:.1f}" r="3.5" fill="{}"/>)svg" "\n", x, y, colour);
    if (i < s.pointLabels.size())
      out += fmt::format(R"svg(<text x="{:.1f}" y="{:.1f}" font-size="10" fill="{}">{}</text>)svg" "\n", x + 5, y - 5, colour,
                         escaped(s.pointLabels[i]));
  }
}

void legend(std::string& out, const std::vector<ChartSeries>& series) {
  double x = kWidth - kRight + 16, y = kTop + 10;
  for (std::size_t i = 0; i < series.size(); ++i, y += 20) {
    const char* colour = kColours[i % std::size(kColours)];
    out += fmt::format(R"svg(<line x1="{}" y1="{}" x2="{}" y2="{}" stroke="{}" stroke-width="2"/>)svg" "\n", x, y, x + 24, y,
                       colour);
    out += fmt::format(R"svg(<text x="{}" y="{}">{}</text>)svg" "\n", x + 30, y + 4, escaped(series[i].name));
  }
}

}  // namespace

std::string logLogChart(const std::vector<ChartSeries>& series, const ChartText& text) {
  std::vector<double> xs, ys;
  for (const ChartSeries& s : series)
    for (auto p : s.points)
      if (plottable(p)) xs.push_back(p.first), ys.push_back(p.second);
  Plot plot(Decades::of(xs), Decades::of(ys));
  std::string out = fmt::format(
      R"svg(<svg xmlns="http://www.w3.org/2000/svg" width="{0}" height="{1}" viewBox="0 0 {0} {1}" font-family="sans-serif" font-size="13">)svg"
      "\n",
      kWidth, kHeight);
  out += fmt::format(R"svg(<rect width="{}" height="{}" fill="white"/>)svg" "\n", kWidth, kHeight);
  out += fmt::format(R"svg(<text x="{}" y="24" text-anchor="middle" font-size="15">{}</text>)svg" "\n",
                     (kLeft + kWidth - kRight) / 2, escaped(text.title));
  plot.axes(out);
  for (std::size_t i = 0; i < series.size(); ++i) polyline(out, plot, series[i], kColours[i % std::size(kColours)]);
  legend(out, series);
  out += fmt::format(R"svg(<text x="{}" y="{}" text-anchor="middle">{}</text>)svg" "\n", (kLeft + kWidth - kRight) / 2,
                     kHeight - 16, escaped(text.xLabel));
  out += fmt::format(R"svg(<text transform="translate(20 {}) rotate(-90)" text-anchor="middle">{}</text>)svg" "\n",
                     (kTop + kHeight - kBottom) / 2, escaped(text.yLabel));
  out += "</svg>\n";
  return out;
}

}  // namespace qdot::driver
