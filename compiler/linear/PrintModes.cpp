// `qdot modes` output: a table for people, JSON for tools. Numbers in shortest round-trip form
// (JSON) or 10 significant digits (table).
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <ostream>

#include "linear/Linearize.h"
#include "qdot/number_text.hpp"

namespace qdot::linear {
namespace {

std::string list(const std::vector<double>& v, const char* separator) {
  std::string out;
  for (double x : v) out += (out.empty() ? "" : separator) + fmt::format("{:.10g}", x == 0 ? 0.0 : x);
  return out;
}

}  // namespace

void printModes(std::ostream& os, const LinearModel& s, const std::vector<Mode>& modes) {
  std::string names;
  for (const auto& c : s.coordinates) names += (names.empty() ? "" : ", ") + c;
  os << "operating point: " << names << " = " << list(s.point, ", ");
  if (s.equilibrium)
    os << " (static equilibrium at t = " << fmt::format("{:g}", s.time) << ", " << s.newtonIterations
       << " Newton iteration" << (s.newtonIterations == 1 ? "" : "s") << ")";
  else
    os << " (the start state at t = " << fmt::format("{:g}", s.time) << ")";
  os << "\n" << fmt::format("{:>4}  {:>16}  {:>16}  {:>12}  shape ({})\n", "mode", "omega [rad/s]", "f [Hz]", "zeta", names);
  for (size_t i = 0; i < modes.size(); ++i) {
    const Mode& m = modes[i];
    if (m.oscillating)
      os << fmt::format("{:>4}  {:>16.10g}  {:>16.10g}  {:>12.6g}  {}\n", i + 1, m.omega,
                        m.omega / (2 * std::numbers::pi), m.zeta == 0 ? 0.0 : m.zeta, list(m.shape, ", "));
    else
      os << fmt::format("{:>4}  {:>16}  {:>16}  {:>12}  {}   (not oscillating: e^({:.10g} t))\n", i + 1, "-", "-",
                        "-", list(m.shape, ", "), m.rate);
  }
}

void printModesJson(std::ostream& os, const LinearModel& s, const std::vector<Mode>& modes) {
  auto array = [](const std::vector<double>& v) {
    std::string out = "[";
    for (size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + shortestText(v[i]);
    return out + "]";
  };
  os << "{\"coordinates\": [";
  for (size_t i = 0; i < s.coordinates.size(); ++i) os << (i ? ", " : "") << '"' << s.coordinates[i] << '"';
  os << "], \"point\": " << array(s.point) << ", \"equilibrium\": " << (s.equilibrium ? "true" : "false")
     << ", \"newtonIterations\": " << s.newtonIterations << ", \"modes\": [";
  for (size_t i = 0; i < modes.size(); ++i) {
    const Mode& m = modes[i];
    os << (i ? ", " : "") << "{\"oscillating\": " << (m.oscillating ? "true" : "false") << ", \"omega\": "
       << shortestText(m.omega) << ", \"hz\": " << shortestText(m.omega / (2 * std::numbers::pi)) << ", \"zeta\": " << shortestText(m.zeta)
       << ", \"rate\": " << shortestText(m.rate) << ", \"shape\": " << array(m.shape) << "}";
  }
  os << "]}\n";
}

}  // namespace qdot::linear
