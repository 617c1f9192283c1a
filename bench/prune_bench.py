#!/usr/bin/env python3
"""--outputs pruning (issue 10 §4): a pendulum beside a large, unrelated spring chain, asked for the
pendulum's angle only, against the pendulum alone and against the whole model. Whole process
(`qdot run --backend bytecode`, compile and solve), best of R runs; one command, ratios in one table.

    bench/prune_bench.py --build build [--quick]
"""
import argparse
import os
import subprocess
import tempfile
import time

PENDULUM = """  parameter Real g = 9.81, l = 1;
  coordinate Real th(start = 0.5);
"""
PENDULUM_ENERGY = "  kinetic = 0.5*l^2*der(th)^2;\n  potential = -g*l*cos(th);\n"


def model(n):
    chain = "" if n == 0 else f"""  parameter Integer n = {n};
  coordinate Real x[n](start = {{0.01*i for i in 1:n}});
"""
    chain_energy = "" if n == 0 else """  kinetic = sum(0.5*der(x[i])^2 for i in 1:n);
  potential = 0.5*100*x[1]^2 + sum(0.5*100*(x[i] - x[i-1])^2 for i in 2:n);
  dissipation = sum(0.5*(der(x[i]))^2 for i in 1:n);
"""
    return f"model P\n{PENDULUM}{chain}mechanics\n{PENDULUM_ENERGY}{chain_energy}end P;\n"


def best(cmd, repeat):
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        times.append(time.perf_counter() - t0)
        if out.returncode != 0:
            raise SystemExit(f"failed: {' '.join(cmd)}\n{out.stderr}")
    return min(times), out.stdout


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    a = ap.parse_args()
    qdot = os.path.join(a.build, "qdot")
    sizes = [1000] if a.quick else [1000, 10000]
    repeat = 1 if a.quick else 3
    run = ["run", "--backend", "bytecode", "--stop", "10", "--interval", "0.02"]
    print("\n## --outputs: only what the requested results need (`bench/prune_bench.py`)\n")
    print(f"A pendulum beside an unrelated damped spring chain of n masses, 0..10 s, whole `qdot run` process "
          f"(compile and solve, VM), best of {repeat}.\n")
    print("| n | pendulum alone [s] | with the chain, `--outputs th` [s] | with the chain, everything [s] | "
          "pruned / alone | whole / alone | th identical |")
    print("|---:|---:|---:|---:|---:|---:|---|")
    with tempfile.TemporaryDirectory() as d:
        alone = os.path.join(d, "alone.qd")
        open(alone, "w").write(model(0))
        t_alone, out_alone = best([qdot, *run, alone, "--outputs", "th"], repeat)
        for n in sizes:
            both = os.path.join(d, f"both{n}.qd")
            open(both, "w").write(model(n))
            t_pruned, out_pruned = best([qdot, *run, both, "--outputs", "th"], repeat)
            t_whole, _ = best([qdot, *run, both, "-o", os.path.join(d, "whole.csv")], repeat)
            print(f"| {n} | {t_alone:.3f} | {t_pruned:.3f} | {t_whole:.3f} | {t_pruned / t_alone:.2f} | "
                  f"{t_whole / t_alone:.1f} | {'yes' if out_pruned == out_alone else 'no'} |")


if __name__ == "__main__":
    main()
