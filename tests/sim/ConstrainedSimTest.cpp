// The constrained-mechanics examples (examples/constrained/, examples/benchmarks/car_axis.qd):
// models with `constraint lhs = rhs;` in their mechanics section, simulated by `qdot run` and
// compared at every output time with references computed here, independently of qdot: closed forms,
// the exact pendulum period (K by the arithmetic–geometric mean), a hand-reduced one-coordinate model
// integrated by classical RK4, and the published solution of the Test Set for IVP Solvers.
// Conventions checked: the k-th constraint's multiplier is the column lambda[k]; its residual
// g_k = lhs − rhs and dg_k/dt are the invariant columns constraint[k] and der(constraint[k]) (with
// --invariants), which must stay near 0.
// The ConstrainedReference tests check the references themselves (they need no qdot run).
#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdlib>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

// ---------------------------------------------------------------------------------------------
// Numerical helpers that have nothing to do with qdot.

// The complete elliptic integral of the first kind K(k) = ∫₀^{π/2} dφ/√(1 − k² sin²φ) by the
// arithmetic–geometric mean: K(k) = π / (2 AGM(1, √(1 − k²))). The AGM converges quadratically.
double ellipticK(double k) {
  double a = 1, b = std::sqrt(1 - k * k);
  for (int i = 0; i < 40 && std::fabs(a - b) > 1e-16 * a; ++i) {
    const double mean = 0.5 * (a + b);
    b = std::sqrt(a * b);
    a = mean;
  }
  return M_PI / (2 * a);
}

// One step of the classical fourth-order Runge–Kutta method for y' = f(t, y).
template <std::size_t N, class Rhs>
std::array<double, N> rk4Step(const Rhs& f, double t, const std::array<double, N>& y, double h) {
  auto axpy = [](const std::array<double, N>& base, double s, const std::array<double, N>& dir) {
    std::array<double, N> out;
    for (std::size_t i = 0; i < N; ++i) out[i] = base[i] + s * dir[i];
    return out;
  };
  const auto k1 = f(t, y);
  const auto k2 = f(t + h / 2, axpy(y, h / 2, k1));
  const auto k3 = f(t + h / 2, axpy(y, h / 2, k2));
  const auto k4 = f(t + h, axpy(y, h, k3));
  std::array<double, N> out;
  for (std::size_t i = 0; i < N; ++i) out[i] = y[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  return out;
}

// A forward-mode dual number v + d·ε (ε² = 0): evaluating f on Dual{x, 1} gives f(x) and f'(x)
// exactly, so the hand-written energies below are differentiated without finite differences.
struct Dual {
  double v = 0, d = 0;
  Dual(double value = 0, double derivative = 0) : v(value), d(derivative) {}
  friend Dual operator+(Dual a, Dual b) { return {a.v + b.v, a.d + b.d}; }
  friend Dual operator-(Dual a, Dual b) { return {a.v - b.v, a.d - b.d}; }
  friend Dual operator-(Dual a) { return {-a.v, -a.d}; }
  friend Dual operator*(Dual a, Dual b) { return {a.v * b.v, a.d * b.v + a.v * b.d}; }
  friend Dual operator/(Dual a, Dual b) { return {a.v / b.v, (a.d * b.v - a.v * b.d) / (b.v * b.v)}; }
};
Dual sin(Dual a) { return {std::sin(a.v), a.d * std::cos(a.v)}; }
Dual cos(Dual a) { return {std::cos(a.v), -a.d * std::sin(a.v)}; }
Dual sqrt(Dual a) { return {std::sqrt(a.v), a.d / (2 * std::sqrt(a.v))}; }

// The largest |value| of a column over all output rows (infinite if any is nan).
double maxAbs(const RunResult& r, const std::string& name) {
  double m = 0;
  for (double v : r.col(name)) m = std::max(m, std::isnan(v) ? INFINITY : std::fabs(v));
  return m;
}

// Every constraint residual column constraint[k] and its derivative der(constraint[k]) stay within
// 100·rtol times their scale (the size of g_k's terms, and of their rates) at every output row:
// index reduction keeps g = 0 and dg/dt = 0 as equations, solved to IDA's tolerance.
void expectConstraintsHeld(const RunResult& r, int count, double rtol, double scale, double rateScale) {
  for (int k = 1; k <= count; ++k) {
    const std::string g = "constraint[" + std::to_string(k) + "]";
    if (!r.has(g) || !r.has("der(" + g + ")")) {
      ADD_FAILURE() << "no column " << g << " or der(" << g << ") in the CSV (qdot run --invariants)";
      continue;
    }
    EXPECT_LE(maxAbs(r, g), 100 * rtol * scale) << g;
    EXPECT_LE(maxAbs(r, "der(" + g + ")"), 100 * rtol * rateScale) << "der(" << g << ")";
    std::cout << "[measured] " << g << ": max |g| " << maxAbs(r, g) << ", max |dg/dt| " << maxAbs(r, "der(" + g + ")")
              << "\n";
  }
}

// `qdot run MODEL args --invariants` (the constraint columns are invariants); the caller asserts
// the exit code.
RunResult runConstrained(const std::string& model, std::vector<std::string> args) {
  args.push_back("--invariants");
  return runQdot(model, args);
}

// ---------------------------------------------------------------------------------------------
// The models compile: `qdot equations FILE` derives the Euler–Lagrange rows with the multipliers
// lambda[1..n] and passes the balance check (equations = unknowns, else it exits with 1), and lists
// the n constraints (at least: index reduction may add their derivatives). This part works before
// index reduction exists.
TEST(ConstrainedModels, DeriveAndBalance) {
  const std::vector<std::pair<std::string, int>> models = {{"examples/constrained/cartesian_pendulum.qd", 1},
                                                           {"examples/constrained/slider_crank.qd", 2},
                                                           {"examples/constrained/ellipsograph_sliders.qd", 2},
                                                           {"examples/constrained/rolling_cylinder.qd", 1},
                                                           {"examples/benchmarks/car_axis.qd", 2}};
  for (const auto& [model, constraints] : models) {
    TempFile out(".txt");
    const std::string command =
        std::string("'") + QDOT_BINARY + "' equations '" + modelPath(model) + "' > '" + out.path() + "' 2>&1";
    const int status = std::system(command.c_str());
    const std::string text = readAll(out.path());
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "qdot equations " << model << "\n" << text;
    for (int k = 1; k <= constraints; ++k)
      EXPECT_NE(text.find("lambda[" + std::to_string(k) + "]"), std::string::npos) << model << ": lambda[" << k << "]";
    EXPECT_EQ(text.find("lambda[" + std::to_string(constraints + 1) + "]"), std::string::npos) << model;
    std::size_t listed = 0;
    for (std::size_t at = text.find("(constraint)"); at != std::string::npos; at = text.find("(constraint)", at + 1))
      ++listed;
    EXPECT_GE(listed, static_cast<std::size_t>(constraints))
        << model << ": the constraints listed (index reduction may list their derivatives too)";
  }
}

// ---------------------------------------------------------------------------------------------
// The references, checked on their own.

// K(0) = π/2; K(1/√2) = Γ(1/4)² / (4√π) (the lemniscatic case).
TEST(ConstrainedReference, EllipticKByAgm) {
  EXPECT_NEAR(ellipticK(0), M_PI / 2, 1e-15);
  const double lemniscatic = std::pow(std::tgamma(0.25), 2) / (4 * std::sqrt(M_PI));
  EXPECT_NEAR(ellipticK(1 / std::sqrt(2.0)), lemniscatic, 1e-14 * lemniscatic);
}

// x'' = −x from (1, 0) over one period 2π: RK4 returns to the start with a global error ≈ h⁴·2π/120,
// and halving h divides the error by 2⁴ (within 12 to 20: fourth order).
TEST(ConstrainedReference, Rk4IsFourthOrder) {
  auto oscillator = [](double, const std::array<double, 2>& y) { return std::array<double, 2>{y[1], -y[0]}; };
  auto errorAfterOnePeriod = [&](int steps) {
    std::array<double, 2> y{1, 0};
    const double h = 2 * M_PI / steps;
    for (int i = 0; i < steps; ++i) y = rk4Step(oscillator, i * h, y, h);
    return std::hypot(y[0] - 1, y[1]);
  };
  const double coarse = errorAfterOnePeriod(500), fine = errorAfterOnePeriod(1000);
  EXPECT_LT(fine, 1e-9);
  EXPECT_GT(coarse / fine, 12);
  EXPECT_LT(coarse / fine, 20);
}

// The pendulum θ'' = −(g/l) sin θ released from rest at θ0 = 1 reaches θ = 0 after a quarter of
// P = 4 √(l/g) K(sin(θ0/2)): RK4 with h = 1e-4 (error ≈ (ωh)⁴ ≈ 1e-15) finds the same time to 1e-10.
TEST(ConstrainedReference, PendulumPeriodFormulaAgreesWithRk4) {
  const double g = 9.81, l = 1, theta0 = 1, h = 1e-4;
  auto pendulum = [&](double, const std::array<double, 2>& y) {
    return std::array<double, 2>{y[1], -g / l * std::sin(y[0])};
  };
  std::array<double, 2> y{theta0, 0};
  double t = 0;
  while (rk4Step(pendulum, t, y, h)[0] > 0) y = rk4Step(pendulum, t, y, h), t += h;
  double lo = 0, hi = h;  // the step length that lands on θ = 0
  for (int k = 0; k < 60; ++k) (rk4Step(pendulum, t, y, 0.5 * (lo + hi))[0] > 0 ? lo : hi) = 0.5 * (lo + hi);
  const double period = 4 * std::sqrt(l / g) * ellipticK(std::sin(theta0 / 2));
  EXPECT_NEAR(4 * (t + 0.5 * (lo + hi)), period, 1e-10 * period);
}

// ---------------------------------------------------------------------------------------------
// cartesian_pendulum.qd: m = 1, l = 1, g = 9.81, released from rest at θ0 = 1 rad.
constexpr double kPendulumG = 9.81, kPendulumL = 1, kPendulumM = 1, kPendulumTheta0 = 1;

double pendulumPeriod() { return 4 * std::sqrt(kPendulumL / kPendulumG) * ellipticK(std::sin(kPendulumTheta0 / 2)); }

// At rtol 1e-8 over the annotation's 30 s (about 14 periods, output every 0.01 s): the mean period
// between the first and last upward zero crossings of x equals P within 1e-6 relative (a crossing
// time is off by about its error/slope ≈ 100·rtol·P); the constraint and its derivative stay within
// 100·rtol times their scales l² and 2 l·v_max (v_max = √(2 g l (1 − cos θ0)), at the bottom).
TEST(ConstrainedPendulum, PeriodFromZeroCrossings) {
  const double rtol = 1e-8, period = pendulumPeriod();
  auto r = runConstrained("examples/constrained/cartesian_pendulum.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 30, 0.01);
  auto crossings = upwardZeroCrossings(r, "x", "der(x)");
  ASSERT_GE(crossings.size(), 10u);
  const double measured = (crossings.back() - crossings.front()) / static_cast<double>(crossings.size() - 1);
  std::cout << "[measured] period " << num(measured) << " exact " << num(period) << "\n";
  EXPECT_NEAR(measured, period, 1e-6 * period);
  const double vmax = std::sqrt(2 * kPendulumG * kPendulumL * (1 - std::cos(kPendulumTheta0)));
  expectConstraintsHeld(r, 1, rtol, kPendulumL * kPendulumL, 2 * kPendulumL * vmax);
}

// 1000 periods at rtol 1e-8, output every 0.05 s (≈ 43 rows per period): the constraint and its
// derivative stay within 100·rtol·scale at every row (they are equations of the reduced system, so
// they do not drift); the energy E = T + V stays at its start value −m g l cos θ0 within
// oscillationBound(rtol, m g l, P, t) (100·rtol·m g l per period elapsed, 1e-3 m g l at the end:
// BDF's local errors add up, about linearly in time; the pendulum in its angle θ at the same rtol
// reaches 0.07 of this bound); every period is there (1000 upward zero crossings, the first at 3P/4
// within 1e-6 P) and their mean spacing equals P within 2e-5 relative: the energy drift changes the
// amplitude and with it the period, dP/P ≈ 0.15 ΔE/(m g l) at θ0 = 1 (the θ form drifts 4e-5 m g l
// and its mean period over these 1000 periods is 2.8e-6 short).
TEST(ConstrainedPendulum, ThousandPeriodsConstraintAndEnergyDrift) {
  const double rtol = 1e-8, period = pendulumPeriod(), stop = 1000 * period;
  auto r = runConstrained("examples/constrained/cartesian_pendulum.qd",
                          {"--rtol", num(rtol), "--stop", num(stop), "--interval", "0.05"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  ASSERT_GT(r.rows, 40000u);
  const double vmax = std::sqrt(2 * kPendulumG * kPendulumL * (1 - std::cos(kPendulumTheta0)));
  expectConstraintsHeld(r, 1, rtol, kPendulumL * kPendulumL, 2 * kPendulumL * vmax);
  const double mgl = kPendulumM * kPendulumG * kPendulumL, e0 = -mgl * std::cos(kPendulumTheta0);
  compareColumn(
      r, "E", [&](double) { return e0; }, [&](double t) { return oscillationBound(rtol, mgl, period, t); });
  auto crossings = upwardZeroCrossings(r, "x", "der(x)");
  ASSERT_EQ(crossings.size(), 1000u);
  EXPECT_NEAR(crossings.front(), 0.75 * period, 1e-6 * period);
  EXPECT_NEAR((crossings.back() - crossings.front()) / 999, period, 2e-5 * period);
}

// ---------------------------------------------------------------------------------------------
// slider_crank.qd reduced by hand to the crank angle phi. With λr = r/L, s = sin phi, c = cos phi:
//   sin psi = −λr s,  cos psi = √(1 − λr² s²),  xB = r c + L cos psi,  G = (r c + (L/2) cos psi, (r/2) s);
//   dpsi/dphi = −λr c / cos psi,  dxB/dphi = −r s − r λr s c / cos psi,
//   dxG/dphi = −r s − (r λr/2) s c / cos psi,  dyG/dphi = (r/2) c;
//   J(phi) = mc r²/3 + mr (dxG² + dyG²) + (mr L²/12) dpsi² + ms dxB²,   V(phi) = (mc + mr) g (r/2) s.
// Lagrange's equation for T = ½ J phi'²: J phi'' + ½ J'(phi) phi'² + V'(phi) = 0.
struct SliderCrank {
  double r = 0.1, L = 0.3, mc = 1, mr = 0.5, ms = 0.8, g = 9.81, omega0 = 30;

  template <class T>
  T inertia(T phi) const {
    using std::cos, std::sin, std::sqrt;
    const double lr = r / L;
    const T s = sin(phi), c = cos(phi), cosPsi = sqrt(1 - lr * lr * s * s);
    const T dpsi = -lr * c / cosPsi, dxB = -r * s - r * lr * s * c / cosPsi;
    const T dxG = -r * s - r * lr / 2 * s * c / cosPsi, dyG = r / 2 * c;
    return mc * r * r / 3 + mr * (dxG * dxG + dyG * dyG) + mr * L * L / 12 * dpsi * dpsi + ms * dxB * dxB;
  }
  template <class T>
  T potential(T phi) const {
    using std::sin;
    return (mc + mr) * g * (r / 2) * sin(phi);
  }
  double energy(const std::array<double, 2>& y) const { return 0.5 * inertia(y[0]) * y[1] * y[1] + potential(y[0]); }
  std::array<double, 2> rhs(double, const std::array<double, 2>& y) const {
    const Dual j = inertia(Dual(y[0], 1)), v = potential(Dual(y[0], 1));
    return {y[1], -(0.5 * j.d * y[1] * y[1] + v.d) / j.v};
  }
  double psi(double phi) const { return -std::asin(r / L * std::sin(phi)); }
  double xB(double phi) const { return r * std::cos(phi) + L * std::cos(psi(phi)); }

  // (phi, phi') at t = k·interval for k = 0 … n, by RK4 with `substeps` steps per interval.
  std::vector<std::array<double, 2>> trajectory(double interval, std::size_t n, int substeps) const {
    std::vector<std::array<double, 2>> out{{0, omega0}};
    const double h = interval / substeps;
    auto f = [this](double t, const std::array<double, 2>& y) { return rhs(t, y); };
    for (std::size_t k = 0; k < n; ++k) {
      auto y = out.back();
      for (int i = 0; i < substeps; ++i) y = rk4Step(f, (k * substeps + i) * h, y, h);
      out.push_back(y);
    }
    return out;
  }
};

// The hand reduction: J(0) = mc r²/3 + mr r²/4 + (mr L²/12)(r/L)² (at phi = 0 the rod's centre moves
// straight up at (r/2) phi' and the slider stands still); J' by dual numbers equals a central
// difference; the RK4 reference (h = 4e-5, (ω h)⁴ ≈ 2e-12) keeps T + V within 1e-9 relative and the
// crank completes at least 5 revolutions in 2 s.
TEST(ConstrainedReference, SliderCrankReducedModel) {
  const SliderCrank sc;
  const double j0 =
      sc.mc * sc.r * sc.r / 3 + sc.mr * sc.r * sc.r / 4 + sc.mr * sc.L * sc.L / 12 * std::pow(sc.r / sc.L, 2);
  EXPECT_NEAR(sc.inertia(0.0), j0, 1e-16);
  for (double phi : {0.3, 1.2, 2.5, 4.0}) {
    const double step = 1e-5, difference = (sc.inertia(phi + step) - sc.inertia(phi - step)) / (2 * step);
    EXPECT_NEAR(sc.inertia(Dual(phi, 1)).d, difference, 1e-8) << "phi = " << phi;
  }
  const auto path = sc.trajectory(0.002, 1000, 50);
  const double e0 = sc.energy(path.front());
  for (const auto& y : path) ASSERT_NEAR(sc.energy(y), e0, 1e-9 * e0);
  EXPECT_GT(path.back()[0], 5 * 2 * M_PI);
}

// The annotation's run (2 s, output every 0.002 s) at rtol 1e-8 against the RK4 reference at every
// output time; phi grows by about 6.4 revolutions (P, the mean revolution time, ≈ 0.31 s).
// Energy: E stays at its start value E0 within 2·oscillationBound(rtol, E0, P, t) (the local errors
// add up linearly, as the Jacobi integral's do in TextbookSimTest). Unlike an oscillation's, the
// phase of a rotation has no restoring force: the linearly growing energy error is a growing speed
// error, so the phase error grows quadratically, and the bound on phi is 100·rtol·2π·(1 + t/P)².
// phi' errs by the phase error times the largest |dω/dφ| = |phi''/phi'| along the reference (≈ 24)
// plus its own oscillationBound(rtol, omega0, P, t). psi and xB are functions of phi with slopes
// below 0.36 and 1.4 r, so their bounds are the phi bound and 2r times it. (The same mechanism written
// with phi alone, at this rtol, uses 0.22 of the phi bound, 0.17 of the phi' bound and 0.37 of E's.)
// The loop closures stay within 100·rtol·(r + L) (their largest terms) and their rates within
// 100·rtol·2 r omega0 (r phi', L psi' and xB' stay below 1.1 r omega0).
TEST(SliderCrank, MatchesHandReducedRk4) {
  const SliderCrank sc;
  const double rtol = 1e-8, interval = 0.002;
  auto r = runConstrained("examples/constrained/slider_crank.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 2, interval);
  const auto path = sc.trajectory(interval, 1000, 50);
  const double revolution = 2 * 2 * M_PI / path.back()[0];
  double slope = 0;  // max |dω/dφ|
  for (const auto& y : path) slope = std::max(slope, std::fabs(sc.rhs(0, y)[1] / y[1]));
  auto at = [&](double t) { return path[static_cast<std::size_t>(std::lround(t / interval))]; };
  auto phiBound = [&](double t) { return 100 * rtol * 2 * M_PI * std::pow(1 + t / revolution, 2); };
  compareColumn(
      r, "phi", [&](double t) { return at(t)[0]; }, phiBound);
  compareColumn(
      r, "der(phi)", [&](double t) { return at(t)[1]; },
      [&](double t) { return slope * phiBound(t) + oscillationBound(rtol, sc.omega0, revolution, t); });
  compareColumn(
      r, "psi", [&](double t) { return sc.psi(at(t)[0]); }, phiBound);
  compareColumn(
      r, "xB", [&](double t) { return sc.xB(at(t)[0]); }, [&](double t) { return 2 * sc.r * phiBound(t); });
  const double e0 = sc.energy(path.front());
  compareColumn(
      r, "E", [&](double) { return e0; }, [&](double t) { return 2 * oscillationBound(rtol, e0, revolution, t); });
  expectConstraintsHeld(r, 2, rtol, sc.r + sc.L, 2 * sc.r * sc.omega0);
  EXPECT_GT(r.col("phi").back(), 2 * M_PI) << "a full revolution";
  // The dependent velocities at the start follow from the differentiated constraints (their
  // declared start 0 is not consistent): psi' = −(r/L) omega0, xB' = 0 at phi = 0.
  EXPECT_NEAR(r.col("der(psi)").front(), -sc.r / sc.L * sc.omega0, 100 * rtol * sc.omega0);
  EXPECT_NEAR(r.col("der(xB)").front(), 0, 100 * rtol * sc.r * sc.omega0);
}

// ---------------------------------------------------------------------------------------------
// ellipsograph_sliders.qd: the model's kinetic energy, written in the slider velocities, equals the
// textbook's ½ (3m + 4m1) l² θ'² when xA' = −2 l sin θ θ', yB' = 2 l cos θ θ' (the constraints).
struct Ellipsograph {
  double m = 1, m1 = 0.5, l = 0.3, torque = 2, theta0 = 0.3;
  double alpha() const { return torque / ((3 * m + 4 * m1) * l * l); }
  double theta(double t) const { return theta0 + alpha() * t * t / 2; }
  double kineticInSliders(double thetaDot, double xADot, double yBDot) const {
    const double crank = 0.5 * (m * l * l / 3) * thetaDot * thetaDot;
    const double ruler = 0.5 * (2 * m) * (xADot * xADot + yBDot * yBDot) / 4 +
                         0.5 * (2 * m * 4 * l * l / 12) * (xADot * xADot + yBDot * yBDot) / (4 * l * l);
    return crank + ruler + 0.5 * m1 * (xADot * xADot + yBDot * yBDot);
  }
};

TEST(ConstrainedReference, EllipsographSliderKineticEnergy) {
  const Ellipsograph e;
  for (double theta : {0.0, 0.3, 1.0, 2.5}) {
    const double thetaDot = 1.7;
    const double t =
        e.kineticInSliders(thetaDot, -2 * e.l * std::sin(theta) * thetaDot, 2 * e.l * std::cos(theta) * thetaDot);
    EXPECT_NEAR(t, 0.5 * (3 * e.m + 4 * e.m1) * e.l * e.l * thetaDot * thetaDot, 1e-14);
  }
}

// The textbook's closed form at every output time (2 s, θ from 0.3 to 9.2 rad: about 1.4 turns), at
// rtol 1e-8. Bound 100·rtol·(|θ(t)| + θ0): the solution is a quadratic in t, reproduced exactly by BDF
// if θ is the state kept, but index reduction may keep a slider instead, whose motion is a cosine;
// xA and yB follow with the factor 2l, θ' with α t + θ0.
TEST(EllipsographSliders, ClosedForm) {
  const Ellipsograph e;
  const double rtol = 1e-8, a = e.alpha();
  auto r = runConstrained("examples/constrained/ellipsograph_sliders.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 2, 0.01);
  auto bound = [&](double t) { return 100 * rtol * (e.theta(t) + e.theta0); };
  compareColumn(
      r, "theta", [&](double t) { return e.theta(t); }, bound);
  compareColumn(
      r, "der(theta)", [&](double t) { return a * t; }, [&](double t) { return 100 * rtol * (a * t + e.theta0); });
  compareColumn(
      r, "xA", [&](double t) { return 2 * e.l * std::cos(e.theta(t)); }, [&](double t) { return 2 * e.l * bound(t); });
  compareColumn(
      r, "yB", [&](double t) { return 2 * e.l * std::sin(e.theta(t)); }, [&](double t) { return 2 * e.l * bound(t); });
  expectConstraintsHeld(r, 2, rtol, 2 * e.l, 2 * e.l * a * 2);
}

// ---------------------------------------------------------------------------------------------
// rolling_cylinder.qd: the rows m x'' − m g sin α = λ, I φ'' = −R λ with x'' = R φ'' solved as a
// linear system (Cramer's rule) give a = g sin α / (1 + I/(m R²)) = (2/3) g sin α and λ = −m g sin α / 3.
struct Cylinder {
  double m = 2, R = 0.1, alpha = 0.3, g = 9.81;
  double I() const { return m * R * R / 2; }
  double a() const { return 2.0 / 3 * g * std::sin(alpha); }
  double friction() const { return -m * g * std::sin(alpha) / 3; }
};

TEST(ConstrainedReference, RollingCylinderLinearSystem) {
  const Cylinder c;
  // Unknowns (x'', φ'', λ): [m 0 −1; 0 I R; 1 −R 0] · u = [m g sin α, 0, 0].
  const std::array<std::array<double, 3>, 3> A{{{c.m, 0, -1}, {0, c.I(), c.R}, {1, -c.R, 0}}};
  const std::array<double, 3> b{c.m * c.g * std::sin(c.alpha), 0, 0};
  auto det = [](const std::array<std::array<double, 3>, 3>& M) {
    return M[0][0] * (M[1][1] * M[2][2] - M[1][2] * M[2][1]) - M[0][1] * (M[1][0] * M[2][2] - M[1][2] * M[2][0]) +
           M[0][2] * (M[1][0] * M[2][1] - M[1][1] * M[2][0]);
  };
  auto solve = [&](int column) {
    auto M = A;
    for (int i = 0; i < 3; ++i) M[i][column] = b[i];
    return det(M) / det(A);
  };
  EXPECT_NEAR(solve(0), c.a(), 1e-14);
  EXPECT_NEAR(solve(0), c.g * std::sin(c.alpha) / (1 + c.I() / (c.m * c.R * c.R)), 1e-14);
  EXPECT_NEAR(solve(1), c.a() / c.R, 1e-13);
  EXPECT_NEAR(solve(2), c.friction(), 1e-14);
}

// The annotation's run (2 s) at rtol 1e-9: x = ½ a t², x' = a t, φ = x/R at every output time within
// 100·rtol·(|y(t)| + scale) (a quadratic: exact for BDF but for its first low-order steps), and the
// multiplier lambda[1], the friction force along +x, equals −m g sin α / 3 within 1e-6 relative
// (an algebraic variable: solved to Newton's tolerance at every step, not integrated).
TEST(RollingCylinder, ClosedFormAndFriction) {
  const Cylinder c;
  const double rtol = 1e-9, a = c.a(), xEnd = a * 2;
  auto r = runConstrained("examples/constrained/rolling_cylinder.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 2, 0.01);
  compareColumn(
      r, "x", [&](double t) { return a * t * t / 2; }, [&](double t) { return 100 * rtol * (a * t * t / 2 + xEnd); });
  compareColumn(
      r, "der(x)", [&](double t) { return a * t; }, [&](double t) { return 100 * rtol * (a * t + a); });
  compareColumn(
      r, "phi", [&](double t) { return a * t * t / 2 / c.R; },
      [&](double t) { return 100 * rtol * (a * t * t / 2 + xEnd) / c.R; });
  compareColumn(
      r, "lambda[1]", [&](double) { return c.friction(); }, [&](double) { return 1e-6 * std::fabs(c.friction()); });
  expectConstraintsHeld(r, 1, rtol, xEnd, 2 * a);
}

// ---------------------------------------------------------------------------------------------
// car_axis.qd: problem CARAXIS of the Test Set for IVP Solvers (examples/benchmarks/README.md).
// Parameters eps = 1e-2, M = 10, L = 1, L0 = 0.5, r = 0.1, w = 10, g = 1; k = M eps²/2.
// The published reference solution at t = 3 (subroutine soln of caraxis.f), all its digits:
// y1..y4 = xl, yl, xr, yr; y5..y8 their velocities; y9, y10 = λ1, λ2.
struct CarAxis {
  double eps = 1e-2, M = 10, L = 1, L0 = 0.5, r = 0.1, w = 10, g = 1;
  double k() const { return M * eps * eps / 2; }
  static constexpr std::array<double, 10> kReferenceAt3{
      0.4934557842755629e-01,  0.4969894602303324e+00, 0.1041742524885400e+01, 0.3739110272652214e+00,
      -0.7705836840321485e-01, 0.7446866596327776e-02, 0.1755681574942899e-01, 0.7703410437794031e+00,
      -0.4736886750784630e-02, -0.1104680411345730e-02};

  template <class T>
  T yb(T t) const {
    using std::sin;
    return r * sin(w * t);
  }
  template <class T>
  T xb(T t) const {
    using std::sqrt;
    return sqrt(L * L - yb(t) * yb(t));
  }
  // V and the constraints as in car_axis.qd, over q = (xl, yl, xr, yr).
  template <class T>
  T potential(const std::array<T, 4>& q, T t) const {
    using std::sqrt;
    const T ll = sqrt(q[0] * q[0] + q[1] * q[1]);
    const T lr = sqrt((q[2] - xb(t)) * (q[2] - xb(t)) + (q[3] - yb(t)) * (q[3] - yb(t)));
    return 0.5 * (ll - L0) * (ll - L0) + 0.5 * (lr - L0) * (lr - L0) + k() * g * (q[1] + q[3]);
  }
  template <class T>
  std::array<T, 2> constraints(const std::array<T, 4>& q, T t) const {
    return {xb(t) * q[0] + yb(t) * q[1], (q[0] - q[2]) * (q[0] - q[2]) + (q[1] - q[3]) * (q[1] - q[3]) - L * L};
  }
  // The test set's right-hand sides f(5..8) (k y'(5..8) = f(5..8)), transcribed from caraxis.f.
  std::array<double, 4> testSetForces(const std::array<double, 10>& y, double t) const {
    const double xl = y[0], yl = y[1], xr = y[2], yr = y[3], lam1 = y[8], lam2 = y[9];
    const double ll = std::sqrt(xl * xl + yl * yl),
                 lr = std::sqrt((xr - xb(t)) * (xr - xb(t)) + (yr - yb(t)) * (yr - yb(t)));
    return {(L0 - ll) * xl / ll + lam1 * xb(t) + 2 * lam2 * (xl - xr),
            (L0 - ll) * yl / ll + lam1 * yb(t) + 2 * lam2 * (yl - yr) - M * eps * eps * g / 2,
            (L0 - lr) * (xr - xb(t)) / lr - 2 * lam2 * (xl - xr),
            (L0 - lr) * (yr - yb(t)) / lr - 2 * lam2 * (yl - yr) - M * eps * eps * g / 2};
  }
};

// The reference and the model's form: the published state at t = 3 satisfies both constraints (to
// 1e-12) and their time derivatives (to 1e-10: the published velocities are good to about 1e-11),
// which also checks the transcription of its digits, as does the
// test set's start; and −∂V/∂q + λ1 ∂g1/∂q + λ2 ∂g2/∂q (derivatives by dual numbers of V and g as
// written in car_axis.qd) equals the test set's f(5..8) at the published state, so qdot's lambda[k]
// are the test set's y9, y10.
TEST(ConstrainedReference, CarAxisPublishedSolutionAndLagrangianForm) {
  const CarAxis ca;
  const auto& y = CarAxis::kReferenceAt3;
  auto residuals = [&](const std::array<double, 10>& s, double t) {
    std::array<Dual, 4> q;  // q(t + ε) = q + ε q': the dual part of g is dg/dt
    for (int i = 0; i < 4; ++i) q[i] = Dual(s[i], s[4 + i]);
    return ca.constraints(q, Dual(t, 1));
  };
  for (const Dual& g : residuals(y, 3)) {
    EXPECT_NEAR(g.v, 0, 1e-12);
    EXPECT_NEAR(g.d, 0, 1e-10);
  }
  const std::array<double, 10> start{0, ca.L0, ca.L, ca.L0, -ca.L0 / ca.L, 0, -ca.L0 / ca.L, 0, 0, 0};
  for (const Dual& g : residuals(start, 0)) {
    EXPECT_NEAR(g.v, 0, 1e-15);
    EXPECT_NEAR(g.d, 0, 1e-15);
  }
  const auto f = ca.testSetForces(y, 3);
  for (int j = 0; j < 4; ++j) {
    std::array<Dual, 4> q;
    for (int i = 0; i < 4; ++i) q[i] = Dual(y[i], i == j ? 1 : 0);
    const Dual v = ca.potential(q, Dual(3));
    const auto g = ca.constraints(q, Dual(3));
    EXPECT_NEAR(-v.d + y[8] * g[0].d + y[9] * g[1].d, f[j], 1e-15) << "row of coordinate " << j + 1;
  }
}

// Dense Gaussian elimination with partial pivoting: the solution of A x = b.
template <std::size_t N>
std::array<double, N> solveLinear(std::array<std::array<double, N>, N> A, std::array<double, N> b) {
  for (std::size_t c = 0; c < N; ++c) {
    std::size_t pivot = c;
    for (std::size_t i = c + 1; i < N; ++i)
      if (std::fabs(A[i][c]) > std::fabs(A[pivot][c])) pivot = i;
    std::swap(A[c], A[pivot]);
    std::swap(b[c], b[pivot]);
    for (std::size_t i = c + 1; i < N; ++i) {
      const double f = A[i][c] / A[c][c];
      for (std::size_t j = c; j < N; ++j) A[i][j] -= f * A[c][j];
      b[i] -= f * b[c];
    }
  }
  std::array<double, N> x{};
  for (std::size_t i = N; i-- > 0;) {
    double s = b[i];
    for (std::size_t j = i + 1; j < N; ++j) s -= A[i][j] * x[j];
    x[i] = s / A[i][i];
  }
  return x;
}

// The car axis as an index-1 system: with G = ∂g/∂q, the accelerations a and multipliers λ solve
//   k a − Gᵀ λ = −∂V/∂q,   G a = −(g'' without the a terms),
// where, with yb = r sin wt, xb = √(L² − yb²) and their time derivatives,
//   g1'' = xb'' xl + 2 xb' xl' + xb xl'' + yb'' yl + 2 yb' yl' + yb yl'',
//   g2'' = 2 (xl' − xr')² + 2 (yl' − yr')² + 2 (xl − xr)(xl'' − xr'') + 2 (yl − yr)(yl'' − yr'').
// ∂V/∂q and G by dual numbers of V and g as written in car_axis.qd. Returns (q', q'') and λ.
std::pair<std::array<double, 8>, std::array<double, 2>> carAxisIndexOne(const CarAxis& ca, double t,
                                                                        const std::array<double, 8>& y) {
  std::array<double, 4> force{};
  std::array<std::array<double, 4>, 2> G{};
  for (int j = 0; j < 4; ++j) {
    std::array<Dual, 4> q;
    for (int i = 0; i < 4; ++i) q[i] = Dual(y[i], i == j ? 1 : 0);
    force[j] = -ca.potential(q, Dual(t)).d;
    const auto g = ca.constraints(q, Dual(t));
    G[0][j] = g[0].d, G[1][j] = g[1].d;
  }
  const double yb = ca.yb(t), yb1 = ca.r * ca.w * std::cos(ca.w * t), yb2 = -ca.w * ca.w * yb;
  const double xb = ca.xb(t), xb1 = -yb * yb1 / xb, xb2 = -(yb1 * yb1 + yb * yb2 + xb1 * xb1) / xb;
  const double dvx = y[4] - y[6], dvy = y[5] - y[7];
  const double rest1 = xb2 * y[0] + 2 * xb1 * y[4] + yb2 * y[1] + 2 * yb1 * y[5];
  const double rest2 = 2 * dvx * dvx + 2 * dvy * dvy;
  std::array<std::array<double, 6>, 6> A{};
  std::array<double, 6> b{force[0], force[1], force[2], force[3], -rest1, -rest2};
  for (int i = 0; i < 4; ++i) {
    A[i][i] = ca.k();
    A[i][4] = -G[0][i], A[i][5] = -G[1][i];
    A[4][i] = G[0][i], A[5][i] = G[1][i];
  }
  const auto x = solveLinear(A, b);
  return {{y[4], y[5], y[6], y[7], x[0], x[1], x[2], x[3]}, {x[4], x[5]}};
}

// The model's Lagrangian form and the test set's start, integrated independently (RK4 with
// h = 1e-4 on the index-1 system above; ω h ≈ 5e-3 for the springs' ω = √(1/k) ≈ 45), reproduce the
// published solution at t = 3: positions within 1e-9 relative, velocities 1e-8, multipliers 1e-6
// (measured: 2e-11, 2e-9, 7e-8). So car_axis.qd and its start are the published problem.
TEST(ConstrainedReference, CarAxisIndexOneRk4ReproducesPublished) {
  const CarAxis ca;
  std::array<double, 8> y{0, ca.L0, ca.L, ca.L0, -ca.L0 / ca.L, 0, -ca.L0 / ca.L, 0};
  auto f = [&](double t, const std::array<double, 8>& s) { return carAxisIndexOne(ca, t, s).first; };
  const int steps = 30000;
  const double h = 3.0 / steps;
  for (int n = 0; n < steps; ++n) y = rk4Step(f, n * h, y, h);
  const auto lambda = carAxisIndexOne(ca, 3, y).second;
  const auto& ref = CarAxis::kReferenceAt3;
  for (int i = 0; i < 8; ++i) EXPECT_NEAR(y[i], ref[i], (i < 4 ? 1e-9 : 1e-8) * std::fabs(ref[i])) << "y" << i + 1;
  EXPECT_NEAR(lambda[0], ref[8], 1e-6 * std::fabs(ref[8]));
  EXPECT_NEAR(lambda[1], ref[9], 1e-6 * std::fabs(ref[9]));
}

// The annotation's run (3 s) at rtol 1e-10 (atol = rtol): the positions at t = 3 agree with the
// published reference to 6 significant digits (|error| ≤ 1e-6·|y|), the velocities to 1e-5 relative
// and the multipliers to 1e-4 relative (the published values come from a run at far tighter
// tolerance; at rtol 1e-10 the test set's own solvers reach 7–9 digits in the positions). The
// constraints hold within 100·rtol·scale at every output row (scale L² = 1; the rates' terms, such as
// yb' yl ≤ r w L0 and 2 |xl − xr| |xl' − xr'|, stay below 2).
TEST(CarAxis, PublishedReferenceAtT3) {
  const double rtol = 1e-10;
  auto r = runConstrained("examples/benchmarks/car_axis.qd", {"--rtol", num(rtol)});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, 0, 3, 0.01);
  const auto& y = CarAxis::kReferenceAt3;
  const std::array<const char*, 10> columns{"xl",      "yl",      "xr",      "yr",        "der(xl)",
                                            "der(yl)", "der(xr)", "der(yr)", "lambda[1]", "lambda[2]"};
  for (std::size_t i = 0; i < columns.size(); ++i) {
    const auto& c = r.col(columns[i]);
    ASSERT_FALSE(c.empty()) << columns[i];
    const double relative = i < 4 ? 1e-6 : i < 8 ? 1e-5 : 1e-4;
    EXPECT_NEAR(c.back(), y[i], relative * std::fabs(y[i])) << columns[i] << " at t = 3";
    std::cout << "[measured] " << columns[i] << "(3) relative error " << std::fabs(c.back() - y[i]) / std::fabs(y[i])
              << "\n";
  }
  expectConstraintsHeld(r, 2, rtol, 1, 2);
  // The start velocities of the dependent coordinates follow from the differentiated constraints:
  // xl' = xr' = −L0/L (their declared start 0 is not consistent).
  const CarAxis ca;
  EXPECT_NEAR(r.col("der(xl)").front(), -ca.L0 / ca.L, 100 * rtol);
  EXPECT_NEAR(r.col("der(xr)").front(), -ca.L0 / ca.L, 100 * rtol);
}

}  // namespace
}  // namespace qdot::simtest
