#!/usr/bin/env python3
"""qdot against sympy on textbook Lagrangians written with Cartesian positions (issue 14): length of
the printed equation of motion and the time to derive and simplify it. sympy: Euler-Lagrange by
hand (d/dt dL/dq' - dL/dq), then trigsimp(simplify(...)) of each row; qdot: `qdot equations
--timings` (derive stage; rows as printed). Usage: sympy_textbook.py QDOT [--repeat R]
Needs sympy (pip install sympy) for the benchmark only; it is not needed to build or test qdot."""
import os, re, subprocess, sys, tempfile, time
import sympy as sp

t = sp.symbols("t")

def cases():
    m, R, W, g, l = sp.symbols("m R Omega g l", positive=True)
    th, ph = sp.Function("theta")(t), sp.Function("phi")(t)
    th1, th2 = sp.Function("th1")(t), sp.Function("th2")(t)
    hoop_pos = [R*sp.sin(th)*sp.cos(W*t), R*sp.sin(th)*sp.sin(W*t), -R*sp.cos(th)]
    sph_pos = [l*sp.sin(th)*sp.cos(ph), l*sp.sin(th)*sp.sin(ph), -l*sp.cos(th)]
    x1, y1 = l*sp.sin(th1), -l*sp.cos(th1)
    x2, y2 = x1 + l*sp.sin(th2), y1 - l*sp.cos(th2)
    def T(pos): return sp.Rational(1, 2)*m*sum(sp.diff(p, t)**2 for p in pos)
    yield ("bead on a rotating hoop", T(hoop_pos) - m*g*hoop_pos[2], [th], HOOP)
    yield ("spherical pendulum (Cartesian)", T(sph_pos) - m*g*sph_pos[2], [th, ph], SPHERICAL)
    yield ("double pendulum", T([x1, y1]) + T([x2, y2]) - m*g*(y1 + y2), [th1, th2], DOUBLE)

HOOP = """model BeadOnHoop
  parameter Real m = 0.1; parameter Real R = 0.5; parameter Real Omega = 5; parameter Real g = 9.81;
  coordinate Real theta(start = 0.5);
  Real x = R*sin(theta)*cos(Omega*time); Real y = R*sin(theta)*sin(Omega*time); Real z = -R*cos(theta);
mechanics
  kinetic = 0.5*m*(der(x)^2 + der(y)^2 + der(z)^2);
  potential = m*g*z;
end BeadOnHoop;
"""
SPHERICAL = """model SphericalPendulum
  parameter Real m = 1; parameter Real l = 1; parameter Real g = 9.81;
  coordinate Real theta(start = 0.8); coordinate Real phi(start = 0);
  Real x = l*sin(theta)*cos(phi); Real y = l*sin(theta)*sin(phi); Real z = -l*cos(theta);
mechanics
  kinetic = 0.5*m*(der(x)^2 + der(y)^2 + der(z)^2);
  potential = m*g*z;
end SphericalPendulum;
"""
DOUBLE = """model DoublePendulum
  parameter Real m = 1; parameter Real l = 1; parameter Real g = 9.81;
  coordinate Real th1(start = 0.5); coordinate Real th2(start = 0);
  Real x1 = l*sin(th1); Real y1 = -l*cos(th1); Real x2 = x1 + l*sin(th2); Real y2 = y1 - l*cos(th2);
mechanics
  kinetic = 0.5*m*(der(x1)^2 + der(y1)^2) + 0.5*m*(der(x2)^2 + der(y2)^2);
  potential = m*g*(y1 + y2);
end DoublePendulum;
"""

def sympy_rows(L, qs):
    t0 = time.perf_counter()
    rows = [sp.trigsimp(sp.simplify(sp.diff(sp.diff(L, sp.diff(q, t)), t) - sp.diff(L, q))) for q in qs]
    return rows, time.perf_counter() - t0

def qdot_rows(qdot, text, repeat):
    with tempfile.NamedTemporaryFile("w", suffix=".qd", delete=False) as f:
        f.write(text)
    best, rows = 1e9, []
    for _ in range(repeat):
        r = subprocess.run([qdot, "equations", f.name, "--timings"], capture_output=True, text=True, check=True)
        ms = re.search(r"derive ([0-9.e+-]+)", r.stderr)
        best = min(best, float(ms.group(1)) / 1e3)
        rows = [line.split(":  ", 1)[1][:-4] for line in r.stdout.splitlines() if line.startswith("  ") and ":  " in line and line.endswith(" = 0")]
    os.unlink(f.name)
    return rows, best

def main():
    qdot = sys.argv[1]
    repeat = int(sys.argv[sys.argv.index("--repeat") + 1]) if "--repeat" in sys.argv else 5
    print("| model | qdot chars | sympy chars | qdot derive [ms] | sympy derive+simplify [ms] | speed-up |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, L, qs, text in cases():
        srows, st = sympy_rows(L, qs)
        qrows, qt = qdot_rows(qdot, text, repeat)
        sc = sum(len(str(r)) for r in srows)
        qc = sum(len(r) for r in qrows)
        print(f"| {name} | {qc} | {sc} | {qt*1e3:.3f} | {st*1e3:.0f} | {st/qt:.0f}× |")
        for r in srows: print(f"<!-- sympy: {r} -->")
        for r in qrows: print(f"<!-- qdot: {r} -->")

if __name__ == "__main__":
    main()
