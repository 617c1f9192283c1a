// Vibration models of examples/vibration/ and the double pendulum simulated by `qdot run` and
// compared with closed-form solutions (Dynamics II, ch. 7) and energy conservation at every output time.
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// ---------------------------------------------------------------------------------------------
// Damped free vibration, §7-2 (m = 1, k = 100, c = 2, x0 = 0.1). Reference: m ẍ + c ẋ + k x = 0,
//   x = x0 e^(−ζω0 t) (cos ωd t + ζ/√(1−ζ²) sin ωd t),  ω0 = √(k/m), ζ = c/(2√(km)), ωd = ω0 √(1−ζ²),
// and its derivative ẋ = −x0 (ω0/√(1−ζ²)) e^(−ζω0 t) sin ωd t.
// Bound: oscillationBound with A = x0 (resp. x0 ω0/√(1−ζ²) for ẋ), P = 2π/ωd (the decay only helps).
TEST(DampedOscillator, ClosedForm) {
  const double m = 1, k = 100, c = 2, x0 = 0.1;
  const double w0 = std::sqrt(k / m), z = c / (2 * std::sqrt(k * m)), wd = w0 * std::sqrt(1 - z * z);
  const double period = 2 * M_PI / wd, vmax = x0 * w0 / std::sqrt(1 - z * z);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/vibration/damped_oscillator.qd", {"--rtol", num(rtol)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 5, 0.005);
    auto d = compareColumn(
        r, "x",
        [&](double t) {
          return x0 * std::exp(-z * w0 * t) * (std::cos(wd * t) + z / std::sqrt(1 - z * z) * std::sin(wd * t));
        },
        [&](double t) { return oscillationBound(rtol, x0, period, t); });
    compareColumn(
        r, "der(x)", [&](double t) { return -vmax * std::exp(-z * w0 * t) * std::sin(wd * t); },
        [&](double t) { return oscillationBound(rtol, vmax, period, t); });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
  }
}

// ---------------------------------------------------------------------------------------------
// Forced vibration from rest (examples/vibration/forced_oscillator.qd: m = 1, k = 100, c = 2,
// F0 = 10, ω = 7). Reference, derived for m ẍ + c ẋ + k x = F0 cos ωt, at rest at the start time t0:
//   particular solution x_p = X cos(ωt − φ): substituting, (k − mω²) X cos(ωt − φ) − cω X sin(ωt − φ)
//     = F0 cos ωt  ⇒  X = F0/√((k − mω²)² + (cω)²),  tan φ = cω/(k − mω²)  (φ = atan2(cω, k − mω²));
//   homogeneous part x_h = e^(−ζω0 s)(A cos ωd s + B sin ωd s), s = t − t0 (ω0, ζ, ωd as above),
//   fitted to x(t0) = 0, ẋ(t0) = 0:
//     x_p(t0) + A = 0                  ⇒  A = −x_p(t0)      (t0 = 0: A = −X cos φ),
//     ẋ_p(t0) − ζω0 A + ωd B = 0       ⇒  B = (ζω0 A − ẋ_p(t0))/ωd  (t0 = 0: ẋ_p(0) = X ω sin φ).
// Bound: oscillationBound with A = X + √(A² + B²) ≥ |x| (resp. ω X + ω0 √(A² + B²) for ẋ) and the
// shorter period 2π/max(ω, ωd).
void checkForced(double t0, double stop) {
  const double m = 1, k = 100, c = 2, f0 = 10, w = 7;
  const double w0 = std::sqrt(k / m), z = c / (2 * std::sqrt(k * m)), wd = w0 * std::sqrt(1 - z * z);
  const double amp = f0 / std::hypot(k - m * w * w, c * w), phi = std::atan2(c * w, k - m * w * w);
  auto xp = [&](double t) { return amp * std::cos(w * t - phi); };
  auto vp = [&](double t) { return -amp * w * std::sin(w * t - phi); };
  const double ca = -xp(t0), cb = (z * w0 * ca - vp(t0)) / wd;
  auto x = [&](double t) {
    double s = t - t0;
    return xp(t) + std::exp(-z * w0 * s) * (ca * std::cos(wd * s) + cb * std::sin(wd * s));
  };
  auto v = [&](double t) {
    double s = t - t0, e = std::exp(-z * w0 * s);
    return vp(t) - z * w0 * e * (ca * std::cos(wd * s) + cb * std::sin(wd * s)) +
           e * wd * (-ca * std::sin(wd * s) + cb * std::cos(wd * s));
  };
  ASSERT_NEAR(x(t0), 0, 1e-15);
  ASSERT_NEAR(v(t0), 0, 1e-14);
  const double xmax = amp + std::hypot(ca, cb), vmax = w * amp + w0 * std::hypot(ca, cb);
  const double period = 2 * M_PI / std::max(w, wd);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/vibration/forced_oscillator.qd",
                     {"--rtol", num(rtol), "--start", num(t0), "--stop", num(stop), "--interval", "0.01"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, t0, stop, 0.01);
    auto d = compareColumn(r, "x", x, [&](double t) { return oscillationBound(rtol, xmax, period, t - t0); });
    compareColumn(r, "der(x)", v, [&](double t) { return oscillationBound(rtol, vmax, period, t - t0); });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
  }
  // Control: the steady amplitude X differs from the static deflection F0/k (the forcing really
  // depends on time), and by the stop time (e^(−ζω0·10) = e^(−10)) the transient has died out.
  EXPECT_GT(std::fabs(amp - f0 / k), 0.05);
}

TEST(ForcedOscillator, TransientAndSteadyStateFromRest) { checkForced(0, 10); }

// The same from rest at t0 = 1 s (--start 1): the force F0 cos ωt uses absolute time, so the
// transient differs from a shifted copy of the first run.
TEST(ForcedOscillator, FromRestAtALaterStartTime) { checkForced(1, 11); }

// ---------------------------------------------------------------------------------------------
// Two masses, three springs, §7-4 (m = 1, k = 100). Reference: from rest at (a1, a2) the motion is
//   x1 = (a1+a2)/2 cos ω1 t + (a1−a2)/2 cos ω2 t,   x2 = (a1+a2)/2 cos ω1 t − (a1−a2)/2 cos ω2 t,
// ω1 = √(k/m) (in phase), ω2 = √(3k/m) (out of phase); a start in a mode stays in it, a pure harmonic.
// Bound: oscillationBound with A = max(|a1|, |a2|) and the shorter period 2π/ω2.
void checkTwoMass(const std::string& model, double a1, double a2, const std::vector<std::string>& parameters) {
  const double m = 1, k = 100, w1 = std::sqrt(k / m), w2 = std::sqrt(3 * k / m);
  const double s = (a1 + a2) / 2, d = (a1 - a2) / 2, amp = std::max(std::fabs(a1), std::fabs(a2));
  const double period = 2 * M_PI / w2;
  for (double rtol : {1e-6, 1e-9}) {
    std::vector<std::string> args = {"--rtol", num(rtol)};
    args.insert(args.end(), parameters.begin(), parameters.end());
    auto r = runQdot(model, args);
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 2, 0.002);
    auto bound = [&](double t) { return oscillationBound(rtol, amp, period, t); };
    auto vbound = [&](double t) { return oscillationBound(rtol, amp * w2, period, t); };
    compareColumn(
        r, "x1", [&](double t) { return s * std::cos(w1 * t) + d * std::cos(w2 * t); }, bound);
    compareColumn(
        r, "x2", [&](double t) { return s * std::cos(w1 * t) - d * std::cos(w2 * t); }, bound);
    compareColumn(
        r, "der(x1)", [&](double t) { return -s * w1 * std::sin(w1 * t) - d * w2 * std::sin(w2 * t); }, vbound);
    compareColumn(
        r, "der(x2)", [&](double t) { return -s * w1 * std::sin(w1 * t) + d * w2 * std::sin(w2 * t); }, vbound);
  }
}

TEST(TwoMass, OutOfPhaseModeIsHarmonicAtSqrt3) {  // two_mass.qd starts at x1 = a, x2 = −a
  checkTwoMass("examples/vibration/two_mass.qd", 0.05, -0.05, {});
}

TEST(TwoMass, InPhaseModeIsHarmonicAtSqrt1) {  // two_mass_modes.qd defaults to a1 = a2 = 0.05
  checkTwoMass("examples/vibration/two_mass_modes.qd", 0.05, 0.05, {});
}

TEST(TwoMass, OutOfPhaseModeViaParameters) {
  checkTwoMass("examples/vibration/two_mass_modes.qd", 0.04, -0.04, {"-p", "a1=0.04", "-p", "a2=-0.04"});
}

TEST(TwoMass, GeneralStartIsTheSumOfTheModes) {
  checkTwoMass("examples/vibration/two_mass_modes.qd", 0.03, -0.01, {"-p", "a1=0.03", "-p", "a2=-0.01"});
}

// The same with each linear solver named explicitly (auto picks dense for n = 4): same reference, same bound.
TEST(TwoMass, GeneralStartWithKluAndDense) {
  for (const char* solver : {"klu", "dense"})
    checkTwoMass("examples/vibration/two_mass_modes.qd", 0.03, -0.01,
                 {"-p", "a1=0.03", "-p", "a2=-0.01", "--linear-solver", solver});
}

// ---------------------------------------------------------------------------------------------
// Very stiff oscillator (examples/vibration/stiff_oscillator.qd: m = 1e-9, k = 1e3, ω0 = 1e6 rad/s,
// x0 = 1e-6) over 1000 periods (6.283 ms, 6285 output times, about six per period).
// Reference: x = x0 cos ω0 t, ẋ = −x0 ω0 sin ω0 t, and the energy ½ k x0² = 5e-10 J (column `jacobi`).
// Bound: oscillationBound with A = x0 (resp. x0 ω0) and P = 2π/ω0 — over 1000 periods that allows
// 1e5·rtol·A at the end; the energy, E ∝ A², gets twice the relative bound (ΔE/E ≈ 2 ΔA/A).
// Run at rtol 1e-7 and 1e-9 (either side of the annotation's 1e-8); the error must shrink ≥ 10×.
TEST(StiffOscillator, ThousandPeriodsAtOneMegaradianPerSecond) {
  const double m = 1e-9, k = 1e3, x0 = 1e-6, w0 = std::sqrt(k / m), period = 2 * M_PI / w0;
  const double energy = 0.5 * k * x0 * x0;
  ASSERT_DOUBLE_EQ(w0, 1e6);
  double previous = INFINITY;
  for (double rtol : {1e-7, 1e-9}) {
    auto r = runQdot("examples/vibration/stiff_oscillator.qd", {"--rtol", num(rtol), "--invariants"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 6.283185307179586e-3, 1e-6);  // the annotation: 1000 periods
    auto d = compareColumn(
        r, "x", [&](double t) { return x0 * std::cos(w0 * t); },
        [&](double t) { return oscillationBound(rtol, x0, period, t); });
    compareColumn(
        r, "der(x)", [&](double t) { return -x0 * w0 * std::sin(w0 * t); },
        [&](double t) { return oscillationBound(rtol, x0 * w0, period, t); });
    compareColumn(
        r, "jacobi", [&](double) { return energy; },
        [&](double t) { return 2 * oscillationBound(rtol, energy, period, t); });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
  }
}

// ---------------------------------------------------------------------------------------------
// Double pendulum (m = l = 1, g = 9.81, θ1 = θ2 = 0.5 at rest, 10 s). Reference: energy conservation,
//   E = T + V,  T = ½ m l² (2 θ̇1² + θ̇2² + 2 θ̇1 θ̇2 cos(θ1 − θ2)),  V = −m g l (2 cos θ1 + cos θ2).
// Checked: the `jacobi` column is this T + V at every row (to rounding, 1e-12·|E|); its drift from
// E(0) is below 10·rtol·|E(0)| at rtol 1e-6 and at rtol 1e-9 (IDA holds each step's relative error
// to rtol; the motion is chaotic but the energy error of BDF accumulates only slowly — measured
// 0.7–3 rtol·|E| over the 10 s); and the drift at 1e-9 is at least 10× smaller than at 1e-6.
TEST(DoublePendulum, EnergyConservedAndTightensWithTolerance) {
  const double m = 1, l = 1, g = 9.81;
  auto energy = [&](double t1, double t2, double w1, double w2) {
    double T = 0.5 * m * l * l * (2 * w1 * w1 + w2 * w2 + 2 * w1 * w2 * std::cos(t1 - t2));
    double V = -m * g * l * (2 * std::cos(t1) + std::cos(t2));
    return T + V;
  };
  const double e0 = energy(0.5, 0.5, 0, 0);
  double drifts[2];
  int i = 0;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/pendulum/double_pendulum.qd", {"--rtol", num(rtol), "--invariants"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 10, 0.01);
    const auto &t1 = r.col("th[1]"), &t2 = r.col("th[2]"), &w1 = r.col("der(th[1])"), &w2 = r.col("der(th[2])");
    const auto& jc = r.col("jacobi");
    ASSERT_EQ(jc.size(), t1.size());
    for (std::size_t k = 0; k < jc.size(); ++k)
      ASSERT_NEAR(jc[k], energy(t1[k], t2[k], w1[k], w2[k]), 1e-12 * std::fabs(e0)) << "row " << k;
    auto d = compareColumn(
        r, "jacobi", [&](double) { return e0; }, [&](double) { return 10 * rtol * std::fabs(e0); });
    drifts[i++] = d.maxError;
    std::cout << "[measured] drift/(rtol |E|) at rtol " << rtol << ": " << d.maxError / (rtol * std::fabs(e0)) << "\n";
  }
  EXPECT_LT(drifts[1], drifts[0] / 10) << "drift at rtol 1e-6: " << drifts[0] << ", at 1e-9: " << drifts[1];
  std::cout << "[measured] drift ratio 1e-6/1e-9: " << drifts[0] / drifts[1] << "\n";
}

// A damped chain of 40 masses whose energy E and damper power P are outputs written as sums
// (tests/sim/models/chain_energy_outputs.qd), computed by loops (docs/loops.md): E(0) is the
// springs' ½ k (0.01 m)² each, and E(t) − E(0) = ∫₀ᵗ P dt (the power balance of a damped system,
// dE/dt = −2D), the integral by the trapezoid rule on the 1 ms output grid (its error: measured
// 9.5e-8 J against 1.1e-2 J dissipated). The outputs expanded to scalars (--no-loops) are the same
// to rounding.
TEST(ChainEnergyOutputs, EnergyFallsByTheDissipatedWorkAndEqualsTheScalarOutputs) {
  const std::string model = "tests/sim/models/chain_energy_outputs.qd";
  const std::vector<std::string> args{"--stop", "0.5", "--interval", "0.001", "--rtol", "1e-8", "--outputs", "E,P"};
  auto r = runQdot(model, args);
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 0.5, 0.001);
  const auto &t = r.time(), &E = r.col("E"), &P = r.col("P");
  ASSERT_EQ(E.size(), t.size());
  EXPECT_NEAR(E[0], 40 * 0.5 * 1000 * 0.01 * 0.01, 1e-12);
  double dissipated = 0, worst = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    dissipated += 0.5 * (P[i] + P[i - 1]) * (t[i] - t[i - 1]);
    worst = std::max(worst, std::fabs(E[i] - E[0] - dissipated));
  }
  EXPECT_LT(dissipated, -1e-2);  // the dampers do work: the balance is not 0 = 0
  EXPECT_LT(worst, 1e-6) << "dissipated " << dissipated;
  std::cout << "[measured] energy balance error " << worst << " J, dissipated " << -dissipated << " J\n";
  std::vector<std::string> scalarArgs = args;
  scalarArgs.push_back("--no-loops");
  auto s = runQdot(model, scalarArgs);
  ASSERT_EQ(s.exitCode, 0) << s.log;
  for (const char* name : {"E", "P"}) {
    const auto &a = r.col(name), &b = s.col(name);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-12) << name << " row " << i;
  }
}

}  // namespace
}  // namespace qdot::simtest
