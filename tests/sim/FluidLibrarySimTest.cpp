// The examples of examples/fluids/ (built from stdlib/Fluid parts with `import Fluid.*;`) simulated
// by `qdot run` and compared with the fluid chapter's closed forms at every output time; the
// zero-flow and empty-tank cases also have their solver step counts bounded (no chattering, no
// step-size collapse).
#include <algorithm>
#include <cmath>
#include <functional>
#include <regex>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

constexpr double kRtol = 1e-8;

RunResult runExample(const std::string& name, double rtol = kRtol) {
  auto r = runQdot("examples/fluids/" + name + ".qd", {"--rtol", num(rtol), "--stats"});
  EXPECT_EQ(r.exitCode, 0) << r.log;
  // A library part must not make a correct model noisy (e.g. a start value on a connector's
  // pressure, unused wherever the node's pressure is fixed, is warning W0302 in every such model).
  EXPECT_EQ(r.log.find("warning"), std::string::npos) << r.log;
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
// Bound while the exact level is above 1 mm (t ≤ 43.7 s of t_e = 45.15 s): 200 rtol h0 for the
// integration (a smooth decay, no phase error; IDA's first low-order steps leave an offset of about
// 100 rtol h0, measured 0.9e-6 m at rtol 1e-8) plus the orifice's regularisation. Its flow is
// (1 + (δ/Δp)²)^(−1/4) of Torricelli's, δ = dpSmall = 1 Pa, Δp = ρ g h, so √h lags the exact
// √h by ∫ (δ/(ρ g s²))²/4 ds ≤ (δ/ρg)²/(12 h^(3/2)) and h by (δ/ρg)²/(6 h): 1.7e-6 m at h = 1 mm
// (we allow 1.5 times that). The tank's throttle acts only below hDry = 0.1 mm: no error here.
// Past empty: the level decays to zero and stays within [−1e-6, hDry] from t_e + 2 s to the end
// (80 s, 1.8 t_e); the run takes at most 500 steps (236 measured; chattering at the empty tank
// would take thousands). It took 72 while the port's pressure and flows were unknowns of the
// system: the pressure's nominal 1e5 then set the scale of h's absolute tolerance as well (100 m,
// one kind of unknown); `qdot run` now solves them out (dae/ExplicitAlgebraics.h) and h has its own.
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
    return 200 * kRtol * h0 + 1.5 * reg;
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
  EXPECT_LE(statistic(r, "steps"), 500);
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
  EXPECT_LE(statistic(r, "steps"), 500);
}

// ---------------------------------------------------------------------------------------------
// laminar_startup.qd: Reservoir h = 1.04 m → Pipe L = 10 m, D = 1 cm (from rest) → Reservoir h = 1 m.
//   rho L/Ap dQ/dt = Δp − R Q:  Q(t) = Q∞ (1 − e^(−t/τ)),  Q∞ = Δp/R,  R = 128 mu L/(π D⁴),
//   τ = rho L/(Ap R) = 3.125 s,  Δp = rho g · 0.04 m.
// The Reynolds number stays below 2000 (1227 at Q∞), where the pipe's friction is exactly
// Hagen–Poiseuille, so the closed form is the model's exact solution. Bound: 100 rtol (|Q∞| + Ap·1 m/s)
// (the flow's error scale is its nominal Ap·1 m/s, a decay has no phase error to accumulate).
TEST(FluidLibrary, LaminarStartupApproachesHagenPoiseuille) {
  auto r = runExample("laminar_startup");
  expectGrid(r, 0, 20, 0.05);
  const double rho = 1000, g = 9.81, mu = 1e-3, L = 10, D = 0.01, Ap = M_PI * D * D / 4;
  const double dp = rho * g * (1.04 - 1), R = 128 * mu * L / (M_PI * std::pow(D, 4)), Qinf = dp / R;
  const double tau = rho * L / (Ap * R);
  EXPECT_NEAR(tau, rho * D * D / (32 * mu), 1e-12);
  EXPECT_LT(4 * rho * Qinf / (M_PI * mu * D), 2000) << "the example must stay laminar";
  auto exact = [&](double t) { return Qinf * (1 - std::exp(-t / tau)); };
  auto bound = [&](double) { return 100 * kRtol * (Qinf + Ap); };
  compareColumn(r, "pipe.Q", exact, bound);
  compareColumn(r, "lower.port.Q", exact, bound);  // the flow into the lower reservoir
  EXPECT_NEAR(r.col("pipe.Q").back(), Qinf * (1 - std::exp(-20 / tau)), bound(20));
}

// ---------------------------------------------------------------------------------------------
// two_tanks.qd: OpenTank A1 = 0.02 m², h1 = 1.1 m and OpenTank A2 = 0.01 m², h2 = 0.8 m joined by a
// loss-free Pipe (L = 2 m, D = 5 cm, friction = false), from rest:
//   y = h1 − h2 = y0 cos ωt,  ω² = g Ap (1/A1 + 1/A2)/L,  Q = y0 ω/(1/A1 + 1/A2) · sin ωt.
// Each level: h1 = h̄ + (A2/(A1 + A2)) y, h2 = h̄ − (A1/(A1 + A2)) y with h̄ = V/(A1 + A2).
// Bounds: the levels 100 rtol h̄ per period elapsed plus two periods' worth at the start (their error
// scale is the level itself, 1 m: IDA's first low-order steps leave about 100 rtol h̄ of offset in y,
// measured 0.98e-6 m at rtol 1e-8, 7e-6 at 1e-6); y = h1 − h2 carries both levels' errors, and
// Q = A1 A2/(A1 + A2) · ẏ is y shifted by a quarter period times ω, so Q's bound is 2 Qamp/y0 times
// the levels'. The total volume A1 h1 + A2 h2 (the `volume`
// column) is conserved: the pipe's flows into the two tanks cancel exactly, so only the
// integration error of the two levels, 100 rtol V over the run, may change it. The levels stay
// far above hDry, where the tanks are exact.
TEST(FluidLibrary, TwoTanksOscillateAndConserveVolume) {
  auto r = runExample("two_tanks");
  expectGrid(r, 0, 30, 0.01);
  const double g = 9.81, A1 = 0.02, A2 = 0.01, L = 2, D = 0.05, Ap = M_PI * D * D / 4;
  const double y0 = 1.1 - 0.8, w = std::sqrt(g * Ap * (1 / A1 + 1 / A2) / L), period = 2 * M_PI / w;
  const double V = A1 * 1.1 + A2 * 0.8, hMean = V / (A1 + A2), Qamp = y0 * w / (1 / A1 + 1 / A2);
  auto y = [&](double t) { return y0 * std::cos(w * t); };
  auto levelBound = [&](double t) { return kPhaseFactor * kRtol * hMean * (2 + t / period); };
  compareColumn(r, "tank1.h", [&](double t) { return hMean + A2 / (A1 + A2) * y(t); }, levelBound);
  compareColumn(r, "tank2.h", [&](double t) { return hMean - A1 / (A1 + A2) * y(t); }, levelBound);
  compareColumn(
      r, "pipe.Q", [&](double t) { return Qamp * std::sin(w * t); },
      [&](double t) { return 2 * Qamp / y0 * levelBound(t); });
  const double volumeDrift = drift(r, "volume");
  EXPECT_LE(volumeDrift, 100 * kRtol * V);
  std::cout << "[measured] ω = " << w << " rad/s, volume drift " << volumeDrift << " m³ (" << volumeDrift / V
            << " of V)\n";
}

// ---------------------------------------------------------------------------------------------
// flow_reversal.qd: tank 1 → Pump (dp0 = 2e4 Pa, Q0 = 0.03 m³/s, speed 1/(1 + e^((t − 30)/2))) →
// Pipe (L = 20 m, D = 10 cm, roughness 0.1 mm) → tank 2, both tanks 1 m² at 1 m. The pump lifts
// water into tank 2 (turbulent, Re ≈ 2e5), stops around t = 30 s, and the flow reverses and sloshes
// back and forth, each time through the laminar–turbulent blend and zero flow.
// Checks: (1) the flow changes sign at least four times; (2) the total volume A1 h1 + A2 h2 is
// conserved within 100 rtol V; (3) the stored energy E = rho L Q²/(2 Ap) + rho g (A1 h1² + A2 h2²)/2
// obeys dE/dt = Q (b.p − a.p)_pump − Q Δp_f(Q): once the pump has stopped (t ≥ 60 s, speed² < 1e-13)
// both terms only remove energy (the stopped pump's −dp0 Q abs(Q)/Q0² and the friction are odd in Q), so
// E never rises from one output time to the next by more than its error scale rtol rho g (A1 + A2)
// (1 m)² = 2e-4 J (each level's absolute tolerance rtol·1 m times rho g A h); a stopped pump whose
// curve were even in Q (−dp0 Q²/Q0²) would drive the backflow, but not enough to show here (the pipe's friction would still win); so the pump is checked on its own: (4) its
// rise b.p − a.p equals dp0 (speed² − Q abs(Q)/Q0²) at every output time within 100 rtol · 1e5 Pa
// (the pressures' error scale is their nominal 1 bar), and once stopped it absorbs power,
// Q (b.p − a.p) ≤ 0 (an even curve would give +22 W at −0.01 m³/s);
// (5) no chattering at zero flow: at most 1500 steps and 150 error-test failures for the 200 s
// (902 and 47 measured at rtol 1e-8).
TEST(FluidLibrary, FlowReversalThroughZeroWithoutChattering) {
  auto r = runExample("flow_reversal");
  expectGrid(r, 0, 200, 0.1);
  const double rho = 1000, g = 9.81, A1 = 1, A2 = 1, L = 20, D = 0.1, Ap = M_PI * D * D / 4;
  const auto &t = r.time(), &Q = r.col("pipe.Q"), &h1 = r.col("tank1.h"), &h2 = r.col("tank2.h");
  int signChanges = 0;
  for (std::size_t i = 1; i < Q.size(); ++i) signChanges += (Q[i - 1] > 0) != (Q[i] > 0);
  EXPECT_GE(signChanges, 4);
  EXPECT_GT(*std::max_element(Q.begin(), Q.end()), 0.015);  // pumped forward, turbulent
  EXPECT_LT(*std::min_element(Q.begin(), Q.end()), -0.01);  // and back, turbulent
  const double V = A1 * 1 + A2 * 1;
  EXPECT_LE(drift(r, "volume"), 100 * kRtol * V);
  auto energy = [&](std::size_t i) {
    return rho * L * Q[i] * Q[i] / (2 * Ap) + rho * g * (A1 * h1[i] * h1[i] + A2 * h2[i] * h2[i]) / 2;
  };
  const double energyTolerance = kRtol * rho * g * (A1 + A2);
  double largestRise = -INFINITY;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i - 1] < 60) continue;
    const double rise = energy(i) - energy(i - 1);
    largestRise = std::max(largestRise, rise);
    EXPECT_LE(rise, energyTolerance) << "energy rose between t = " << t[i - 1] << " and " << t[i];
  }
  EXPECT_LT(energy(t.size() - 1), energy(600) - 1) << "the sloshing is damped";
  const double dp0 = 2e4, Q0 = 0.03;
  const auto &pIn = r.col("tank1.port.p"), &pOut = r.col("pump.b.p");
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double speed = 1 / (1 + std::exp((t[i] - 30) / 2)), rise = pOut[i] - pIn[i];
    EXPECT_NEAR(rise, dp0 * (speed * speed - Q[i] * std::fabs(Q[i]) / (Q0 * Q0)), 100 * kRtol * 1e5) << "t = " << t[i];
    if (t[i] >= 60) {
      EXPECT_LE(Q[i] * rise, 1e-9) << "the stopped pump drives the flow at t = " << t[i];
    }
  }
  const long steps = statistic(r, "steps"), failures = statistic(r, "error-test failures");
  EXPECT_LE(steps, 1500);
  EXPECT_LE(failures, 150);
  std::cout << "[measured] " << signChanges << " flow reversals, steps " << steps << ", error-test failures "
            << failures << ", volume drift " << drift(r, "volume") << " m³, largest energy rise after the stop "
            << largestRise << " J (tolerance " << energyTolerance << " J)\n";
}

// ---------------------------------------------------------------------------------------------
// The Pipe's friction law as stdlib/Fluid/README.md states it: Hagen–Poiseuille up to Re 2000,
// Darcy–Weisbach with Haaland's factor from 4000, the C¹ smooth step s = x²(3 − 2x) between.
struct PipeLaw {
  double L, D, roughness, rho = 1000, mu = 1e-3;
  double area() const { return M_PI * D * D / 4; }
  double reynolds(double Q) const { return rho * std::fabs(Q) * D / (mu * area()); }
  static double haaland(double Re, double relativeRoughness) {
    return std::pow(-1.8 * std::log10(std::pow(relativeRoughness / 3.7, 1.11) + 6.9 / Re), -2);
  }
  double loss(double Q) const {
    const double laminar = 128 * mu * L * Q / (M_PI * std::pow(D, 4));
    const double Re = reynolds(Q), f = haaland(std::max(Re, 2000.0), roughness / D);
    const double turbulent = f * (L / D) * rho / (2 * area() * area()) * Q * std::fabs(Q);
    const double x = std::clamp((Re - 2000) / 2000, 0.0, 1.0), s = x * x * (3 - 2 * x);
    return (1 - s) * laminar + s * turbulent;
  }
  // The steady flow for a pressure difference dp > 0 (the loss grows with Q: bisection).
  double steadyFlow(double dp) const {
    double lo = 0, hi = 1;
    for (int i = 0; i < 200; ++i) {
      const double mid = 0.5 * (lo + hi);
      (loss(mid) < dp ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
  }
};

// Colebrook's Darcy friction factor, by fixed-point iteration (converges in a few steps).
double colebrook(double Re, double relativeRoughness) {
  double f = 0.02;
  for (int i = 0; i < 100; ++i) f = std::pow(-2 * std::log10(relativeRoughness / 3.7 + 2.51 / (Re * std::sqrt(f))), -2);
  return f;
}

// steady_pipes.qd: three pipes between reservoirs settle to the flow where rho g ΔH = Δp_f(Q):
// turbulent (ΔH = 10 m, L = 100 m, D = 5 cm, roughness 0.05 mm; Re ≈ 1.06e5), in the transition band
// (ΔH = 0.15 m, L = 10 m, D = 1 cm; Re ≈ 3000) and laminar (ΔH = 0.02 m; Re ≈ 610). The steady flows
// are solved from the law above by bisection; at t = 60 s the model must equal them within
// 100 rtol (Q + Ap·1 m/s) (the flow's error scale) plus what is left of the slowest (laminar)
// start-up, Q e^(−60/τ) with τ = rho D²/(32 mu) = 3.125 s (5e-9 relative). The laminar flow also
// equals Hagen–Poiseuille's rho g ΔH π D⁴/(128 mu L), and Haaland's factor at the turbulent pipe's
// Reynolds number is within 2 % of Colebrook's (the Moody chart's equation).
TEST(FluidLibrary, SteadyPipeFlowInAllThreeRegimes) {
  auto r = runExample("steady_pipes");
  expectGrid(r, 0, 60, 0.1);
  const double rho = 1000, g = 9.81, mu = 1e-3;
  struct Case {
    const char* pipe;
    PipeLaw law;
    double head;
  } cases[] = {{"turbulent", {100, 0.05, 5e-5}, 10}, {"transition", {10, 0.01, 0}, 0.15}, {"laminar", {10, 0.01, 0}, 0.02}};
  for (const auto& c : cases) {
    const double expected = c.law.steadyFlow(rho * g * c.head), got = r.col(std::string(c.pipe) + ".Q").back();
    const double tau = rho * c.law.D * c.law.D / (32 * mu);
    EXPECT_NEAR(got, expected, 100 * kRtol * (expected + c.law.area()) + expected * std::exp(-60 / tau)) << c.pipe;
    std::cout << "[measured] " << c.pipe << ": Q = " << got << " m³/s (law " << expected << ", relative error "
              << (got - expected) / expected << "), Re = " << c.law.reynolds(got) << "\n";
  }
  const double reTurbulent = cases[0].law.reynolds(r.col("turbulent.Q").back());
  const double reTransition = cases[1].law.reynolds(r.col("transition.Q").back());
  EXPECT_GT(reTurbulent, 4000);
  EXPECT_GT(reTransition, 2000);
  EXPECT_LT(reTransition, 4000);
  const double D = 0.01, L = 10, poiseuille = rho * g * 0.02 * M_PI * std::pow(D, 4) / (128 * mu * L);
  EXPECT_NEAR(r.col("laminar.Q").back(), poiseuille, 1e-6 * poiseuille);
  const double fHaaland = PipeLaw::haaland(reTurbulent, 1e-3), fColebrook = colebrook(reTurbulent, 1e-3);
  EXPECT_NEAR(fHaaland, fColebrook, 0.02 * fColebrook);
  std::cout << "[measured] Re " << reTurbulent << ": Haaland f = " << fHaaland << ", Colebrook f = " << fColebrook
            << " (" << (fHaaland - fColebrook) / fColebrook << ")\n";
}

// ---------------------------------------------------------------------------------------------
// venturi_meter.qd: Reservoir (3 m) → Pipe (20 m, D = 5 cm, smooth) → Venturi (D1 = 5 cm,
// D2 = 3.5 cm) → Ambient. (1) The meter reads the flow: Q = A2 √(2 (a.p − throat.p)/(rho (1 − (A2/A1)²)))
// with a.p = 101325 Pa (the meter discharges to the atmosphere, b.p = a.p) equals pipe.Q at every
// output time with Q > 1e-4 m³/s within 1e-6 relative (throat.p is computed from Q, so only the
// pressure's rounding, 1e-11 of 1 bar against a difference of ≥ 100 Pa, separates them).
// (2) Loss-free meter: the steady flow is the pipe law's for the whole head, rho g · 3 m = Δp_f(Q),
// within 100 rtol (Q + Ap) (the start-up's time constant is about 1.1 s, gone by t = 40 s).
TEST(FluidLibrary, VenturiMeterReadsTheFlow) {
  auto r = runExample("venturi_meter");
  expectGrid(r, 0, 40, 0.05);
  const double rho = 1000, g = 9.81, A1 = M_PI * 0.05 * 0.05 / 4, A2 = M_PI * 0.035 * 0.035 / 4, pa = 101325;
  const auto &Q = r.col("pipe.Q"), &throat = r.col("meter.throat.p");
  double largest = 0;
  for (std::size_t i = 0; i < Q.size(); ++i) {
    if (Q[i] <= 1e-4) continue;
    const double measured = A2 * std::sqrt(2 * (pa - throat[i]) / (rho * (1 - std::pow(A2 / A1, 2))));
    EXPECT_NEAR(measured, Q[i], 1e-6 * Q[i]) << "t = " << r.time()[i];
    largest = std::max(largest, std::fabs(measured - Q[i]) / Q[i]);
  }
  const PipeLaw pipe{20, 0.05, 0};
  const double steady = pipe.steadyFlow(rho * g * 3);
  EXPECT_NEAR(Q.back(), steady, 100 * kRtol * (steady + pipe.area()));
  EXPECT_GT(throat.back(), 0) << "the throat pressure must stay physical (no cavitation)";
  std::cout << "[measured] meter reading vs flow: largest relative difference " << largest << "; steady Q "
            << Q.back() << " (pipe law " << steady << ", Re " << pipe.reynolds(Q.back()) << "), throat "
            << throat.back() << " Pa\n";
}

// ---------------------------------------------------------------------------------------------
// floating_box.qd: FloatingBox m = 500 kg, Aw = 1 m², released at z0 = 5 cm from rest:
// z = z0 cos ωt, ω = √(rho g Aw/m) = 4.4294 rad/s, under oscillationBound (100 rtol z0 per period);
// the period from the upward zero crossings of z (linear interpolation between rows 5 ms apart,
// error below (ω h)² z0/8 / (ω z0) ≈ 1e-4 of an interval) equals 2π/ω within 1e-5 relative.
TEST(FluidLibrary, FloatingBoxHeaveFrequency) {
  auto r = runExample("floating_box");
  expectGrid(r, 0, 10, 0.005);
  const double rho = 1000, g = 9.81, m = 500, Aw = 1, z0 = 0.05, w = std::sqrt(rho * g * Aw / m), period = 2 * M_PI / w;
  compareColumn(r, "box.z", [&](double t) { return z0 * std::cos(w * t); },
                [&](double t) { return oscillationBound(kRtol, z0, period, t); });
  compareColumn(r, "der(box.z)", [&](double t) { return -z0 * w * std::sin(w * t); },
                [&](double t) { return oscillationBound(kRtol, z0 * w, period, t); });
  const auto &t = r.time(), &z = r.col("box.z");
  std::vector<double> crossings;
  for (std::size_t i = 0; i + 1 < z.size(); ++i)
    if (z[i] < 0 && z[i + 1] >= 0) crossings.push_back(t[i] + (t[i + 1] - t[i]) * z[i] / (z[i] - z[i + 1]));
  ASSERT_GE(crossings.size(), 3u);
  const double measured = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  EXPECT_NEAR(measured, period, 1e-5 * period);
  std::cout << "[measured] heave period " << measured << " s (2π/ω = " << period << " s)\n";
}

// ---------------------------------------------------------------------------------------------
// gate.qd: the hydrostatics functions of Fluid on a gate (w = 1.5 m, edges 1.2 m and 0.2 m above the
// floor) in a tank (2 m²) filled at 0.01 m³/s from h = 2 m: h = 2 + 0.005 t exactly (a constant
// rate, which BDF integrates to rounding: within 1e-12 m, measured 4e-16). The oracles are the textbook's forms, not
// the library's: with the edges at depths d1 = h − 1.2, d2 = h − 0.2, the gate's height b = d2 − d1
// and its centroid's depth ȳ = (d1 + d2)/2,
//   F = rho g ȳ (w b)   (the pressure at the centroid times the area; = rho g w (d2² − d1²)/2),
//   y_cp = ȳ + I/(ȳ A) = ȳ + b²/(12 ȳ)   (= (2/3)(d2³ − d1³)/(d2² − d1²)),
// the latch's force F (y_cp − d1)/b, the floor's pressure p0 + rho g h and the sea-water force with
// rho = 1025 (a named argument). The functions' values are exact expressions of h: relative 1e-12
// covers the propagated 1e-12 m of h and rounding (measured below 2e-15).
TEST(FluidLibrary, GateForceAndCentreOfPressureFromTheFunctions) {
  auto r = runExample("gate");
  expectGrid(r, 0, 100, 1);
  const double rho = 1000, g = 9.81, w = 1.5, zTop = 1.2, zBottom = 0.2, b = zTop - zBottom;
  auto h = [](double t) { return 2 + 0.005 * t; };
  auto centroid = [&](double t) { return h(t) - (zTop + zBottom) / 2; };
  auto force = [&](double t, double density) { return density * g * centroid(t) * w * b; };
  auto ycp = [&](double t) { return centroid(t) + b * b / (12 * centroid(t)); };
  auto relative = [](const std::function<double(double)>& f) { return [f](double t) { return 1e-12 * std::fabs(f(t)); }; };
  compareColumn(r, "h", h, [](double) { return 1e-12; });
  std::function<double(double)> F = [&](double t) { return force(t, rho); };
  std::function<double(double)> FSea = [&](double t) { return force(t, 1025); };
  std::function<double(double)> Y = ycp;
  std::function<double(double)> latch = [&](double t) { return F(t) * (ycp(t) - (h(t) - zTop)) / b; };
  std::function<double(double)> pFloor = [&](double t) { return 101325 + rho * g * h(t); };
  compareColumn(r, "F", F, relative(F));
  compareColumn(r, "FSea", FSea, relative(FSea));
  compareColumn(r, "ycp", Y, relative(Y));
  compareColumn(r, "latch", latch, relative(latch));
  compareColumn(r, "pFloor", pFloor, relative(pFloor));
}

// buoy.qd: a buoy (m = 200 kg, Aw = 0.5 m², H = 1 m) whose only force besides gravity is
// Fluid.buoyancy(Aw d), released at d = 0.5 m from rest: d = d_eq + a cos ωt, d_eq = m/(rho Aw) =
// 0.4 m, a = 0.1 m, ω = √(rho g Aw/m), under oscillationBound with the error scale of d (its largest
// value, 0.5 m: the tolerance is relative to d); the buoyancy column equals rho g Aw d of the same
// row (the inlined function, relative 1e-12) and stays in (0, rho g Aw H) (the box stays afloat).
TEST(FluidLibrary, BuoyHeavesOnArchimedesForce) {
  auto r = runExample("buoy");
  expectGrid(r, 0, 5, 0.01);
  const double rho = 1000, g = 9.81, m = 200, Aw = 0.5, dEq = m / (rho * Aw), a = 0.1, w = std::sqrt(rho * g * Aw / m);
  const double period = 2 * M_PI / w;
  compareColumn(r, "d", [&](double t) { return dEq + a * std::cos(w * t); },
                [&](double t) { return oscillationBound(kRtol, dEq + a, period, t); });
  const auto &d = r.col("d"), &Fb = r.col("Fb");
  for (std::size_t i = 0; i < d.size(); ++i) {
    EXPECT_NEAR(Fb[i], rho * g * Aw * d[i], 1e-12 * rho * g * Aw) << "row " << i;
    EXPECT_GT(Fb[i], 0);
    EXPECT_LT(Fb[i], rho * g * Aw * 1.0);
  }
}

// ---------------------------------------------------------------------------------------------
// surge_tank.qd: Reservoir H = 10 m → loss-free Pipe (L = 500 m, D = 0.5 m) → surge tank
// (As = 5 m²) and a valve (Cd = 0.6, a = 0.05 m²) to the atmosphere, in steady flow
// Q0 = Cd a √(2 g H); the valve closes at t = 10 s (logistic opening, width 5 ms). After it:
//   hs = H + Q0/(As ω) sin ω(t − 10),  Q = Q0 cos ω(t − 10),  ω = √(g Ap/(L As)),
// period 2π√(L As/(g Ap)), maximum surge v0 √(L As/(g Ap)) (Ap/As) = Q0/(As ω).
// Compared from t = 10.5 s (100 widths after the middle of the closure). The smooth closure is the
// sudden one convolved with a symmetric kernel of width s = 5 ms: it changes the surge's amplitude by
// the factor πωs/sinh(πωs) = 1 − 3e-8 and its phase not at all. Bounds: oscillationBound with the
// level's error scale, its largest value H + Q0/(As ω) (the tank's tolerance is relative to its
// level), and with Q0 for the flow. Before the closure the level stays at H within 100 rtol H.
// The measured maximum surge equals Q0/(As ω) within 1e-5 relative (rows 0.5 s apart near a peak
// of period 226 s: (ω·0.25 s)²/2 = 2.4e-5 at worst, the parabola through three rows is exact to
// far below that).
TEST(FluidLibrary, SurgeTankPeriodAndMaximumSurge) {
  auto r = runExample("surge_tank");
  expectGrid(r, 0, 600, 0.5);
  const double g = 9.81, H = 10, L = 500, D = 0.5, Ap = M_PI * D * D / 4, As = 5, tc = 10;
  const double Q0 = 0.6 * 0.05 * std::sqrt(2 * g * H), w = std::sqrt(g * Ap / (L * As)), period = 2 * M_PI / w;
  const double surge = Q0 / (As * w), v0 = Q0 / Ap;
  EXPECT_NEAR(surge, v0 * std::sqrt(L * As / (g * Ap)) * (Ap / As), 1e-12);
  EXPECT_NEAR(period, 2 * M_PI * std::sqrt(L * As / (g * Ap)), 1e-9);
  const RunResult before = rowsUntil(r, tc - 0.5);
  compareColumn(before, "surge.h", [&](double) { return H; }, [&](double) { return 100 * kRtol * H; });
  RunResult after = r;
  const auto& t = r.time();
  const std::size_t first = std::lower_bound(t.begin(), t.end(), tc + 0.5) - t.begin();
  for (auto& [name, column] : after.columns) column.erase(column.begin(), column.begin() + first);
  after.rows -= first;
  compareColumn(after, "surge.h", [&](double s) { return H + surge * std::sin(w * (s - tc)); },
                [&](double s) { return oscillationBound(kRtol, H + surge, period, s - tc); });
  compareColumn(after, "pipe.Q", [&](double s) { return Q0 * std::cos(w * (s - tc)); },
                [&](double s) { return oscillationBound(kRtol, Q0, period, s - tc); });
  const auto& h = r.col("surge.h");
  const std::size_t peak = std::max_element(h.begin(), h.end()) - h.begin();
  ASSERT_GT(peak, 0u);
  ASSERT_LT(peak + 1, h.size());
  const double curvature = h[peak + 1] - 2 * h[peak] + h[peak - 1], slope = h[peak + 1] - h[peak - 1];
  const double highest = h[peak] - slope * slope / (8 * curvature);
  EXPECT_NEAR(highest - H, surge, 1e-5 * surge);
  std::cout << "[measured] maximum surge " << highest - H << " m (closed form " << surge << " m), period " << period
            << " s\n";
}

// surge_tank_friction.qd: the same with a rough pipe (roughness 0.1 mm), started in steady flow by
// the initialization system. (1) The start: the level hs0 where rho g (H − hs0) = Δp_f(Q0) with the
// valve's Q0 = Cd a √(2 g hs0) (its regularisation is 1e-11 relative at 70 kPa), solved by bisection
// with the pipe law; the model's start equals it within 1e-6 relative (the Newton iteration's
// tolerance is far below). (2) Damping: the successive maxima of hs − H decrease, the first stays
// below the loss-free surge Q0/(As ω) for the same Q0, and the last swing (t ≥ 450 s) is less than
// half the first.
TEST(FluidLibrary, SurgeTankWithFrictionIsDamped) {
  auto r = runExample("surge_tank_friction");
  expectGrid(r, 0, 600, 0.5);
  const double g = 9.81, H = 10, L = 500, D = 0.5, Ap = M_PI * D * D / 4, As = 5, Cd = 0.6, a = 0.05;
  const PipeLaw pipe{L, D, 1e-4};
  double lo = 0, hi = H;  // the start level: the friction head falls as the level (and the flow) falls
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi), Q = Cd * a * std::sqrt(2 * g * mid);
    (1000 * g * (H - mid) > pipe.loss(Q) ? lo : hi) = mid;
  }
  const double hs0 = 0.5 * (lo + hi), Q0 = Cd * a * std::sqrt(2 * g * hs0);
  EXPECT_NEAR(r.col("surge.h").front(), hs0, 1e-6 * hs0);
  EXPECT_NEAR(r.col("pipe.Q").front(), Q0, 1e-6 * Q0);
  const auto &t = r.time(), &h = r.col("surge.h");
  std::vector<double> maxima;
  for (std::size_t i = 1; i + 1 < h.size(); ++i)
    if (t[i] > 10 && h[i] > h[i - 1] && h[i] >= h[i + 1]) maxima.push_back(h[i] - H);
  ASSERT_GE(maxima.size(), 2u);
  for (std::size_t i = 1; i < maxima.size(); ++i) EXPECT_LT(maxima[i], maxima[i - 1]) << "swing " << i;
  const double w = std::sqrt(g * Ap / (L * As));
  EXPECT_LT(maxima.front(), Q0 / (As * w));
  EXPECT_LT(maxima.back(), 0.5 * maxima.front());
  std::cout << "[measured] start level " << h.front() << " m (law " << hs0 << "), Q0 " << r.col("pipe.Q").front()
            << " m³/s; surge maxima above H:";
  for (double m : maxima) std::cout << " " << m;
  std::cout << " m (loss-free " << Q0 / (As * w) << " m)\n";
}

// ---------------------------------------------------------------------------------------------
// utube_parts.qd against examples/textbook/utube.qd (example 5-2): the U-tube from Fluid parts
// (two legs A = 1e-4 m², a loss-free pipe l = 1 m) and the textbook's Lagrangian l ẍ + 2 g x = 0 are
// one system: leg1.h − 0.3 m equals the textbook's x at every output time, both runs at rtol 1e-8,
// within twice oscillationBound (each run's own error) plus the parts' start offset, and both equal
// (h/2) cos(√(2g/l) t). The start offset: the ports' flows are algebraic unknowns whose automatic
// absolute tolerance is rtol × 1e-3 × the largest algebraic magnitude (the pressures, 1 bar), so
// IDACalcIC leaves them consistent only to about 1e-9 m³/s (measured −9.8e-10 where 0 is exact),
// which is 1e-5 m/s of level rate in a leg of 1e-4 m²; the first steps carry that into the levels:
// 2e-6 m measured at t = 0.01 s. We allow 1000 rtol h̄0 = 3.5e-6 m for it (a Fluid model with tiny
// areas may want `port(Q(nominal = …))` on its tanks).
TEST(FluidLibrary, UTubeFromPartsEqualsTheTextbookLagrangian) {
  auto parts = runExample("utube_parts");
  auto textbook = runQdot("examples/textbook/utube.qd", {"--rtol", num(kRtol)});
  ASSERT_EQ(textbook.exitCode, 0) << textbook.log;
  ASSERT_EQ(parts.rows, textbook.rows);
  const double g = 9.81, l = 1, amp = 0.05, w = std::sqrt(2 * g / l), period = 2 * M_PI / w;
  const auto &x = textbook.col("x"), &h1 = parts.col("leg1.h"), &t = parts.time();
  const double startOffset = 1000 * kRtol * 0.35;
  double largest = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_NEAR(h1[i] - 0.3, x[i], 2 * oscillationBound(kRtol, amp, period, t[i]) + startOffset) << "t = " << t[i];
    largest = std::max(largest, std::fabs(h1[i] - 0.3 - x[i]));
  }
  compareColumn(textbook, "x", [&](double s) { return amp * std::cos(w * s); },
                [&](double s) { return oscillationBound(kRtol, amp, period, s); });
  compareColumn(parts, "leg1.h", [&](double s) { return 0.3 + amp * std::cos(w * s); },
                [&](double s) { return oscillationBound(kRtol, amp, period, s) + startOffset; });
  std::cout << "[measured] largest |parts − textbook| " << largest << " m\n";
}

}  // namespace
}  // namespace qdot::simtest
