#!/usr/bin/env python3
"""Rigid-body benchmark (issue 12): a loose stack of n free bodies under gravity (no contacts),
declared with `body` and compiled by qdot, against the same equations written by hand
(bench/reference/FreeBodies.cpp) and integrated by the same IDA settings (reference_sim bodies).
Reports qdot's compile time (parse to runnable model), both solve times, the whole process and IDA's
counters, with the ratios, as a markdown table.
Usage: rigid_bench.py --build DIR [--quick]   (from the repository root)"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time


def model_text(n):
    """n free bodies; the start values are FreeBodies::startValues()."""
    lines = [f"model Stack{n} \"{n} free bodies under gravity, no contacts\""]
    for i in range(1, n + 1):
        lines.append(f"  body b{i}(mass = {1 + 0.01 * i!r}, inertia = {{0.1, 0.2, 0.25}}, r(start = {{0, 0, {i}}}),"
                     f" v(start = {{{0.1 * math.sin(i)!r}, 0, 0}}), omega(start = {{1, 0.5, {2 + 0.01 * i!r}}}));")
    lines += ["mechanics", "  gravity = {0, 0, -9.81};", f"end Stack{n};", ""]
    return "\n".join(lines)


def best_of(repeat, f):
    results = [f() for _ in range(repeat)]
    return min(results, key=lambda r: r["wall"])


def state_columns(n):
    """The columns the hand-written program writes: every body's q, r, v, omega."""
    cols = []
    for i in range(1, n + 1):
        cols += [f"b{i}.q[{k}]" for k in range(1, 5)]
        cols += [f"b{i}.{v}[{k}]" for v in ("r", "v", "omega") for k in range(1, 4)]
    return cols


def run_qdot(build, path, stop, backend, columns=None):
    args = [f"{build}/qdot", "run", path, "--stop", repr(stop), "--stats", "-o", os.devnull]
    if columns:
        args += ["--outputs", ",".join(columns)]
    args += ["--backend", "bytecode"] if backend == "bytecode" else ["--backend", "llvm", "--jit-wait"]
    t0 = time.perf_counter()
    p = subprocess.run(args, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"qdot failed:\n{p.stderr}")
    solve = float(re.search(r"solve ([0-9.]+) s", p.stderr).group(1))
    steps = int(re.search(r"\n\s*steps\s+(\d+)", p.stderr).group(1))
    # "compile [ms]: parse …, kernel …, codegen (…) …; total T": the front end to a runnable model
    compile_s = float(re.search(r"compile \[ms\]:.*total ([0-9.]+)", p.stderr).group(1)) / 1000
    return {"wall": wall, "solve": solve, "steps": steps, "compile": compile_s, "log": p.stderr}


def run_reference(build, n, stop):
    with tempfile.NamedTemporaryFile(suffix=".json") as j:
        args = [f"{build}/bench/reference_sim", "bodies", "--n", str(n), "--stop", repr(stop), "-o", os.devnull,
                "--json", j.name]
        t0 = time.perf_counter()
        subprocess.run(args, check=True, capture_output=True)
        wall = time.perf_counter() - t0
        data = json.load(open(j.name))
    return {"wall": wall, "solve": data["solve"], "steps": data["steps"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    o = ap.parse_args()
    sizes = [10, 100] if o.quick else [10, 100, 300]
    repeat = 1 if o.quick else 3
    stop = 2.0
    print("\n## Rigid bodies: n free bodies (bench/rigid_bench.py)\n")
    print(f"stop {stop} s, rtol 1e-6, 500 output rows; hand-written: bench/reference/FreeBodies.cpp on the same IDA settings\n")
    print("Columns: *states* writes what the hand-written program writes (q, r, v, omega of every body);")
    print("*all* adds the body outputs (Euler angles unwrapped along the run, L, energy).\n")
    print("| n | backend | columns | compile [s] | qdot solve [s] | hand solve [s] | solve ratio | qdot whole [s] | hand whole [s] | whole ratio | steps qdot / hand |")
    print("|---:|---|---|---:|---:|---:|---:|---:|---:|---:|---|")
    with tempfile.TemporaryDirectory() as d:
        for n in sizes:
            path = os.path.join(d, f"stack{n}.qd")
            open(path, "w").write(model_text(n))
            ref = best_of(repeat, lambda: run_reference(o.build, n, stop))
            for backend, columns in (("bytecode", "states"), ("llvm", "states"), ("llvm", "all")):
                cols = state_columns(n) if columns == "states" else None
                q = best_of(repeat, lambda: run_qdot(o.build, path, stop, backend, cols))
                print(f"| {n} | {backend} | {columns} | {q['compile']:.3f} | {q['solve']:.3f} | {ref['solve']:.3f} | "
                      f"{q['solve'] / ref['solve']:.2f} | {q['wall']:.3f} | {ref['wall']:.3f} | {q['wall'] / ref['wall']:.2f} | "
                      f"{q['steps']} / {ref['steps']} |")


if __name__ == "__main__":
    main()
