#!/usr/bin/env python3
"""Components benchmark (issue 9 §5): a chain of n `Vibration.Mass`/`Vibration.Spring` components
against the equivalent flat `mechanics` model, side by side, printed as markdown tables.

Both models are generated here for each n (the same masses, springs and wall):
  * compile: `eval_bench --no-llvm --no-eval` (driver::compileFile to the kernels, then the bytecode
    and the VM model, per-stage times from driver::Compilation::times), once per fresh process,
    REPEAT processes, the best time per stage; peak memory is the process's maximum resident set
    (os.wait4), the smallest of the REPEAT;
  * simulate: `vm_solve` (qdot run --backend bytecode in one process) on both, best solve of
    REPEAT, IDA's counters, and the largest difference of the last mass's position between the two
    CSV files (the same trajectory to within the tolerances).
Usage: component_bench.py --build DIR [--quick]   (from the repository root)"""
import argparse
import csv
import json
import os
import subprocess
import sys
import tempfile

COMPONENT = """model ComponentChain "n Vibration.Mass and Vibration.Spring components, the first spring on a wall"
  import Vibration.*;
  parameter Integer n = {n};
  Mass ms[n](m = fill(1, n){mass_start});
  Spring ks[n](k = fill(100, n));
  Fixed wall;
equation
  connect(wall.a, ks[1].a);
  connect(ks[1].b, ms[1].a);
  for i in 2:n loop
    connect(ms[i-1].b, ks[i].a);
    connect(ks[i].b, ms[i].a);
  end for;
end ComponentChain;
"""

FLAT = """model FlatChain "the same chain as one mechanics model"
  parameter Integer n = {n};
  parameter Real m[n] = fill(1, n), k[n] = fill(100, n);
  coordinate Real x[n]{start};
mechanics
  kinetic = sum(0.5*m[i]*der(x[i])^2 for i in 1:n);
  potential = 0.5*k[1]*x[1]^2 + sum(0.5*k[i]*(x[i] - x[i-1])^2 for i in 2:n);
end FlatChain;
"""

STAGES = ("parse+check", "flatten", "derive", "dae", "kernel", "bytecode")


def write_models(n, directory, moving):
    """The component chain and the flat chain of size n: {kind: (path, last mass's CSV column)}.
    At rest unless `moving` (start positions 0.01 i: the springs stretched, the chain released).
    The compile benchmark leaves the start values out: an array modifier on an array of components
    (`ms[n](s(start = {...}))`) is expanded once per element, O(n²) (README, Components)."""
    start = "{0.01*i for i in 1:n}"
    text = {"component": COMPONENT.format(n=n, mass_start=f", s(start = {start})" if moving else ""),
            "flat": FLAT.format(n=n, start=f"(start = {start})" if moving else "")}
    models = {}
    for kind, last in (("component", f"ms[{n}].s"), ("flat", f"x[{n}]")):
        path = os.path.join(directory, f"{kind}{n}.qd")
        with open(path, "w") as f:
            f.write(text[kind])
        models[kind] = (path, last)
    return models


def run(command):
    """Runs a command; exits on failure."""
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if done.returncode != 0:
        sys.exit(f"component_bench: {' '.join(command)} failed:\n{done.stderr}")


def compile_once(build, path):
    """One eval_bench process: its stage times and its peak resident set [MB] (wait4 gives the
    child's own maximum; RUSAGE_CHILDREN would be the maximum over all children so far)."""
    command = [f"{build}/bench/eval_bench", path, "--no-llvm", "--no-eval"]
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: becomes eval_bench, its stdout the pipe
        os.close(read)
        os.dup2(write, 1)
        try:
            os.execv(command[0], command)
        finally:
            os._exit(127)
    os.close(write)
    with os.fdopen(read) as f:
        out = f.read()
    _, status, usage = os.wait4(pid, 0)
    if status != 0:
        sys.exit(f"component_bench: {' '.join(command)} failed (status {status})")
    result = json.loads(out)
    result["peakMB"] = usage.ru_maxrss / 1024  # Linux: kilobytes
    return result


def compile_times(build, path, repeat):
    """Best time per stage of `repeat` fresh processes, the unknowns and the smallest peak memory."""
    best = None
    for _ in range(repeat):
        r = compile_once(build, path)
        s = r["stages"]
        sample = {"parse+check": s["parse"] + s["check"], "flatten": s["flatten"], "derive": s["derive"],
                  "dae": s["dae"], "kernel": s["kernel"], "bytecode": s["bytecode"], "peakMB": r["peakMB"],
                  "variables": r["variables"]}
        best = sample if best is None else {k: min(best[k], sample[k]) for k in sample}
    best["total"] = sum(best[stage] for stage in STAGES)
    return best


def ratio(a, b):
    return f"{a / b:.2f}" if b else "–"


def print_compile_table(rows, repeat):
    print(f"\n### Compile: component chain vs flat chain (parse → kernels and bytecode; best per stage "
          f"of {repeat} fresh processes)\n")
    print("| n | model | unknowns | " + " | ".join(f"{s} [ms]" for s in STAGES) + " | **total [ms]** | peak memory [MB] |")
    print("|---:|---|---:|" + "---:|" * len(STAGES) + "---:|---:|")
    for n, comp, flat in rows:
        for kind, r in (("component", comp), ("flat", flat)):
            cells = " | ".join(f"{r[s] * 1e3:.1f}" for s in STAGES)
            print(f"| {n if kind == 'component' else ''} | {kind} | {r['variables']} | {cells} "
                  f"| **{r['total'] * 1e3:.1f}** | {r['peakMB']:.0f} |")
        cells = " | ".join(ratio(comp[s], flat[s]) for s in STAGES)
        print(f"| | **ratio** | {ratio(comp['variables'], flat['variables'])} | {cells} "
              f"| **{ratio(comp['total'], flat['total'])}** | {ratio(comp['peakMB'], flat['peakMB'])} |")
        sys.stdout.flush()


def last_column(path):
    with open(path) as f:
        return [(float(row[0]), float(row[-1])) for row in list(csv.reader(f))[1:]]


def simulate(build, models, stop, repeat, directory):
    """vm_solve on both models: {kind: JSON result}, and max |difference| of the last mass's position."""
    results, columns = {}, {}
    for kind, (path, last) in models.items():
        out, result = os.path.join(directory, f"{kind}.csv"), os.path.join(directory, f"{kind}.json")
        run([f"{build}/bench/vm_solve", path, "--stop", repr(stop), "--outputs", last, "-o", out,
                      "--repeat", str(repeat), "--json", result])
        with open(result) as f:
            results[kind] = json.load(f)
        columns[kind] = last_column(out)
    comp, flat = columns["component"], columns["flat"]
    if [t for t, _ in comp] != [t for t, _ in flat]:
        sys.exit("component_bench: the two runs wrote different output times")
    difference = max(abs(a - b) for (_, a), (_, b) in zip(comp, flat))
    return results, difference


def print_simulation_table(n, stop, results, difference, repeat):
    print(f"\n### Simulation: the same chain, n = {n}, 0..{stop:g} s, `qdot run --backend bytecode` "
          f"(vm_solve, best solve of {repeat})\n")
    print("| model | solve [ms] | steps | residual evals | Jacobian evals | error-test failures | µs per step |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for kind in ("component", "flat"):
        r = results[kind]
        print(f"| {kind} | {r['solve'] * 1e3:.1f} | {r['steps']} | {r['residuals']} | {r['jacobians']} "
              f"| {r['errorTestFailures']} | {r['solve'] / r['steps'] * 1e6:.1f} |")
    comp, flat = results["component"], results["flat"]
    print(f"| **ratio** | **{ratio(comp['solve'], flat['solve'])}** | {ratio(comp['steps'], flat['steps'])} "
          f"| {ratio(comp['residuals'], flat['residuals'])} | {ratio(comp['jacobians'], flat['jacobians'])} | "
          f"| {ratio(comp['solve'] / comp['steps'], flat['solve'] / flat['steps'])} |")
    print(f"\nLargest difference of the last mass's position between the two runs over {comp['rows']} rows: "
          f"{difference:.2g} m (start values up to {0.01 * n:g} m; rtol 1e-6).")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="build directory (default: build)")
    parser.add_argument("--quick", action="store_true", help="small n, one repetition")
    args = parser.parse_args()
    repeat = 1 if args.quick else 3
    sizes = [100, 1000] if args.quick else [1000, 10000, 100000]
    budget = 60  # seconds for the largest size's compile runs; larger sizes are skipped beyond it
    sim_n, sim_stop = (100, 2.0) if args.quick else (1000, 10.0)
    print("\n## Components: a chain of Vibration.Mass/Spring components against the flat mechanics model\n")
    with tempfile.TemporaryDirectory(prefix="qdot-component-bench-") as directory:
        rows = []
        for n in sizes:
            models = write_models(n, directory, moving=False)
            comp = compile_times(args.build, models["component"][0], repeat)
            flat = compile_times(args.build, models["flat"][0], repeat)
            rows.append((n, comp, flat))
            # growth is about linear: the next size (10×) would take 10× these runs
            if 10 * repeat * (comp["total"] + flat["total"]) > budget:
                break
        print_compile_table(rows, repeat)
        results, difference = simulate(args.build, write_models(sim_n, directory, moving=True), sim_stop, repeat, directory)
        print_simulation_table(sim_n, sim_stop, results, difference, repeat)


if __name__ == "__main__":
    main()
