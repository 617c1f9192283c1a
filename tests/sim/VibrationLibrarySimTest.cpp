// The component examples of examples/vibration/ (built from stdlib/Vibration parts with
// `import Vibration.*;`) simulated by `qdot run` and compared with the vibration chapter's closed
// forms at every output time, plus the measured quantities a textbook states (period, logarithmic
// decrement, steady amplitude and phase, transmissibility, backbone frequency, limit cycle), and the
// proof of spec §7's energy rule: one system written flat and as connected parts gives one trajectory.
#include <array>
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// Every example runs at this tolerance; bounds below are in units of it (oscillationBound: 100 rtol A
// per period elapsed, see QdotRun.h).
constexpr double kRtol = 1e-8;

RunResult runExample(const std::string& name) {
  auto r = runQdot("examples/vibration/" + name + ".qd", {"--rtol", num(kRtol)});
  EXPECT_EQ(r.exitCode, 0) << r.log;
  return r;
}

using Fn = std::function<double(double)>;

// Compares column `name` with `exact` under the oscillation bound for amplitude `amp` and period `period`.
Deviation expectOscillation(const RunResult& r, const std::string& name, const Fn& exact, double amp, double period) {
  return compareColumn(r, name, exact, [=](double t) { return oscillationBound(kRtol, amp, period, t); });
}

// ---------------------------------------------------------------------------------------------
// Measurements on a sampled oscillation.

// upwardZeroCrossings (QdotRun.h) locates each period's zero crossing.

// The mean period between the first and the last upward zero crossing.
double measuredPeriod(const RunResult& r, const std::string& x, const std::string& v) {
  auto c = upwardZeroCrossings(r, x, v);
  if (c.size() < 2) {
    ADD_FAILURE() << x << ": fewer than two upward zero crossings";
    return NAN;
  }
  return (c.back() - c.front()) / static_cast<double>(c.size() - 1);
}

// Local maxima of a column as (time, value), each the vertex of the parabola through three rows.
std::vector<std::pair<double, double>> peaks(const RunResult& r, const std::string& x) {
  const auto &t = r.time(), &xs = r.col(x);
  std::vector<std::pair<double, double>> result;
  for (std::size_t i = 1; i + 1 < xs.size(); ++i) {
    if (!(xs[i] > xs[i - 1] && xs[i] >= xs[i + 1])) continue;
    double curvature = xs[i + 1] - 2 * xs[i] + xs[i - 1], slope = xs[i + 1] - xs[i - 1];
    double shift = -slope / (2 * curvature);  // in output intervals
    result.push_back({t[i] + shift * (t[i + 1] - t[i]), xs[i] - slope * slope / (8 * curvature)});
  }
  return result;
}

// Least-squares fit x ≈ X sin(ωt + θ) over the rows with t ≥ from: returns (X, θ).
std::pair<double, double> fitHarmonic(const RunResult& r, const std::string& x, double w, double from) {
  const auto &t = r.time(), &xs = r.col(x);
  double ss = 0, sc = 0, cc = 0, xsn = 0, xcs = 0;
  for (std::size_t i = 0; i < xs.size(); ++i) {
    if (t[i] < from) continue;
    double s = std::sin(w * t[i]), c = std::cos(w * t[i]);
    ss += s * s, sc += s * c, cc += c * c, xsn += xs[i] * s, xcs += xs[i] * c;
  }
  double det = ss * cc - sc * sc;
  double a = (xsn * cc - xcs * sc) / det, b = (xcs * ss - xsn * sc) / det;  // x ≈ a sin ωt + b cos ωt
  return {std::hypot(a, b), std::atan2(b, a)};
}

// ---------------------------------------------------------------------------------------------
// One degree of freedom, m ẍ + c ẋ + k x = F0 sin(ωt + ψ), from x(0) = x0, ẋ(0) = v0, underdamped
// (0 ≤ ζ < 1) and not at undamped resonance. Derivation: the particular solution
// x_p = X sin(ωt + ψ − φ), X = F0/√((k − mω²)² + (cω)²), φ = atan2(cω, k − mω²), plus the free part
// e^(−σt)(A cos ωd t + B sin ωd t), σ = c/(2m), ωd = √(k/m − σ²), fitted to the start:
// A = x0 − x_p(0), B = (v0 − ẋ_p(0) + σA)/ωd.
struct Oscillator {
  double m, c, k;
  double F0 = 0, w = 0, psi = 0;  // the drive
  double x0 = 0, v0 = 0;          // the start

  double sigma() const { return c / (2 * m); }
  double wd() const { return std::sqrt(k / m - sigma() * sigma()); }
  double amplitude() const { return F0 / std::hypot(k - m * w * w, c * w); }
  double lag() const { return std::atan2(c * w, k - m * w * w); }
  double A() const { return x0 - amplitude() * std::sin(psi - lag()); }
  double B() const { return (v0 - amplitude() * w * std::cos(psi - lag()) + sigma() * A()) / wd(); }
  double x(double t) const {
    double e = std::exp(-sigma() * t);
    return amplitude() * std::sin(w * t + psi - lag()) + e * (A() * std::cos(wd() * t) + B() * std::sin(wd() * t));
  }
  double v(double t) const {
    double e = std::exp(-sigma() * t), cs = std::cos(wd() * t), sn = std::sin(wd() * t);
    return amplitude() * w * std::cos(w * t + psi - lag()) +
           e * ((-sigma() * A() + wd() * B()) * cs + (-sigma() * B() - wd() * A()) * sn);
  }
  // Bounds of |x| and |ẋ| over all time, and the shorter of the two periods.
  double xmax() const { return amplitude() + std::hypot(A(), B()); }
  double vmax() const { return amplitude() * w + std::sqrt(k / m) * std::hypot(A(), B()); }
  double period() const { return 2 * M_PI / std::max(w, wd()); }
};

void expectOscillator(const RunResult& r, const std::string& mass, const Oscillator& o) {
  ASSERT_NEAR(o.x(0), o.x0, 1e-15);
  ASSERT_NEAR(o.v(0), o.v0, 1e-13);
  expectOscillation(r, mass + ".s", [&](double t) { return o.x(t); }, o.xmax(), o.period());
  expectOscillation(r, "der(" + mass + ".s)", [&](double t) { return o.v(t); }, o.vmax(), o.period());
}

// ---------------------------------------------------------------------------------------------
// free_vibration.qd. Mass–spring (m = 2, k = 200, x0 = 0.05): x = x0 cos ωn t, ωn = √(k/m) = 10;
// torsional disk (J = 0.02, kt = 8, φ0 = 0.1): φ = φ0 cos ωt t, ωt = √(kt/J) = 20; the wall's
// reaction (the flow through the Fixed's flange, the force on the wall) is k x.
// Bounds: oscillationBound for the trajectories; the periods measured from the upward zero crossings
// equal 2π/ω within 1e-6 relative (a crossing time is off by about its error/slope ≈ 100 rtol P).
TEST(VibrationLibrary, FreeVibrationNaturalFrequencies) {
  auto r = runExample("free_vibration");
  expectGrid(r, 0, 2, 0.002);
  const double wn = std::sqrt(200.0 / 2), wt = std::sqrt(8 / 0.02), x0 = 0.05, phi0 = 0.1;
  expectOscillation(r, "mass.s", [&](double t) { return x0 * std::cos(wn * t); }, x0, 2 * M_PI / wn);
  expectOscillation(r, "der(mass.s)", [&](double t) { return -x0 * wn * std::sin(wn * t); }, x0 * wn, 2 * M_PI / wn);
  expectOscillation(r, "disk.phi", [&](double t) { return phi0 * std::cos(wt * t); }, phi0, 2 * M_PI / wt);
  expectOscillation(r, "wall.a.f", [&](double t) { return 200 * x0 * std::cos(wn * t); }, 200 * x0, 2 * M_PI / wn);
  EXPECT_NEAR(measuredPeriod(r, "mass.s", "der(mass.s)"), 2 * M_PI / wn, 1e-6 * 2 * M_PI / wn);
  EXPECT_NEAR(measuredPeriod(r, "disk.phi", "der(disk.phi)"), 2 * M_PI / wt, 1e-6 * 2 * M_PI / wt);
}

// ---------------------------------------------------------------------------------------------
// damped_vibration.qd: m = 1, k = 100 (ωn = 10), x0 = 0.1 from rest, ζ = 0.05, 0.5, 1, 2.
// Closed forms (see the model's header) at every row under oscillationBound (A = x0, P = 2π/ωn).
// Logarithmic decrement: ln of the ratio of successive peaks of the lightly damped mass equals
// 2πζ/√(1 − ζ²) within 1e-5 (the parabolic peak is exact to (ωn h)⁴ ≈ 1e-8 of the peak).
// Critical damping: never below zero (bound: the tolerance, 1e-9), and it settles into the 2 % band
// (|x| ≤ 0.002 from then on) before both the underdamped mass (which overshoots below −1 % of x0)
// and the overdamped one; the settling times equal those of the closed forms within two output intervals.
TEST(VibrationLibrary, DampedVibrationDecrementAndCriticalDamping) {
  auto r = runExample("damped_vibration");
  expectGrid(r, 0, 3, 0.001);
  const double m = 1, k = 100, x0 = 0.1, wn = 10, period = 2 * M_PI / wn;
  Oscillator light{m, 1, k}, under{m, 10, k};
  light.x0 = under.x0 = x0;
  expectOscillator(r, "light", light);
  expectOscillator(r, "under", under);
  auto critical = [&](double t) { return x0 * (1 + wn * t) * std::exp(-wn * t); };
  const double zeta = 2, r1 = -wn * (zeta - std::sqrt(zeta * zeta - 1)), r2 = -wn * (zeta + std::sqrt(zeta * zeta - 1));
  auto over = [&](double t) { return x0 * (r1 * std::exp(r2 * t) - r2 * std::exp(r1 * t)) / (r1 - r2); };
  expectOscillation(r, "critical.s", critical, x0, period);
  expectOscillation(r, "over.s", over, x0, period);

  const double z = 0.05, delta = 2 * M_PI * z / std::sqrt(1 - z * z);
  auto p = peaks(r, "light.s");
  ASSERT_GE(p.size(), 3u);
  for (std::size_t i = 0; i + 1 < p.size(); ++i)
    EXPECT_NEAR(std::log(p[i].second / p[i + 1].second), delta, 1e-5) << "peaks at t = " << p[i].first;

  const auto& t = r.time();
  auto settling = [&](const std::vector<double>& x) {  // the first output time from which |x| ≤ 2 % x0
    double last = 0;
    for (std::size_t i = 0; i < x.size(); ++i)
      if (std::fabs(x[i]) > 0.02 * x0) last = t[std::min(i + 1, x.size() - 1)];
    return last;
  };
  auto sampled = [&](const Fn& f) {
    std::vector<double> v;
    for (double ti : t) v.push_back(f(ti));
    return v;
  };
  const auto &xc = r.col("critical.s"), &xu = r.col("under.s"), &xo = r.col("over.s");
  EXPECT_GE(*std::min_element(xc.begin(), xc.end()), -1e-9) << "critical damping overshoots";
  EXPECT_GE(*std::min_element(xo.begin(), xo.end()), -1e-9) << "overdamping overshoots";
  EXPECT_LT(*std::min_element(xu.begin(), xu.end()), -0.01 * x0) << "ζ = 0.5 should overshoot";
  const double tc = settling(xc), tu = settling(xu), to = settling(xo);
  EXPECT_LT(tc, tu);
  EXPECT_LT(tc, to);
  EXPECT_NEAR(tc, settling(sampled(critical)), 0.002);
  EXPECT_NEAR(to, settling(sampled(over)), 0.002);
  EXPECT_NEAR(tu, settling(sampled([&](double s) { return under.x(s); })), 0.002);
  std::cout << "[measured] settling into 2 %: ζ = 0.5 " << tu << " s, ζ = 1 " << tc << " s, ζ = 2 " << to << " s\n";
}

// ---------------------------------------------------------------------------------------------
// forced_response.qd: m = 1, c = 2, k = 100 (ζ = 0.1), F0 cos ωt (F0 = 10, ω = 5, 10, 15, 30), from rest.
// The full solution (Oscillator with ψ = π/2) at every row under oscillationBound; then the steady
// amplitude and phase lag fitted over the last 2 s (the transient is down to e^(−ζωn·13) = 2e−6 of
// its start): X within 1e-5 relative of F0/√((k − mω²)² + (cω)²) and φ within 1e-5 rad of
// atan2(cω, k − mω²) (the fit gives x ≈ X sin(ωt + θ), θ = π/2 − φ).
TEST(VibrationLibrary, ForcedResponseAmplitudeAndPhaseVsFrequencyRatio) {
  auto r = runExample("forced_response");
  expectGrid(r, 0, 15, 0.005);
  const double ws[] = {5, 10, 15, 30};
  for (int i = 0; i < 4; ++i) {
    Oscillator o{1, 2, 100, 10, ws[i], M_PI / 2};
    const std::string mass = std::string("m") + char('1' + i);
    expectOscillator(r, mass, o);
    auto [X, theta] = fitHarmonic(r, mass + ".s", o.w, 13);
    const double lag = M_PI / 2 - theta;
    EXPECT_NEAR(X, o.amplitude(), 1e-5 * o.amplitude()) << mass;
    EXPECT_NEAR(std::remainder(lag - o.lag(), 2 * M_PI), 0, 1e-5) << mass;
    std::cout << "[measured] r = " << o.w / 10 << ": X = " << X << " (closed form " << o.amplitude()
              << "), phase lag " << lag << " (closed form " << o.lag() << ")\n";
  }
}

// ---------------------------------------------------------------------------------------------
// undamped_resonance.qd: m = 1, k = 100, F0 cos ωt with F0 = 1 at ω = ωn = 10, from rest:
//   x = F0 t sin(ωt)/(2mω)   (substitute: m ẍ + k x = F0 cos ωt, x(0) = ẋ(0) = 0).
// Bound: oscillationBound with the final amplitude F0·10/(2mω). The peaks follow the envelope
// F0 t/(2mω): at a peak tan ωt = −ωt, so x = g t/√(1 + 1/(ωt)²), below g t by less than
// g/(2ω²t) ≤ g/ω (g = F0/(2mω)), plus 1e-6 for the tolerance.
TEST(VibrationLibrary, UndampedResonanceGrowsLinearly) {
  auto r = runExample("undamped_resonance");
  expectGrid(r, 0, 10, 0.005);
  const double m = 1, w = 10, f0 = 1, g = f0 / (2 * m * w), amp = g * 10;
  expectOscillation(r, "mass.s", [&](double t) { return g * t * std::sin(w * t); }, amp, 2 * M_PI / w);
  expectOscillation(
      r, "der(mass.s)", [&](double t) { return g * (std::sin(w * t) + w * t * std::cos(w * t)); }, amp * w,
      2 * M_PI / w);
  auto p = peaks(r, "mass.s");
  ASSERT_GE(p.size(), 10u);
  for (auto [t, x] : p) EXPECT_NEAR(x, g * t, g / w + 1e-6) << "peak at t = " << t;
  EXPECT_GT(p.back().second, 0.45);  // 0.5 m after 10 s: no damping limits it
}

// ---------------------------------------------------------------------------------------------
// base_excitation.qd: base y = Y sin ωt (Y = 0.01), mount k = 100, c = 2, mass 1 (ζ = 0.1), from rest.
// m ẍ + c ẋ + k x = k y + c ẏ = Y √(k² + (cω)²) sin(ωt + β), β = atan2(cω, k): the Oscillator with
// that drive, at every row under oscillationBound. The steady amplitude fitted over the last 2 s
// gives the transmissibility X/Y = √((1 + (2ζr)²)/((1 − r²)² + (2ζr)²)) within 1e-5 relative.
TEST(VibrationLibrary, BaseExcitationTransmissibility) {
  auto r = runExample("base_excitation");
  expectGrid(r, 0, 15, 0.005);
  const double m = 1, c = 2, k = 100, Y = 0.01, zeta = 0.1, ws[] = {5, std::sqrt(2.0) * 10, 30};
  for (int i = 0; i < 3; ++i) {
    const double w = ws[i], ratio = w / 10;
    Oscillator o{m, c, k, Y * std::hypot(k, c * w), w, std::atan2(c * w, k)};
    const std::string mass = std::string("m") + char('1' + i);
    expectOscillator(r, mass, o);
    const double tr = std::sqrt((1 + std::pow(2 * zeta * ratio, 2)) /
                                (std::pow(1 - ratio * ratio, 2) + std::pow(2 * zeta * ratio, 2)));
    auto [X, theta] = fitHarmonic(r, mass + ".s", w, 13);
    EXPECT_NEAR(X / Y, tr, 1e-5 * tr) << mass;
    std::cout << "[measured] r = " << ratio << ": X/Y = " << X / Y << " (closed form " << tr << ")\n";
  }
}

// ---------------------------------------------------------------------------------------------
// Two degrees of freedom, M ẍ + K x = F(t), M = diag(m1, m2), K = [[k11, k12], [k12, k22]]:
// natural frequencies from det(K − ω²M) = 0 (a quadratic in ω²) and mode shapes u = (1, (k11 − m1 ω²)/(−k12)).
struct TwoDof {
  double m1, m2, k11, k12, k22;
  std::array<double, 2> omegas() const {
    double a = m1 * m2, b = -(m1 * k22 + m2 * k11), c = k11 * k22 - k12 * k12, d = std::sqrt(b * b - 4 * a * c);
    return {std::sqrt((-b - d) / (2 * a)), std::sqrt((-b + d) / (2 * a))};
  }
  double shape(double w) const { return (k11 - m1 * w * w) / -k12; }  // x2/x1 in that mode
};

// two_dof.qd: m1 = 1, m2 = 2, k1 = 100, k2 = 50, k3 = 100, from rest at (0.05, 0).
// Free motion x = Σ_j c_j u_j cos ω_j t with c1 + c2 = x1(0), c1 r1 + c2 r2 = x2(0), r_j the
// shape ratios. Checks: ω1, ω2 and r1, r2 against the numbers in the model's header (7.8078, 12.8078;
// 1.7808, −0.2808, to 1e-4 — the quadratic's roots); the trajectories at every row under
// oscillationBound (A = Σ|c_j|·max(1, |r_j|), P = 2π/ω2).
TEST(VibrationLibrary, TwoDofModesAndFreeMotion) {
  auto r = runExample("two_dof");
  expectGrid(r, 0, 3, 0.002);
  TwoDof sys{1, 2, 150, -50, 150};
  auto [w1, w2] = sys.omegas();
  const double r1 = sys.shape(w1), r2 = sys.shape(w2);
  EXPECT_NEAR(w1, 7.8078, 1e-4);
  EXPECT_NEAR(w2, 12.8078, 1e-4);
  EXPECT_NEAR(r1, 1.7808, 1e-4);
  EXPECT_NEAR(r2, -0.2808, 1e-4);
  const double a = 0.05, b = 0, c2 = (b - r1 * a) / (r2 - r1), c1 = a - c2;
  const double amp = std::fabs(c1) * std::max(1.0, std::fabs(r1)) + std::fabs(c2) * std::max(1.0, std::fabs(r2));
  auto x1 = [&](double t) { return c1 * std::cos(w1 * t) + c2 * std::cos(w2 * t); };
  auto x2 = [&](double t) { return c1 * r1 * std::cos(w1 * t) + c2 * r2 * std::cos(w2 * t); };
  expectOscillation(r, "m1.s", x1, amp, 2 * M_PI / w2);
  expectOscillation(r, "m2.s", x2, amp, 2 * M_PI / w2);
  expectOscillation(
      r, "der(m2.s)", [&](double t) { return -c1 * r1 * w1 * std::sin(w1 * t) - c2 * r2 * w2 * std::sin(w2 * t); },
      amp * w2, 2 * M_PI / w2);
}

// beating.qd: two m = 1, k = 100 oscillators joined by kc = 4, from rest at (a, 0), a = 0.05:
//   x1 = a cos Δt cos ω̄t,  x2 = a sin Δt sin ω̄t,  ω1 = 10, ω2 = √108, Δ = (ω2 − ω1)/2, ω̄ = (ω1 + ω2)/2.
// Bound: oscillationBound (A = a, P = 2π/ω2). The energy passes completely: within a quarter period
// P = 2π/ω2 of t* = π/(ω2 − ω1) = 8.01 s, |x1| stays below 0.05 a (its envelope a |cos Δt| is at most
// a sin(Δ P/4) = 0.030 a there) while x2 reaches above 0.99 a (envelope ≥ 0.9996 a, and the window
// holds a crest of |sin ω̄t|).
TEST(VibrationLibrary, BeatingTransfersTheMotion) {
  auto r = runExample("beating");
  expectGrid(r, 0, 17, 0.005);
  const double a = 0.05, w1 = 10, w2 = std::sqrt(108.0), d = (w2 - w1) / 2, wm = (w1 + w2) / 2, period = 2 * M_PI / w2;
  expectOscillation(r, "m1.s", [&](double t) { return a * std::cos(d * t) * std::cos(wm * t); }, a, period);
  expectOscillation(r, "m2.s", [&](double t) { return a * std::sin(d * t) * std::sin(wm * t); }, a, period);
  const double tstar = M_PI / (w2 - w1);
  const auto &t = r.time(), &x1 = r.col("m1.s"), &x2 = r.col("m2.s");
  double max1 = 0, max2 = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (std::fabs(t[i] - tstar) <= period / 4) max1 = std::max(max1, std::fabs(x1[i])), max2 = std::max(max2, std::fabs(x2[i]));
  EXPECT_LT(max1, 0.05 * a);
  EXPECT_GT(max2, 0.99 * a);
}

// ---------------------------------------------------------------------------------------------
// forced_two_dof.qd: m1 = 1, k1 = 100, m2 = 0.1, k2 = 10, F0 cos ωt on m1 (F0 = 1, ω = 7), from rest.
// x = X cos ωt + Σ_j a_j u_j cos ω_j t with (K − ω²M) X = (F0, 0) and Σ_j a_j u_j = −X (x(0) = 0;
// ẋ(0) = 0 needs no sines). Bound: oscillationBound with A = max|X_i| + Σ_j |a_j| max(1, |r_j|).
TEST(VibrationLibrary, ForcedTwoDofFromRest) {
  auto r = runExample("forced_two_dof");
  expectGrid(r, 0, 5, 0.002);
  const double m1 = 1, k1 = 100, m2 = 0.1, k2 = 10, f0 = 1, w = 7;
  TwoDof sys{m1, m2, k1 + k2, -k2, k2};
  const double det = (k1 + k2 - m1 * w * w) * (k2 - m2 * w * w) - k2 * k2;
  const double X1 = f0 * (k2 - m2 * w * w) / det, X2 = f0 * k2 / det;
  auto [w1, w2] = sys.omegas();
  const double r1 = sys.shape(w1), r2 = sys.shape(w2);
  const double a2 = (-X2 + r1 * X1) / (r2 - r1), a1 = -X1 - a2;  // a1 + a2 = −X1, r1 a1 + r2 a2 = −X2
  auto x1 = [&](double t) { return X1 * std::cos(w * t) + a1 * std::cos(w1 * t) + a2 * std::cos(w2 * t); };
  auto x2 = [&](double t) { return X2 * std::cos(w * t) + r1 * a1 * std::cos(w1 * t) + r2 * a2 * std::cos(w2 * t); };
  const double amp = std::max(std::fabs(X1), std::fabs(X2)) + std::fabs(a1) * std::max(1.0, std::fabs(r1)) +
                     std::fabs(a2) * std::max(1.0, std::fabs(r2));
  const double period = 2 * M_PI / std::max(w, w2);
  expectOscillation(r, "m1.s", x1, amp, period);
  expectOscillation(r, "m2.s", x2, amp, period);
  EXPECT_GT(std::fabs(X1), 0.01);  // off the absorber's tuning the main mass does move
}

// absorber.qd: main mass m1 = 1, k1 = 100 driven at its resonance ω = 10 by F0 cos ωt (F0 = 1); the
// absorber m2 = 0.1, k2 = 10 is tuned to ω. Started in the steady state x1 = 0, x2 = −(F0/k2) cos ωt,
// it stays there: m1 within oscillationBound(A = F0/k2 = 0.1, P = 2π/ω) of 0 for the 5 s, the
// absorber on its cosine. For contrast, without the absorber the main mass would reach
// F0 t/(2 m1 ω) = 0.25 m by then, 10⁴ times that bound.
TEST(VibrationLibrary, TunedAbsorberHoldsTheMainMassStill) {
  auto r = runExample("absorber");
  expectGrid(r, 0, 5, 0.002);
  const double w = 10, xa = 0.1, period = 2 * M_PI / w;
  expectOscillation(r, "m1.s", [](double) { return 0.0; }, xa, period);
  expectOscillation(r, "der(m1.s)", [](double) { return 0.0; }, xa * w, period);
  expectOscillation(r, "m2.s", [&](double t) { return -xa * std::cos(w * t); }, xa, period);
  EXPECT_LT(oscillationBound(kRtol, xa, period, 5), 1e-4 * 5 / (2 * w));
}

// ---------------------------------------------------------------------------------------------
// string.qd: T = 100, rhoL = 0.01, L = 1, n = 20 (h = 1/21), from rest in a_k sin(kπ i/21),
// a = (2, 1, 0.5) mm. The chain's modes are exactly these sines with
//   ω_k = 2 √(T/(rhoL h²)) sin(kπ/(2(n + 1))),
// so y_i = Σ_k a_k sin(kπ i/21) cos ω_k t at every row under oscillationBound (A = Σ a_k, P = 2π/ω3).
TEST(VibrationLibrary, StringModesOfTheLumpedChain) {
  auto r = runExample("string");
  expectGrid(r, 0, 0.05, 0.0002);
  const int n = 20;
  const double T = 100, rhoL = 0.01, L = 1, h = L / (n + 1), amps[] = {0.002, 0.001, 0.0005};
  double w[4];
  for (int k = 1; k <= 3; ++k) w[k] = 2 * std::sqrt(T / (rhoL * h * h)) * std::sin(k * M_PI / (2 * (n + 1)));
  for (int i = 1; i <= n; ++i) {
    auto y = [&, i](double t) {
      double s = 0;
      for (int k = 1; k <= 3; ++k) s += amps[k - 1] * std::sin(k * M_PI * i / (n + 1)) * std::cos(w[k] * t);
      return s;
    };
    expectOscillation(r, "str.y[" + std::to_string(i) + "]", y, 0.0035, 2 * M_PI / w[3]);
  }
}

// tests/sim/models/string_fundamental.qd: the same string in its first mode for n = 3, 10, 40
// (`-p n=…`, a structural parameter passed on to the String by a modifier). The fundamental measured
// from the zero crossings of the middle mass over 10 periods equals the chain's exact
// 2 √(T/(rhoL h²)) sin(π/(2(n + 1))) within 1e-6 relative, so its relative distance from the
// continuous string's f1 = 1/(2L) √(T/rhoL) = 50 Hz is sin(x)/x − 1, x = π/(2(n + 1)), within 1e-6 —
// −2.5e−2, −3.4e−3, −2.4e−4: it shrinks as 1/n² (examples/vibration/README.md has the table).
TEST(VibrationLibrary, StringConvergesToTheContinuousString) {
  const double T = 100, rhoL = 0.01, L = 1, continuous = 1 / (2 * L) * std::sqrt(T / rhoL);
  double previous = INFINITY;
  for (int n : {3, 10, 40}) {
    auto r = runQdot("tests/sim/models/string_fundamental.qd", {"--rtol", num(kRtol), "-p", "n=" + std::to_string(n)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    const double h = L / (n + 1), x = M_PI / (2 * (n + 1));
    const double chain = 2 * std::sqrt(T / (rhoL * h * h)) * std::sin(x) / (2 * M_PI);
    const std::string mid = "str.y[" + std::to_string((n + 1) / 2) + "]";
    const double f = 1 / measuredPeriod(r, mid, "der(" + mid + ")"), error = f / continuous - 1;
    EXPECT_NEAR(f, chain, 1e-6 * chain) << "n = " << n;
    EXPECT_NEAR(error, std::sin(x) / x - 1, 1e-6) << "n = " << n;
    EXPECT_LT(std::fabs(error), previous);
    previous = std::fabs(error);
    std::cout << "[measured] n = " << n << ": f1 = " << f << " Hz, relative error against the continuous string "
              << error << "\n";
  }
}

// ---------------------------------------------------------------------------------------------
// duffing.qd: m = 1, k = 100, k3 = 1e4, from rest at A = 0.02, 0.05, 0.1.
// Exact period from the energy integral (x = A sin θ):
//   τ = 4 ∫_0^(π/2) dθ / √(k/m + (k3/(2m)) A² (1 + sin² θ))
// (Simpson's rule with 2000 panels: the integrand is smooth and periodic, error ≪ 1e-12).
// Checks: the period measured from the upward zero crossings within 1e-6 relative of τ; the
// frequency grows with the amplitude; the backbone ω² ≈ ω0² + ¾ (k3/m) A² holds within 0.03 ε² ω0²,
// ε = k3 A²/k (the next Lindstedt–Poincaré term is −(3/128) ε² ω0²); each mass starts at its A.
TEST(VibrationLibrary, DuffingBackbone) {
  auto r = runExample("duffing");
  expectGrid(r, 0, 6, 0.001);
  const double m = 1, k = 100, k3 = 1e4;
  auto exactPeriod = [&](double A) {
    const int panels = 2000;
    const double step = (M_PI / 2) / panels;
    double s = 0;
    for (int i = 0; i <= panels; ++i) {
      double th = i * step, f = 1 / std::sqrt(k / m + k3 / (2 * m) * A * A * (1 + std::pow(std::sin(th), 2)));
      s += (i == 0 || i == panels ? 1 : (i % 2 ? 4 : 2)) * f;
    }
    return 4 * s * step / 3;
  };
  double previous = 0;
  for (auto [mass, A] : {std::pair{"small", 0.02}, {"medium", 0.05}, {"large", 0.1}}) {
    const std::string x = std::string(mass) + ".s";
    EXPECT_NEAR(r.col(x).front(), A, 1e-15);
    const double tau = exactPeriod(A), measured = measuredPeriod(r, x, "der(" + x + ")");
    EXPECT_NEAR(measured, tau, 1e-6 * tau) << mass;
    const double w = 2 * M_PI / measured, eps = k3 * A * A / k;
    EXPECT_NEAR(w * w, k / m + 0.75 * k3 / m * A * A, 0.03 * eps * eps * k / m) << mass;
    EXPECT_GT(w, previous);
    previous = w;
    std::cout << "[measured] A = " << A << ": ω = " << w << " rad/s (exact " << 2 * M_PI / tau << ", backbone "
              << std::sqrt(k / m + 0.75 * k3 / m * A * A) << ")\n";
  }
}

// van_der_pol.qd: m = 1, k = 1, c = 0.2, A = 0.5 (μ = 0.2), from rest at 0.05 (inside) and 2 (outside).
// The limit cycle's amplitude is A (2 + μ²/96 + O(μ⁴)) = 1.000208 (averaging gives 2A; the μ² term is
// the next order of the expansion). Checks: the peaks of the last 20 s within 1e-4 relative of it
// (the transient decays as e^(−μ t) = e^(−20) by then); from inside the peaks grow, from outside
// they shrink, monotonically until they settle (each step allowed 1e-6 of rounding and tolerance).
TEST(VibrationLibrary, VanDerPolLimitCycleFromInsideAndOutside) {
  auto r = runExample("van_der_pol");
  expectGrid(r, 0, 120, 0.02);
  const double A = 0.5, mu = 0.2, cycle = A * (2 + mu * mu / 96);
  for (auto [mass, growing] : {std::pair{"inside", true}, {"outside", false}}) {
    auto p = peaks(r, std::string(mass) + ".s");
    ASSERT_GE(p.size(), 15u);
    for (std::size_t i = 0; i + 1 < p.size(); ++i) {
      if (p[i].first > 100) {
        EXPECT_NEAR(p[i].second, cycle, 1e-4 * cycle) << mass << " peak at t = " << p[i].first;
      }
      double step = p[i + 1].second - p[i].second;
      EXPECT_GT(growing ? step : -step, -1e-6) << mass << " peak at t = " << p[i].first;
    }
    EXPECT_NEAR(p.back().second, cycle, 1e-4 * cycle) << mass;
    std::cout << "[measured] " << mass << ": last peak " << p.back().second << " (A (2 + μ²/96) = " << cycle << ")\n";
  }
}

// ---------------------------------------------------------------------------------------------
// pendulum_absorber.qd: cart M = 1 on k = 49.05, pendulum m = 0.1, l = 0.2 (√(g/l) = √(k/M) = ω),
// F0 cos ωt on the cart (F0 = 1e-3), started in the linear steady state x = 0, φ = Φ cos ωt,
// Φ = −F0/(m g). Bounds: the pendulum within oscillationBound(A = |Φ|) of Φ cos ωt (the nonlinear
// detuning Φ²/16 = 6.5e−8 shifts its phase by < 3e−6 |Φ| over the 5 s); the cart within
// oscillationBound(A = |Φ| l) + 1e-3 F0/k of 0 (|Φ| l = 2e−4 m is the bob's swing; the O(Φ³) terms
// move the cart by far less than 1e-3 of the static deflection F0/k). Without the pendulum the cart
// would reach F0 t/(2Mω) = 3.6e−4 m.
TEST(VibrationLibrary, PendulumAbsorberHoldsTheCartStill) {
  auto r = runExample("pendulum_absorber");
  expectGrid(r, 0, 5, 0.002);
  const double M = 1, k = 49.05, m = 0.1, l = 0.2, g = 9.81, f0 = 1e-3, w = std::sqrt(g / l);
  ASSERT_NEAR(std::sqrt(k / M), w, 1e-12);
  const double phi = -f0 / (m * g), period = 2 * M_PI / w;
  compareColumn(
      r, "cart.s", [](double) { return 0.0; },
      [&](double t) { return oscillationBound(kRtol, std::fabs(phi) * l, period, t) + 1e-3 * f0 / k; });
  expectOscillation(r, "pendulum.phi", [&](double t) { return phi * std::cos(w * t); }, std::fabs(phi), period);
  EXPECT_LT(oscillationBound(kRtol, std::fabs(phi) * l, period, 5) + 1e-3 * f0 / k, 1e-2 * f0 * 5 / (2 * M * w));
}

// base_excited_pendulum.qd: pivot y = Y sin Ωt (Y = 1e-3, Ω = 2), m = l = 1, g = 9.81, from rest:
// small-angle solution φ = (YΩ²/l)/(ω0² − Ω²) (sin Ωt − (Ω/ω0) sin ω0 t), ω0 = √(g/l).
// Bound: oscillationBound(A = Φmax) plus the neglected nonlinear terms: sin φ − φ and (1 − cos φ) ÿ
// are below Φmax³/6 relative to the restoring force, so φ differs from the linear solution by at most
// 1e-6 Φmax per period elapsed (Φmax²/6 = 2e−7 of Φmax, accumulating in phase).
TEST(VibrationLibrary, BaseExcitedPendulumSmallAngleResponse) {
  auto r = runExample("base_excited_pendulum");
  expectGrid(r, 0, 10, 0.005);
  const double Y = 1e-3, W = 2, l = 1, g = 9.81, w0 = std::sqrt(g / l);
  const double coef = (Y * W * W / l) / (w0 * w0 - W * W), phimax = coef * (1 + W / w0), period = 2 * M_PI / w0;
  compareColumn(
      r, "pendulum.phi", [&](double t) { return coef * (std::sin(W * t) - W / w0 * std::sin(w0 * t)); },
      [&](double t) { return oscillationBound(kRtol, phimax, period, t) + 1e-6 * phimax * (1 + t / period); });
}

// ---------------------------------------------------------------------------------------------
// tests/sim/models/library_elements.qd: the parts and offsets the examples leave out. Fixed at
// s0 = 1 with a Spring (k = 100, s0 = 0.5) to a mass 1 released at 1.6: s = 1.5 + 0.1 cos 10t; the
// same with a SpringDamper (c = 2): 1.5 + the Oscillator{1, 2, 100} from 0.1. A disk J = 0.02 on a
// TorsionSpring (k = 8) and a TorsionDamper (c = 0.04) from a RotFixed at phi0 = 0.2, driven by a
// Torque 0.1 cos 15t from rest at 0.2: phi = 0.2 + the Oscillator{0.02, 0.04, 8, 0.1, 15, π/2}; the
// mount's reaction (the torque on it) k u + c u̇, u = phi − 0.2. Bounds: oscillationBound (the
// reaction: k·A_u + c·A_u̇), the Torque's own flow −0.1 cos 15t too (an algebraic unknown: its
// output values come from IDA's interpolating polynomial, not from the equation a.tau = −tau).
TEST(VibrationLibrary, ElementsAndOffsetsTheExamplesLeaveOut) {
  auto r = runQdot("tests/sim/models/library_elements.qd", {"--rtol", num(kRtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 3, 0.002);
  const double period = 2 * M_PI / 10;
  expectOscillation(r, "mass.s", [](double t) { return 1.5 + 0.1 * std::cos(10 * t); }, 1.6, period);
  Oscillator damped{1, 2, 100};
  damped.x0 = 0.1;
  expectOscillation(r, "dampedMass.s", [&](double t) { return 1.5 + damped.x(t); }, 1.6, period);
  expectOscillation(r, "der(dampedMass.s)", [&](double t) { return damped.v(t); }, damped.vmax(), period);
  Oscillator disk{0.02, 0.04, 8, 0.1, 15, M_PI / 2};
  expectOscillation(r, "disk.phi", [&](double t) { return 0.2 + disk.x(t); }, 0.2 + disk.xmax(), disk.period());
  expectOscillation(r, "der(disk.phi)", [&](double t) { return disk.v(t); }, disk.vmax(), disk.period());
  expectOscillation(
      r, "mount.a.tau", [&](double t) { return 8 * disk.x(t) + 0.04 * disk.v(t); },
      8 * disk.xmax() + 0.04 * disk.vmax(), disk.period());
  expectOscillation(r, "drive.a.tau", [](double t) { return -0.1 * std::cos(15 * t); }, 0.1, 2 * M_PI / 15);
}

// ---------------------------------------------------------------------------------------------
// Spec §7's energy rule: a system written flat (one Lagrangian, one dissipation function, the
// forces) and built from connected Vibration parts gives the same trajectory. Each run is within the
// tolerance of the exact solution, so their difference is within twice oscillationBound.

// Compares the component run's column `part` with the flat run's `flatName` (and their der(), or
// the run's `partRate` where a variable of its own is the velocity) at every output time: |difference| ≤ 2 oscillationBound(A = amp, resp. vamp for the velocity).
void expectSameTrajectory(const RunResult& flat, const RunResult& parts, const std::string& flatName,
                          const std::string& part, double amp, double vamp, double period,
                          const std::string& partRate = "") {
  ASSERT_EQ(flat.rows, parts.rows);
  auto flatAt = [&flat](const std::string& name) {  // the flat run's value at an output time (same grid)
    return [&flat, name](double time) {
      const auto& t = flat.time();
      auto row = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), time - 1e-12) - t.begin());
      return flat.col(name).at(row);
    };
  };
  compareColumn(parts, part, flatAt(flatName), [&](double t) { return 2 * oscillationBound(kRtol, amp, period, t); });
  compareColumn(parts, partRate.empty() ? "der(" + part + ")" : partRate, flatAt("der(" + flatName + ")"),
                [&](double t) { return 2 * oscillationBound(kRtol, vamp, period, t); });
}

// tests/sim/models/three_mass_flat.qd against three_mass_components.qd (Fixed, SpringDamper, Spring,
// Damper ∥ CubicSpring, Mass, Force with F = 2 sin 5t). A = 0.15 m above the largest displacement,
// 0.114 m; velocity A·30 s⁻¹; P = 2π/30 s, shorter than the fastest mode's 2π/25.3 s (`qdot modes`
// of the flat model; the cubic spring adds < 2 %). A 1 % change of one damper fails this by 20×.
TEST(VibrationLibrary, FlatAndComponentModelsAgree) {
  std::vector<std::string> args = {"--rtol", num(kRtol)};
  auto flat = runQdot("tests/sim/models/three_mass_flat.qd", args);
  auto parts = runQdot("tests/sim/models/three_mass_components.qd", args);
  ASSERT_EQ(flat.exitCode, 0) << flat.log;
  ASSERT_EQ(parts.exitCode, 0) << parts.log;
  for (int i = 1; i <= 3; ++i)
    expectSameTrajectory(flat, parts, "x" + std::to_string(i), "m" + std::to_string(i) + ".s", 0.15, 0.15 * 30,
                         2 * M_PI / 30);
}

// examples/vibration/spring_chain.qd (flat, n = 10) against tests/sim/models/chain_components.qd
// (arrays `SpringDamper links[n]`, `Mass ms[n]` joined by `connect` in `for` loops). Bounds from the
// start energy V0 = n · ½ k (0.01 m)² = 0.5 J: every elongation e_i has Σ e_i² ≤ 2 V0/k, so
// |x_i| ≤ Σ|e_i| ≤ √(n · 2V0/k) = 0.1 m, and |ẋ_i| ≤ √(2 V0/m) = 1 m/s; P = 2π/64 s, the fastest
// mode being 2√(k/m) sin((2n − 1)π/(2(2n + 1))) = 63.1 rad/s.
TEST(VibrationLibrary, ChainOfComponentArraysEqualsTheFlatChain) {
  std::vector<std::string> args = {"--rtol", num(kRtol)};
  auto flat = runQdot("examples/vibration/spring_chain.qd", args);
  auto parts = runQdot("tests/sim/models/chain_components.qd", args);
  ASSERT_EQ(flat.exitCode, 0) << flat.log;
  ASSERT_EQ(parts.exitCode, 0) << parts.log;
  for (int i = 1; i <= 10; ++i) {
    const std::string index = std::to_string(i);
    expectSameTrajectory(flat, parts, "x[" + index + "]", "ms[" + index + "].s", 0.1, 1, 2 * M_PI / 64);
  }
}

// The same two chains with 40 masses: the component chain is expanded to scalars, and its rows
// that repeat from mass to mass are rerolled into loops (dae/Reroll.h; --stats says so). Reference:
// the flat chain (its own loops, derived from its energies), mass by mass, and each link's law
// b.f = k (s_i − s_{i−1}) + c (v_i − v_{i−1}) on the forces computed with the results (by loops too).
TEST(VibrationLibrary, ARerolledChainOfComponentArraysEqualsTheFlatChain) {
  std::vector<std::string> args = {"--rtol", num(kRtol), "-p", "n=40", "--stop", "0.5"};
  auto flat = runQdot("examples/vibration/spring_chain.qd", args);
  args.push_back("--stats");
  auto parts = runQdot("tests/sim/models/chain_components.qd", args);
  ASSERT_EQ(flat.exitCode, 0) << flat.log;
  ASSERT_EQ(parts.exitCode, 0) << parts.log;
  EXPECT_NE(parts.log.find("rows repeat along arrays of unknowns: rerolled into 2 loops"), std::string::npos) << parts.log;
  EXPECT_NE(parts.log.find("outputs repeat along arrays of unknowns: computed by 4 loops"), std::string::npos) << parts.log;
  for (int i : {1, 2, 20, 39, 40}) {
    const std::string index = std::to_string(i);
    expectSameTrajectory(flat, parts, "x[" + index + "]", "ms[" + index + "].s", 0.4, 0.4 * 64, 2 * M_PI / 64);
  }
  const double k = 1000, c = 0.5;
  for (int i : {1, 2, 21, 40}) {
    const std::string at = "[" + std::to_string(i) + "]", before = "[" + std::to_string(i - 1) + "]";
    const auto &s = parts.col("ms" + at + ".s"), &v = parts.col("der(ms" + at + ".s)"), &f = parts.col("links" + at + ".b.f");
    for (std::size_t row = 0; row < parts.rows; ++row) {
      double s0 = i == 1 ? 0.0 : parts.col("ms" + before + ".s")[row], v0 = i == 1 ? 0.0 : parts.col("der(ms" + before + ".s)")[row];
      double law = k * (s[row] - s0) + c * (v[row] - v0);
      ASSERT_NEAR(f[row], law, 1e-12 * (1 + std::fabs(law))) << "links" << at << " at t = " << parts.time()[row];
    }
  }
}

// The chain of parts run with some results asked for, none of them a connector's flow: the parts'
// energies are summed over their connections (flat::sumConnectedEnergies: the flows leave the
// model) and the terms that repeat along the arrays become sums again (flat::rerollTerms), so the
// run is compiled as loops from its energies, as the flat chain is (--stats says so). Reference:
// the flat chain, mass by mass, with the bounds of the test above; a potential asked for (ms[3].a.s,
// made ms[3].s by the part's equation) is still a column.
TEST(VibrationLibrary, AChainOfComponentArraysAskedForSomeResultsIsCompiledAsLoops) {
  std::vector<std::string> args = {"--rtol", num(kRtol), "-p", "n=40", "--stop", "0.5"};
  auto flat = runQdot("examples/vibration/spring_chain.qd", args);
  std::string outputs = "ms[3].a.s,ms[3].s";
  for (int i : {1, 2, 20, 39, 40}) outputs += ",ms[" + std::to_string(i) + "].s,der(ms[" + std::to_string(i) + "].s)";
  args.insert(args.end(), {"--outputs", outputs, "--stats"});
  auto parts = runQdot("tests/sim/models/chain_components.qd", args);
  ASSERT_EQ(flat.exitCode, 0) << flat.log;
  ASSERT_EQ(parts.exitCode, 0) << parts.log;
  EXPECT_NE(parts.log.find("loops: the model's repeated structure is compiled as loops"), std::string::npos) << parts.log;
  EXPECT_NE(parts.log.find("their energies are summed over the connections (the connectors' flows are not computed"),
            std::string::npos) << parts.log;
  for (int i : {1, 2, 20, 39, 40}) {
    const std::string index = std::to_string(i);
    expectSameTrajectory(flat, parts, "x[" + index + "]", "ms[" + index + "].s", 0.4, 0.4 * 64, 2 * M_PI / 64);
  }
  EXPECT_EQ(parts.col("ms[3].a.s"), parts.col("ms[3].s"));
}

// The chain with each spring and damper a part of its own, in parallel (three flanges at every
// node: each connection a flow balance, whose last flow the sum takes as the others' combination):
// compiled as loops too. Reference: the flat chain, as above.
TEST(VibrationLibrary, AChainOfParallelPartsIsCompiledAsLoops) {
  std::vector<std::string> args = {"--rtol", num(kRtol), "-p", "n=40", "--stop", "0.5"};
  auto flat = runQdot("examples/vibration/spring_chain.qd", args);
  std::string outputs;
  for (int i : {1, 21, 40}) outputs += (outputs.empty() ? "" : ",") + ("ms[" + std::to_string(i) + "].s,der(ms[" + std::to_string(i) + "].s)");
  args.insert(args.end(), {"--outputs", outputs, "--stats"});
  auto parts = runQdot("tests/sim/models/parallel_chain_components.qd", args);
  ASSERT_EQ(flat.exitCode, 0) << flat.log;
  ASSERT_EQ(parts.exitCode, 0) << parts.log;
  EXPECT_NE(parts.log.find("loops: the model's repeated structure is compiled as loops"), std::string::npos) << parts.log;
  for (int i : {1, 21, 40}) {
    const std::string index = std::to_string(i);
    expectSameTrajectory(flat, parts, "x[" + index + "]", "ms[" + index + "].s", 0.4, 0.4 * 64, 2 * M_PI / 64);
  }
}

// A chain of graded parts (masses, stiffnesses and dampings differ from element to element; masses
// declared first, connections written mass-first): the run that asks for its masses only (energies
// summed, templates reading each part's parameters in a loop) against the run that also asks for a
// link force, which keeps the parts' rows and flows (expanded, then rerolled) — --stats says why.
// Both are within 2 oscillationBound of the exact solution: V0 ≤ n ½ k_max (0.01 m)² = 2.4 J for
// n = 30, |x_i| ≤ √(n 2V0/k_min) = 0.38 m, |ẋ_i| ≤ √(2V0/m_min) = 3.1 m/s, the fastest mode below
// 2√(k_max/m_min) = 113 rad/s. The link force obeys its law with the masses' results.
TEST(VibrationLibrary, AGradedChainOfPartsGivesOneMotionWithAndWithoutItsFlows) {
  std::vector<std::string> args = {"--rtol", num(kRtol), "-p", "n=30", "--stop", "0.5", "--stats", "--outputs"};
  std::string outputs;
  for (int i : {1, 2, 17, 30}) outputs += (outputs.empty() ? "" : ",") + ("ms[" + std::to_string(i) + "].s,der(ms[" + std::to_string(i) + "].s)");
  auto some = args, withFlow = args;
  some.push_back(outputs);
  withFlow.push_back(outputs + ",links[2].b.f");
  auto summed = runQdot("tests/sim/models/graded_chain_components.qd", some);
  auto expanded = runQdot("tests/sim/models/graded_chain_components.qd", withFlow);
  ASSERT_EQ(summed.exitCode, 0) << summed.log;
  ASSERT_EQ(expanded.exitCode, 0) << expanded.log;
  EXPECT_NE(summed.log.find("loops: the model's repeated structure is compiled as loops"), std::string::npos) << summed.log;
  EXPECT_NE(expanded.log.find("the flow 'links[2].b.f' is among the results asked for"), std::string::npos) << expanded.log;
  for (int i : {1, 2, 17, 30}) {
    const std::string name = "ms[" + std::to_string(i) + "].s";
    expectSameTrajectory(expanded, summed, name, name, 0.38, 3.1, 2 * M_PI / 113);
  }
  const double k = 1000 + 20 * 2, c = 0.5 + 0.01 * 2;
  const auto &s1 = expanded.col("ms[1].s"), &s2 = expanded.col("ms[2].s"), &f = expanded.col("links[2].b.f");
  const auto &v1 = expanded.col("der(ms[1].s)"), &v2 = expanded.col("der(ms[2].s)");
  for (std::size_t row = 0; row < expanded.rows; ++row) {
    double law = k * (s2[row] - s1[row]) + c * (v2[row] - v1[row]);
    ASSERT_NEAR(f[row], law, 1e-12 * (1 + std::fabs(law))) << "at t = " << expanded.time()[row];
  }
}

// The same chain's link forces: `qdot run` solves them out of the system (dae/ExplicitAlgebraics.h)
// and computes them with the results, so the run integrates the 2n states alone (every unknown
// differential: y'(t0) by one division, no IDACalcIC). Reference: each link's law, b.f = k (s_i −
// s_{i−1}) + c (v_i − v_{i−1}) with the wall at s_0 = 0 (k = 1000, c = 0.5), at every written row, to
// rounding; the two flanges of a link carry opposite forces.
TEST(VibrationLibrary, ChainOfComponentArraysComputesItsLinkForcesFromTheStates) {
  auto r = runQdot("tests/sim/models/chain_components.qd", {"--rtol", num(kRtol), "--stats"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  EXPECT_NE(r.log.find("made consistent directly"), std::string::npos) << r.log;
  const double k = 1000, c = 0.5;
  for (int i = 1; i <= 10; ++i) {
    const std::string at = "[" + std::to_string(i) + "]", before = "[" + std::to_string(i - 1) + "]";
    const auto &s = r.col("ms" + at + ".s"), &v = r.col("der(ms" + at + ".s)"), &f = r.col("links" + at + ".b.f");
    const auto &fa = r.col("links" + at + ".a.f");
    for (std::size_t row = 0; row < r.rows; ++row) {
      double s0 = i == 1 ? 0.0 : r.col("ms" + before + ".s")[row], v0 = i == 1 ? 0.0 : r.col("der(ms" + before + ".s)")[row];
      double law = k * (s[row] - s0) + c * (v[row] - v0);
      ASSERT_NEAR(f[row], law, 1e-12 * (1 + std::fabs(law))) << "links" << at << " at t = " << r.time()[row];
      ASSERT_NEAR(fa[row], -f[row], 1e-12 * (1 + std::fabs(law))) << "links" << at << " at t = " << r.time()[row];
    }
  }
}

// The chain's masses x[i] and velocities v[i] of a chain written as equations, against the chain
// derived from its energies (spring_chain.qd, n = 10): the same equations of motion reached by
// another path (no Euler–Lagrange derivation).
void expectTheLagrangianChainsMotion(const std::string& model) {
  std::vector<std::string> args = {"--rtol", num(kRtol)};
  auto energies = runQdot("examples/vibration/spring_chain.qd", args);
  auto equations = runQdot(model, args);
  ASSERT_EQ(energies.exitCode, 0) << energies.log;
  ASSERT_EQ(equations.exitCode, 0) << equations.log;
  for (int i = 1; i <= 10; ++i) {
    const std::string index = std::to_string(i);
    expectSameTrajectory(energies, equations, "x[" + index + "]", "x[" + index + "]", 0.1, 1, 2 * M_PI / 64,
                         "v[" + index + "]");
  }
}

// Newton's law per mass (examples/vibration/spring_chain_equations.qd, its interior `for`
// equations one loop each).
TEST(VibrationLibrary, ChainWrittenAsEquationsMovesAsTheLagrangianChain) {
  expectTheLagrangianChainsMotion("examples/vibration/spring_chain_equations.qd");
}

// The link forces as algebraic unknowns (tests/sim/models/chain_forces.qd, every `for` equation one
// loop: an index-1 DAE whose algebraic rows each define their own unknown).
TEST(VibrationLibrary, ChainWithLinkForcesMovesAsTheLagrangianChain) {
  expectTheLagrangianChainsMotion("tests/sim/models/chain_forces.qd");
}

// Expanded to scalars (--no-loops), the equation chain's rows come in
// another order than its unknowns, so the Jacobian's diagonal has structural zeros and KLU must not
// start with its block triangular form (whose maximum transversal then costs O(n · nnz): 92 s at
// n = 10⁵). It says so, and it and the looped run move as the Lagrangian chain (n = 300, KLU).
TEST(VibrationLibrary, AnExpandedEquationChainIsFactoredWithoutBlockTriangularForm) {
  std::vector<std::string> args = {"--rtol", num(kRtol), "-p", "n=300", "--stop", "0.2", "--stats"};
  auto looped = runQdot("examples/vibration/spring_chain_equations.qd", args);
  args.push_back("--no-loops");
  auto scalar = runQdot("examples/vibration/spring_chain_equations.qd", args);
  auto energies = runQdot("examples/vibration/spring_chain.qd", args);
  for (const auto* r : {&looped, &scalar, &energies}) ASSERT_EQ(r->exitCode, 0) << r->log;
  const std::string without = "without block triangular form";
  EXPECT_NE(scalar.log.find(without), std::string::npos) << scalar.log;
  EXPECT_EQ(looped.log.find(without), std::string::npos) << looped.log;
  EXPECT_EQ(energies.log.find(without), std::string::npos) << energies.log;
  for (int i : {1, 150, 300}) {
    const std::string x = "x[" + std::to_string(i) + "]", v = "v[" + std::to_string(i) + "]";
    expectSameTrajectory(energies, looped, x, x, 0.1, 1, 2 * M_PI / 64, v);
    expectSameTrajectory(energies, scalar, x, x, 0.1, 1, 2 * M_PI / 64, v);
  }
}

// Reference: the Jacobi integral of a connected undamped system is its energy T + V (the flows of
// each node cancel in the power balance). two_dof.qd: m1 = 1, m2 = 2, k1 = 100, k2 = 50, k3 = 100,
// released from rest at s1 = 0.05: E = ½ k1 s1² + ½ k2 s1² = 0.1875 J, conserved; at rtol 1e-9 its
// drift over 3 s stays below 1e-6 of it. A forced system (absorber.qd) has no such integral.
TEST(VibrationLibrary, ConnectedUndampedSystemConservesItsEnergy) {
  auto r = runQdot("examples/vibration/two_dof.qd", {"--rtol", "1e-9", "--invariants"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  const auto& e = r.col("jacobi");
  ASSERT_FALSE(e.empty());
  EXPECT_NEAR(e.front(), 0.1875, 1e-12);
  for (double v : e) EXPECT_NEAR(v, 0.1875, 0.1875e-6);
  auto forced = runQdot("examples/vibration/absorber.qd", {"--stop", "0.01", "--invariants"});
  ASSERT_EQ(forced.exitCode, 0) << forced.log;
  for (const auto& name : forced.header) EXPECT_NE(name, "jacobi");
}

}  // namespace
}  // namespace qdot::simtest
