// The textbook examples of examples/textbook/ simulated by `qdot run` and compared with the
// textbook's (Dynamics II, ch. 5) closed forms and first integrals at every output time.
#include <cmath>

#include "QdotRun.h"

namespace qdot::simtest {
namespace {

constexpr double kG = 9.81;

// ---------------------------------------------------------------------------------------------
// U-tube, example 5-2. Reference: l ẍ + 2 g x = 0 with x(0) = h/2, ẋ(0) = 0, so
//   x = (h/2) cos(ω t),  ẋ = −(h/2) ω sin(ω t),  ω = √(2g/l).
// Bound: oscillationBound (QdotRun.h): 100·rtol·A·(1 + t/P), A = h/2 for x and (h/2)ω for ẋ.
void checkUTube(double h, double l, const std::vector<std::string>& parameters) {
  const double w = std::sqrt(2 * kG / l), period = 2 * M_PI / w, a = h / 2;
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    std::vector<std::string> args = {"--rtol", num(rtol)};
    args.insert(args.end(), parameters.begin(), parameters.end());
    auto r = runQdot("examples/textbook/utube.qd", args);
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 10, 0.01);  // the experiment annotation
    auto dx = compareColumn(
        r, "x", [&](double t) { return a * std::cos(w * t); },
        [&](double t) { return oscillationBound(rtol, a, period, t); });
    compareColumn(
        r, "der(x)", [&](double t) { return -a * w * std::sin(w * t); },
        [&](double t) { return oscillationBound(rtol, a * w, period, t); });
    // The model's own energy column E = ½ρAl ẋ² + ρAg x² against its start value ρAg h²/4.
    const double rho = 1000, bore = 1e-4, e0 = rho * bore * kG * a * a;
    compareColumn(
        r, "E", [&](double) { return e0; }, [&](double t) { return 2 * oscillationBound(rtol, e0, period, t); });
    EXPECT_LT(dx.maxError, previous / 10) << "the error must shrink with the tolerance";
    previous = dx.maxError;
  }
}

TEST(UTube, ClosedForm) { checkUTube(0.1, 1.0, {}); }

TEST(UTube, ClosedFormWithParameters) { checkUTube(0.2, 0.5, {"-p", "h=0.2", "-p", "l=0.5"}); }

// --start 2: the start values hold at t0 = 2, so x = (h/2) cos(ω (t − t0)); same bound with t − t0
// elapsed, at the annotation's Tolerance = 1e-6.
TEST(UTube, LaterStartTime) {
  const double h = 0.1, l = 1, t0 = 2, w = std::sqrt(2 * kG / l), period = 2 * M_PI / w, a = h / 2, rtol = 1e-6;
  auto r = runQdot("examples/textbook/utube.qd", {"--start", "2", "--stop", "7", "--interval", "0.02"});
  ASSERT_EQ(r.exitCode, 0) << r.log;
  expectGrid(r, t0, 7, 0.02);
  compareColumn(
      r, "x", [&](double t) { return a * std::cos(w * (t - t0)); },
      [&](double t) { return oscillationBound(rtol, a, period, t - t0); });
}

// ---------------------------------------------------------------------------------------------
// Ellipsograph with a constant crank torque, example 5-1. Reference: (3m + 4m1) l² θ̈ = M_O, so
//   θ = θ0 + α t²/2,  θ̇ = α t,  α = M_O / ((3m + 4m1) l²)   (m = 1, m1 = 0.5, l = 0.3, M_O = 2, θ0 = 0.3).
// Bound: 10·(rtol·|y(t)| + atol_y). The solution is a quadratic, which BDF of every order ≥ 2
// reproduces exactly; only IDA's first order-1 steps commit an error, each held by the error test
// below rtol·|y| + atol_y (atol_y = rtol × scale: 0.3 for θ, 1e-3·0.3 for θ̇, from the start values).
TEST(Ellipsograph, ConstantCrankTorque) {
  const double m = 1, m1 = 0.5, l = 0.3, torque = 2, theta0 = 0.3;
  const double alpha = torque / ((3 * m + 4 * m1) * l * l);
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/textbook/ellipsograph.qd", {"--rtol", num(rtol)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 2, 0.01);
    compareColumn(
        r, "theta", [&](double t) { return theta0 + alpha * t * t / 2; },
        [&](double t) { return 10 * (rtol * (theta0 + alpha * t * t / 2) + rtol * theta0); });
    compareColumn(
        r, "der(theta)", [&](double t) { return alpha * t; },
        [&](double t) { return 10 * (rtol * alpha * t + rtol * 1e-3 * theta0); });
  }
}

// ---------------------------------------------------------------------------------------------
// Wedge, cylinder and block, example 5-4. Reference: the chapter's three equations,
//   [mA+mB+mD      mB cos α     0          ] [ẍA]   [0         ]
//   [mB cos α      3/2 mB       1/2 mB     ] [ẍB] = [mB g sin α]
//   [0             1/2 mB       1/2(mB+2mD)] [ÿD]   [mD g      ]
// solved here by Cramer's rule: constant accelerations a, so from rest q = a t²/2, q̇ = a t.
// Bound: 10·rtol·(|y(t)| + 1): as for the ellipsograph (a quadratic is exact for BDF of order ≥ 2),
// with atol_y = rtol × 1 since every unknown starts at zero (runtime/README.md: scale 1).
double det3(const double a[3][3]) {
  return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
         a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

TEST(Wedge, ConstantAccelerationsFromRest) {
  const double mA = 4, mB = 2, mD = 1, alpha = M_PI / 6;
  const double mass[3][3] = {{mA + mB + mD, mB * std::cos(alpha), 0},
                             {mB * std::cos(alpha), 1.5 * mB, 0.5 * mB},
                             {0, 0.5 * mB, 0.5 * (mB + 2 * mD)}};
  const double rhs[3] = {0, mB * kG * std::sin(alpha), mD * kG};
  double acc[3];
  const double det = det3(mass);
  ASSERT_GT(std::fabs(det), 1e-9);
  for (int j = 0; j < 3; ++j) {
    double mj[3][3];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) mj[r][c] = c == j ? rhs[r] : mass[r][c];
    acc[j] = det3(mj) / det;
  }
  EXPECT_LT(acc[0], 0) << "the wedge recoils";
  const char* names[3] = {"xA", "xB", "yD"};
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/textbook/wedge.qd", {"--rtol", num(rtol)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 1, 0.01);
    for (int j = 0; j < 3; ++j) {
      const double a = acc[j];
      compareColumn(
          r, names[j], [&](double t) { return a * t * t / 2; },
          [&](double t) { return 10 * rtol * (std::fabs(a) * t * t / 2 + 1); });
      compareColumn(
          r, std::string("der(") + names[j] + ")", [&](double t) { return a * t; },
          [&](double t) { return 10 * rtol * (std::fabs(a) * t + 1); });
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Centrifugal governor at constant ω, example 5-3 (m1 = 0.2, m2 = 1, m3 = 0.5, l = 0.25, ω = 10).
// Reference: the relative equilibrium cos θe = (6m1 + 3m2 + 3m3) g / ((3m2 + 2m1) ω² l).
// Started there at rest (-p theta0=θe) it stays there. Bound: 1e-12 rad on θ and 1e-12 rad/s on θ̇,
// independent of rtol: the exact solution is a constant, which every BDF formula reproduces
// exactly (the error estimate is zero), so the only perturbation is rounding (~1e-16) of θe and of
// the residual; the equilibrium is stable (θ started at 0.8 oscillates about it, next test), so
// rounding cannot grow. A bound of rtol·θe would not catch a solver that drifts off a fixed point.
TEST(Governor, StaysAtRelativeEquilibrium) {
  const double m1 = 0.2, m2 = 1, m3 = 0.5, l = 0.25, w = 10;
  const double thetaE = std::acos((6 * m1 + 3 * m2 + 3 * m3) * kG / ((3 * m2 + 2 * m1) * w * w * l));
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/textbook/governor.qd", {"--rtol", num(rtol), "-p", "theta0=" + num(thetaE)});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 5, 0.01);
    compareColumn(
        r, "theta", [&](double) { return thetaE; }, [](double) { return 1e-12; });
    compareColumn(
        r, "der(theta)", [](double) { return 0.0; }, [](double) { return 1e-12; });
  }
  // Control: away from θe (the default θ0 = 0.8) the governor does move, by far more than the bound.
  auto off = runQdot("examples/textbook/governor.qd", {"--stop", "1"});
  ASSERT_EQ(off.exitCode, 0) << off.log;
  const auto& th = off.col("theta");
  EXPECT_GT(*std::max_element(th.begin(), th.end()) - *std::min_element(th.begin(), th.end()), 0.05);
}

// Governor from θ0 = 0.8 at rest. Reference: L has no explicit time, so the Jacobi integral
//   J = T2 − T0 + V = (2/3 m1 + 2 m1 sin²θ + m2 + 2 m3 sin²θ) l² θ̇² − (2/3 m1 + m2) ω² l² sin²θ
//       − (4 m1 + 2 m2 + 2 m3) g l cos θ     (the textbook's T and V; T2 with 2 m2, see governor.qd)
// is conserved. Checked: the `jacobi` column equals this formula at every row (to rounding, 1e-12
// relative), and its drift from J(0) stays within 10·rtol·|J(0)| — IDA holds each step's error to
// rtol relative; the energy error of BDF on this bounded libration accumulates slowly (measured
// 0.1–1 rtol·|J| over the 5 s, ~8 oscillations) — at rtol 1e-6 and 1e-9, shrinking ≥ 10× between them.
TEST(Governor, JacobiIntegralConserved) {
  const double m1 = 0.2, m2 = 1, m3 = 0.5, l = 0.25, w = 10;
  auto jacobi = [&](double th, double v) {
    double s2 = std::sin(th) * std::sin(th);
    return (2.0 / 3 * m1 + 2 * m1 * s2 + m2 + 2 * m3 * s2) * l * l * v * v - (2.0 / 3 * m1 + m2) * w * w * l * l * s2 -
           (4 * m1 + 2 * m2 + 2 * m3) * kG * l * std::cos(th);
  };
  const double j0 = jacobi(0.8, 0);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/textbook/governor.qd", {"--rtol", num(rtol), "--invariants"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 5, 0.01);
    const auto &th = r.col("theta"), &v = r.col("der(theta)"), &jc = r.col("jacobi");
    ASSERT_EQ(jc.size(), th.size());
    for (std::size_t i = 0; i < jc.size(); ++i)
      ASSERT_NEAR(jc[i], jacobi(th[i], v[i]), 1e-12 * std::fabs(j0)) << "row " << i;
    auto d = compareColumn(
        r, "jacobi", [&](double) { return j0; }, [&](double) { return 10 * rtol * std::fabs(j0); });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
  }
}

// ---------------------------------------------------------------------------------------------
// Free governor, example 5-3 part 3 (§5-3). Reference: φ is cyclic, so
//   p_φ = (4/3 m1 + 2 m2) l² sin²θ φ̇
// is conserved; from θ0 = 0.8, φ̇0 = 10 (the model's initial equation) its value is
// (4/3·0.2 + 2)·0.25²·sin²(0.8)·10. Checked: the `p(phi)` column equals the formula at every row (to
// rounding) and stays within 10·rtol·|p0| of p0 (as for the Jacobi integral above), at rtol 1e-6
// and 1e-9, shrinking ≥ 10× between them.
TEST(FreeGovernor, CyclicMomentumConserved) {
  const double m1 = 0.2, m2 = 1, l = 0.25;
  auto momentum = [&](double th, double wphi) {
    return (4.0 / 3 * m1 + 2 * m2) * l * l * std::sin(th) * std::sin(th) * wphi;
  };
  const double p0 = momentum(0.8, 10);
  double previous = INFINITY;
  for (double rtol : {1e-6, 1e-9}) {
    auto r = runQdot("examples/textbook/governor_free.qd", {"--rtol", num(rtol), "--invariants"});
    ASSERT_EQ(r.exitCode, 0) << r.log;
    expectGrid(r, 0, 5, 0.01);
    const auto &th = r.col("theta"), &wphi = r.col("der(phi)"), &p = r.col("p(phi)");
    ASSERT_EQ(p.size(), th.size());
    for (std::size_t i = 0; i < p.size(); ++i)
      ASSERT_NEAR(p[i], momentum(th[i], wphi[i]), 1e-12 * p0) << "row " << i;
    auto d = compareColumn(
        r, "p(phi)", [&](double) { return p0; }, [&](double) { return 10 * rtol * p0; });
    EXPECT_LT(d.maxError, previous / 10);
    previous = d.maxError;
    // It is a real test: θ moves, so sin²θ and φ̇ change while their product is conserved.
    EXPECT_GT(std::fabs(wphi.back() - wphi.front()), 0.1);
  }
}

}  // namespace
}  // namespace qdot::simtest
