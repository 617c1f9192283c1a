#!/usr/bin/env python3
"""Fidelity against cost (issue 11, section 6): how many elements a model needs for a given accuracy.

Two families, each against its continuum:
- `Vibration.String(n, T = 100, rhoL = 0.01, L = 1)` (examples/vibration/string.qd): n lumped masses
  between fixed ends against the continuous string, w_k = k pi / L * sqrt(T / rhoL) = 314.16 k rad/s.
- The N-link pendulum (examples/pendulum/nlink.qd) of total length L = 1 m (l = L/n, m = 1/n kg)
  against the hanging chain of the same length, w_k = (j_0k / 2) sqrt(g / L), j_0k the zeros of the
  Bessel function J0 (2.404826, 5.520078, 8.653728): the chain the links approximate as n grows.
For each n: the relative error of the three lowest frequencies of `qdot modes` (linearized at the
static equilibrium), the wall time of `qdot modes` (compile + linearization) and of `qdot run`
(whole process: compile, solve with the default settings, CSV) over the example's horizon.

    bench/fidelity_bench.py --build build [--quick]
"""
import argparse
import math
import os
import re
import subprocess
import sys
import tempfile
import time

BESSEL_J0_ZEROS = [2.404825557695773, 5.520078110286311, 8.653727912911013]
G = 9.81


def string_model(n):
    starts = f"{{0.002*sin(pi*i/{n + 1}) for i in 1:{n}}}"
    return (f"model StringFidelity\n  import Vibration.*;\n"
            f"  String str(n = {n}, T = 100, rhoL = 0.01, L = 1, y(start = {starts}, nominal = 0.002));\n"
            f"  annotation(experiment(StopTime = 0.05, Interval = 0.0002));\nend StringFidelity;\n")


def string_exact(k):
    return k * math.pi * math.sqrt(100 / 0.01)


def pendulum_exact(k):
    return BESSEL_J0_ZEROS[k - 1] / 2 * math.sqrt(G / 1.0)


def timed(command):
    start = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"fidelity_bench: {' '.join(command)} failed:\n{done.stderr}")
    return time.perf_counter() - start, done.stdout


def frequencies(modes_output):
    """omega of each mode from `qdot modes` (rows: index, omega, f, zeta, shape)."""
    found = re.findall(r"^\s+(\d+)\s+([0-9.eE+-]+)\s+[0-9.eE+-]+\s+[0-9.eE+-]+\s", modes_output, re.MULTILINE)
    return [float(omega) for _, omega in found]


def measure(build, path, parameters, exact, lowest):
    modes_seconds, output = timed([f"{build}/qdot", "modes", path] + parameters)
    run_seconds, _ = timed([f"{build}/qdot", "run", path, "-o", os.devnull] + parameters)
    omegas = sorted(frequencies(output))
    errors = [abs(omegas[k - 1] - exact(k)) / exact(k) if k <= len(omegas) else None for k in range(1, lowest + 1)]
    return errors, modes_seconds, run_seconds


def table(title, reference, rows):
    print(f"\n### {title}\n\nReference: {reference}\n")
    print("| n | unknowns | error w1 | error w2 | error w3 | `qdot modes` [s] | `qdot run` whole [s] |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for n, errors, modes_seconds, run_seconds in rows:
        cells = " | ".join(f"{e:.2e}" if e is not None else "–" for e in errors)
        print(f"| {n} | {2 * n} | {cells} | {modes_seconds:.3f} | {run_seconds:.3f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--quick", action="store_true", help="fewer sizes")
    args = parser.parse_args()
    string_sizes = [5, 10, 20, 40] if args.quick else [5, 10, 20, 40, 80, 160, 320]
    pendulum_sizes = [1, 2, 4, 8] if args.quick else [1, 2, 4, 8, 16, 32]
    print("\n## Fidelity against cost (bench/fidelity_bench.py)")
    with tempfile.TemporaryDirectory() as directory:
        rows = []
        for n in string_sizes:
            path = os.path.join(directory, f"string{n}.qd")
            with open(path, "w") as f:
                f.write(string_model(n))
            rows.append((n, *measure(args.build, path, [], string_exact, 3)))
        table("Vibration.String(n): lumped string against the continuous one",
              "w_k = k pi sqrt(T/rhoL)/L = 314.159 k rad/s (lumped exactly: 2 sqrt(T/(rhoL h^2)) sin(k pi/(2(n+1))), "
              "h = L/(n+1))", rows)
        rows = []
        for n in pendulum_sizes:
            parameters = ["-p", f"n={n}", "-p", f"l={1.0 / n!r}", "-p", f"m={1.0 / n!r}"]
            rows.append((n, *measure(args.build, "examples/pendulum/nlink.qd", parameters, pendulum_exact, 3)))
        table("N-link pendulum of total length 1 m against the hanging chain",
              "w_k = (j_0k/2) sqrt(g/L) = 3.766, 8.645, 13.553 rad/s (J0's zeros; g = 9.81, L = 1 m)", rows)


if __name__ == "__main__":
    main()
