// qdot wp's pieces: the proportionality analysis (slope, floor), exact solutions written in qdot's
// expression syntax (values and located errors), and the SVG chart.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "driver/SvgChart.h"
#include "driver/WorkPrecisionExact.h"
#include "driver/WorkPrecisionReport.h"

namespace qdot::driver {
namespace {

std::vector<WpPoint> ladder(const std::vector<std::pair<double, double>>& rtolError) {
  std::vector<WpPoint> points;
  for (auto [rtol, error] : rtolError) {
    WpPoint p;
    p.rtol = rtol;
    p.error = error;
    p.success = true;
    points.push_back(p);
  }
  return points;
}

TEST(WorkPrecision, SlopeOfAnErrorProportionalToRtolIsOne) {
  Proportionality fit = fitProportionality(ladder({{1e-3, 3e-3}, {1e-4, 3e-4}, {1e-5, 3e-5}, {1e-6, 3e-6}}));
  EXPECT_NEAR(fit.slope, 1.0, 1e-12);
  EXPECT_EQ(fit.fitted, 4u);
  EXPECT_FALSE(fit.floor);
}

TEST(WorkPrecision, FloorWhereTheErrorStopsFallingAndSlopeAboveIt) {
  // error = rtol^0.8 down to 1e-6, then stuck near 2e-9 (round-off or the reference's own error).
  auto points = ladder({{1e-3, std::pow(1e-3, 0.8)}, {1e-4, std::pow(1e-4, 0.8)}, {1e-5, std::pow(1e-5, 0.8)},
                        {1e-6, 2.2e-9}, {1e-7, 2e-9}, {1e-8, 2.5e-9}});
  Proportionality fit = fitProportionality(points);
  ASSERT_TRUE(fit.floor);
  EXPECT_EQ(*fit.floor, 2e-9);
  EXPECT_EQ(fit.floorRtol, 1e-6);
  EXPECT_EQ(fit.fitted, 4u);  // 1e-3 … 1e-6: the last point that still fell
  EXPECT_GT(fit.slope, 0.8);  // the drop into the floor steepens the fit; it stays a fit over falling points
}

TEST(WorkPrecision, FailedRunsAreLeftOutOfTheFit) {
  auto points = ladder({{1e-3, 1e-3}, {1e-4, 1e-4}, {1e-5, 1e-5}});
  points[1].success = false;
  Proportionality fit = fitProportionality(points);
  EXPECT_EQ(fit.fitted, 2u);
  EXPECT_NEAR(fit.slope, 1.0, 1e-12);
}

TEST(WorkPrecisionExact, EvaluatesTimeParametersAndFunctions) {
  SourceManager sources;
  DiagnosticEngine diags;
  NameValues names = {{"h", 0.1}, {"w", 20}, {"m[2]", 3}};
  auto exact = parseExact("x = h/2*cos(w*time) + m[2]^2 - (if time > 1 then 1 else 0)", {"x", "der(x)"}, names,
                          sources, diags);
  ASSERT_TRUE(exact) << diags.diagnostics().front().message;
  EXPECT_EQ(exact->column, "x");
  EXPECT_DOUBLE_EQ(evaluateExact(*exact, 0.5, names), 0.05 * std::cos(10.0) + 9);
  EXPECT_DOUBLE_EQ(evaluateExact(*exact, 2.0, names), 0.05 * std::cos(40.0) + 8);
}

// Every mistake is a diagnostic in the "--exact" buffer, pointing at the text the user typed.
TEST(WorkPrecisionExact, MistakesAreLocatedInTheExactText) {
  struct Case {
    std::string text;
    std::string message;
    uint32_t begin;
  };
  for (const Case& c : std::vector<Case>{{"x = 2*omega*time", "unknown name 'omega'", 6},
                                         {"x = coz(time)", "unknown function 'coz'", 4},
                                         {"y = time", "'y' is not a result column", 0},
                                         {"x = atan2(time)", "atan2 takes 2 arguments", 4},
                                         {"x = (time", "expected", 9}}) {
    SourceManager sources;
    DiagnosticEngine diags;
    EXPECT_FALSE(parseExact(c.text, {"x"}, {}, sources, diags)) << c.text;
    ASSERT_TRUE(diags.hasErrors()) << c.text;
    const Diagnostic& d = diags.diagnostics().front();
    EXPECT_NE(d.message.find(c.message), std::string::npos) << d.message;
    EXPECT_EQ(sources.name(d.range.file), "--exact");
    EXPECT_EQ(d.range.begin, c.begin) << c.text;
  }
}

TEST(SvgChart, HasOnePolylinePerSeriesDecadeTicksAndALegend) {
  std::string svg = logLogChart({{"llvm/ida", {{1e-3, 0.05}, {1e-6, 0.2}}, {"1e-03", "1e-06"}},
                                 {"bytecode/ida", {{2e-3, 0.01}, {0, 1}}, {}}},
                                {"title <&>", "error", "time [s]"});
  EXPECT_EQ(svg.rfind("<svg", 0), 0u);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  std::size_t polylines = 0;
  for (std::size_t at = svg.find("<polyline"); at != std::string::npos; at = svg.find("<polyline", at + 1)) ++polylines;
  EXPECT_EQ(polylines, 2u);
  EXPECT_NE(svg.find(">-6</tspan>"), std::string::npos);  // x decades 1e-6 … 1e-2
  EXPECT_NE(svg.find(">-2</tspan>"), std::string::npos);
  EXPECT_NE(svg.find("bytecode/ida"), std::string::npos);
  EXPECT_NE(svg.find("title &lt;&amp;&gt;"), std::string::npos);
}

}  // namespace
}  // namespace qdot::driver
