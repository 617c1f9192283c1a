#!/usr/bin/env python3
"""Equal-error benchmark (issue 11, section 2): qdot's whole process against the hand-written program.

Both programs run a ladder of tolerances on the same model: `qdot run --rtol R` with qdot's default
(automatic, calibrated tolerances: docs/accuracy.md) and `reference_sim --rtol R --atol R` (the
hand-written C++ program on the same IDA, with SUNDIALS' absolute atol as a person writing it would
give). The error of each run is the largest |y - y_ref| over the output grid and the compared
columns, y_ref a run of the hand-written program at rtol = atol = 1e-12. Each qdot run's whole wall
time (process start to exit: compile, solve, CSV) is compared with the hand-written program's wall
time at the *same error*, interpolated log-log between its two nearest runs (no extrapolation).

    bench/equal_error_bench.py --build build [--quick]
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import tempfile
import time

PENDULUM = "examples/pendulum/nlink.qd"
CHAIN = "examples/vibration/spring_chain.qd"
REFERENCE_RTOL = 1e-12


class Case:
    def __init__(self, title, kind, source, n, stop, interval, columns):
        self.title, self.kind, self.source, self.n = title, kind, source, n
        self.stop, self.interval, self.columns = stop, interval, columns

    def options(self):
        return ["--stop", repr(self.stop), "--interval", repr(self.interval), "--outputs", ",".join(self.columns)]


def cases(quick):
    pendulum = Case("8-link pendulum", "nlink", PENDULUM, 8, 10.0, 0.01, ["th[1]", "th[8]"])
    chain1k = Case("spring chain", "chain", CHAIN, 1000, 40.0 if not quick else 10.0, 0.08, ["x[1]", "x[1000]"])
    chain10k = Case("spring chain", "chain", CHAIN, 10000, 4.0 if not quick else 1.0, 0.008, ["x[1]", "x[10000]"])
    return [pendulum, chain1k, chain10k]


def timed(command):
    start = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"equal_error_bench: {' '.join(command)} failed:\n{done.stderr}")
    return seconds


def read_columns(path, columns):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [[float(row[c]) for c in columns] for row in rows]


def max_error(values, reference):
    if len(values) != len(reference):
        sys.exit("equal_error_bench: a run and the reference have different output grids")
    return max(abs(a - b) for row, ref in zip(values, reference) for a, b in zip(row, ref))


def qdot_run(build, case, rtol, path):
    command = [f"{build}/qdot", "run", case.source, "-p", f"n={case.n}", "--rtol", repr(rtol), "-o", path]
    return timed(command + case.options())


def hand_run(build, case, rtol, path):
    command = [f"{build}/bench/reference_sim", case.kind, "--n", str(case.n), "--rtol", repr(rtol), "--atol",
               repr(rtol), "-o", path]
    return timed(command + case.options())


def ladder(run, build, case, rtols, reference, directory, repeat):
    """(rtol, error, best wall time) per rung."""
    points = []
    for rtol in rtols:
        path = os.path.join(directory, "run.csv")
        seconds = min(run(build, case, rtol, path) for _ in range(repeat))
        points.append((rtol, max_error(read_columns(path, case.columns), reference), seconds))
    return points


def time_at_error(points, error):
    """The wall time at this error on a ladder's curve, log-log between its two nearest runs; None outside it."""
    curve = sorted((e, t) for _, e, t in points if e > 0)
    for (e0, t0), (e1, t1) in zip(curve, curve[1:]):
        if e0 <= error <= e1 and e0 < e1:
            w = (math.log(error) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp((1 - w) * math.log(t0) + w * math.log(t1))
    return None


def report(case, qdot, hand):
    print(f"\n### {case.title}, n = {case.n}, t in [0, {case.stop:g}], columns {', '.join(case.columns)}\n")
    print("| rtol | qdot error | qdot whole [s] | hand error (rtol = atol) | hand whole [s] "
          "| hand at qdot's error [s] | **qdot / hand at equal error** |")
    print("|---:|---:|---:|---:|---:|---:|---:|")
    for (rtol, qe, qt), (_, he, ht) in zip(qdot, hand):  # the hand-written ladder's tighter rungs: curve only
        at = time_at_error(hand, qe)
        cells = f"{at:.3f} | **{qt / at:.2f}**" if at else "– | – (outside the hand-written curve)"
        print(f"| {rtol:g} | {qe:.3g} | {qt:.3f} | {he:.3g} | {ht:.3f} | {cells} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--quick", action="store_true", help="shorter runs, three rungs, one repetition")
    args = parser.parse_args()
    rtols = [1e-4, 1e-6, 1e-8] if args.quick else [1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9]
    repeat = 1 if args.quick else 3
    print("\n## Equal error: qdot's whole process against the hand-written program (bench/equal_error_bench.py)")
    print(f"\nReference: the hand-written program at rtol = atol = {REFERENCE_RTOL:g}. Error: max |y - y_ref| over "
          f"the output grid and the columns named. Whole: process wall time, best of {repeat}.")
    with tempfile.TemporaryDirectory() as directory:
        for case in cases(args.quick):
            path = os.path.join(directory, "reference.csv")
            hand_run(args.build, case, REFERENCE_RTOL, path)
            reference = read_columns(path, case.columns)
            qdot = ladder(qdot_run, args.build, case, rtols, reference, directory, repeat)
            # two decades tighter for the hand-written program, so its curve spans qdot's errors
            hand = ladder(hand_run, args.build, case, rtols + [rtols[-1] / 10, rtols[-1] / 100], reference, directory,
                          repeat)
            report(case, qdot, hand)


if __name__ == "__main__":
    main()
