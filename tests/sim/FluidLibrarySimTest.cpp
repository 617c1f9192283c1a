// The examples of examples/fluids/ (built from stdlib/Fluid parts with `import Fluid.*;`) simulated
// by `qdot run` and compared with the fluid chapter's closed forms at every output time; the
// zero-flow and empty-tank cases also have their solver step counts bounded (no chattering, no
// step-size collapse).
#include <cmath>
#include <regex>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

constexpr double kRtol = 1e-8;

RunResult runExample(const std::string& name, double rtol = kRtol) {
  auto r = runQdot("examples/fluids/" + name + ".qd", {"--rtol", num(rtol), "--stats"});
  EXPECT_EQ(r.exitCode, 0) << r.log;
  return r;
}

// The rows of r with time ≤ until.
RunResult rowsUntil(const RunResult& r, double until) {
  RunResult head = r;
  const auto& t = r.time();
  const std::size_t n = std::upper_bound(t.begin(), t.end(), until) - t.begin();
  for (auto& [name, column] : head.columns) column.resize(n);
  head.rows = n;
  return head;
}

// A counter of `--stats` ("  steps   72 (last step …)"), or -1 when missing.
long statistic(const RunResult& r, const std::string& name) {
  std::smatch m;
  if (!std::regex_search(r.log, m, std::regex("\\n\\s*" + name + "\\s+(\\d+)"))) {
    ADD_FAILURE() << "no '" << name << "' in --stats:\n" << r.log;
    return -1;
  }
  return std::stol(m[1]);
}

// ---------------------------------------------------------------------------------------------
// torricelli.qd: OpenTank A = 0.5 m², h0 = 1 m → Orifice Cd = 0.5, area a = 1e-2 m² → Ambient.
//   A dh/dt = −Cd a √(2 g h):  h(t) = (√h0 − k t)²,  k = (Cd a/A) √(g/2),  drain time t_e = √h0/k.
// Bound while the exact level is above 1 mm (t ≤ 43.7 s of t_e = 45.15 s): 100 rtol h0 for the
// integration (a smooth decay, no phase error) plus the orifice's regularisation. Its flow is
// (1 + (δ/Δp)²)^(−1/4) of Torricelli's, δ = dpSmall = 1 Pa, Δp = ρ g h, so √h lags the exact
// √h by ∫ (δ/(ρ g s²))²/4 ds ≤ (δ/ρg)²/(12 h^(3/2)) and h by (δ/ρg)²/(6 h): 1.7e-6 m at h = 1 mm
// (we allow 1.5 times that). The tank's throttle acts only below hDry = 0.1 mm: no error here.
// Past empty: the level decays to zero and stays within [−1e-6, hDry] from t_e + 2 s to the end
// (80 s, 1.8 t_e); the run takes at most 200 steps (72 measured; chattering at the empty tank
// would take thousands).
TEST(FluidLibrary, TorricelliDrainsToEmptyAndStays) {
  auto r = runExample("torricelli");
  expectGrid(r, 0, 80, 0.1);
  const double h0 = 1, A = 0.5, Cd = 0.5, a = 1e-2, g = 9.81, rho = 1000, dpSmall = 1;
  const double k = (Cd * a / A) * std::sqrt(g / 2), te = std::sqrt(h0) / k, hDry = 1e-4;
  EXPECT_NEAR(te, (A / (Cd * a)) * std::sqrt(2 * h0 / g), 1e-12);
  const double hCompared = 1e-3, tCompared = (std::sqrt(h0) - std::sqrt(hCompared)) / k;
  auto exact = [&](double t) { return std::pow(std::sqrt(h0) - k * t, 2); };
  auto bound = [&](double t) {
    const double reg = std::pow(dpSmall / (rho * g), 2) / (6 * exact(t));
    return 100 * kRtol * h0 + 1.5 * reg;
  };
  const RunResult draining = rowsUntil(r, tCompared);
  compareColumn(draining, "tank.h", exact, bound);
  // Q = Cd a √(2 g h): an error ε in h is an error Cd a √(2g) ε/(2√h) in Q; the regularised law
  // itself is below Torricelli's by at most (δ/Δp)²/4 relative.
  auto torricelliQ = [&](double t) { return Cd * a * std::sqrt(2 * g * exact(t)); };
  compareColumn(draining, "orifice.a.Q", torricelliQ, [&](double t) {
    const double direct = torricelliQ(t) * std::pow(dpSmall / (rho * g * exact(t)), 2) / 4;
    return Cd * a * std::sqrt(2 * g) * bound(t) / (2 * std::sqrt(exact(t))) + direct;
  });

  const auto &t = r.time(), &h = r.col("tank.h");
  for (std::size_t i = 0; i < h.size(); ++i) {
    EXPECT_GE(h[i], -1e-6) << "the level went below zero at t = " << t[i];
    if (t[i] >= te + 2) {
      EXPECT_LE(h[i], hDry) << "not empty at t = " << t[i];
    }
  }
  EXPECT_LE(statistic(r, "steps"), 200);
  std::cout << "[measured] steps " << statistic(r, "steps") << ", error-test failures "
            << statistic(r, "error-test failures") << ", lowest level " << *std::min_element(h.begin(), h.end())
            << " m\n";
}

// The same run at the default tolerance (1e-6): it finishes, the level stays above −hDry.
TEST(FluidLibrary, TorricelliAtDefaultToleranceRunsPastEmpty) {
  auto r = runExample("torricelli", 1e-6);
  const auto& h = r.col("tank.h");
  EXPECT_GE(*std::min_element(h.begin(), h.end()), -1e-4);
  EXPECT_LE(h.back(), 1e-4);
  EXPECT_LE(statistic(r, "steps"), 200);
}

}  // namespace
}  // namespace qdot::simtest
