#!/usr/bin/env python3
"""Simulation benchmark: `qdot run --backend bytecode` against hand-written SUNDIALS IDA programs
(bench/reference/, run by reference_sim) on identical settings, printed as markdown tables.

For each case the model file is written with `parameter Integer n` set, then
  * check_reference has already compared the hand-written residual and Jacobian with qdot's;
  * reference_sim and vm_solve (qdot's own pipeline and runtime in one process, see vm_solve.cpp)
    each simulate it REPEAT times in one process: the best solve time, IDA's counters; then once
    more with the residual and Jacobian timed (--breakdown);
  * `qdot run --stats` runs REPEAT times as a command: compile time, its own solve time (rounded
    to ms), the counters (which must equal vm_solve's) and the whole command's wall time;
  * reference_sim runs REPEAT times as a command for its whole wall time.
Usage: sim_bench.py --build DIR [--quick]   (from the repository root)"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time

PENDULUM = "examples/pendulum/nlink.qd"
CHAIN = "examples/vibration/spring_chain.qd"


class Case:
    def __init__(self, title, kind, source, n, stop, interval=None, outputs=None):
        self.title, self.kind, self.source, self.n = title, kind, source, n
        self.stop, self.interval, self.outputs = stop, interval, outputs

    def run_options(self):
        """The options shared by qdot run, vm_solve and reference_sim."""
        options = ["--stop", repr(self.stop), "-o", os.devnull]
        if self.interval:
            options += ["--interval", repr(self.interval)]
        if self.outputs:
            options += ["--outputs", ",".join(self.outputs)]
        return options


def cases(quick):
    pendulum = Case("N-link pendulum, dense", "nlink", PENDULUM, 8, 10.0, 0.01)
    chain1k = Case("spring chain, KLU", "chain", CHAIN, 1000, 40.0, outputs=["x[1]", "x[1000]"])
    if quick:
        return [pendulum, chain1k, Case("spring chain, KLU", "chain", CHAIN, 10000, 2.0, outputs=["x[1]", "x[10000]"])]
    return [pendulum, chain1k, Case("spring chain, KLU", "chain", CHAIN, 100000, 0.5, outputs=["x[1]", "x[100000]"])]


def agreement_cases():
    """Short horizons on which the step sequences must be identical (see bench/README.md)."""
    return [Case("N-link pendulum, dense", "nlink", PENDULUM, 8, 2.5, 0.01),
            Case("spring chain, KLU", "chain", CHAIN, 1000, 20.0, outputs=["x[1]", "x[1000]"])]


def sized_model(case, directory):
    with open(case.source) as f:
        text = f.read()
    text = re.sub(r"parameter Integer n = [0-9]+", f"parameter Integer n = {case.n}", text)
    path = os.path.join(directory, f"{case.kind}{case.n}.qd")
    with open(path, "w") as f:
        f.write(text)
    return path


def run(command):
    """Runs a command; returns (wall seconds, stderr). Exits on failure."""
    start = time.perf_counter()
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        sys.exit(f"sim_bench: {' '.join(command)} failed:\n{done.stderr}")
    return wall, done.stderr


def in_process(command, repeat, directory):
    """reference_sim or vm_solve with --repeat and --json: their JSON result."""
    result = os.path.join(directory, "result.json")
    run(command + ["--repeat", str(repeat), "--breakdown", "--json", result])
    with open(result) as f:
        return json.load(f)


def number(pattern, text):
    match = re.search(pattern, text)
    if not match:
        sys.exit(f"sim_bench: '{pattern}' not found in:\n{text}")
    return match.group(1)


def qdot_command(build, model, case, repeat):
    """`qdot run --stats` repeat times: best wall, compile and solve, and the counters."""
    best = None
    for _ in range(repeat):
        wall, log = run([f"{build}/qdot", "run", model, "--backend", "bytecode", "--stats"] + case.run_options())
        # "compile [ms]: parse 0.05, check 0.01, ..., kernel 2.7, codegen (bytecode) 0.18"
        stages = number(r"compile \[ms\]: (.*)", log).split(";")[0].split(",")
        compile_ms = sum(float(stage.split()[-1]) for stage in stages)
        sample = {"wall": wall, "compile": compile_ms / 1e3,
                  "setup": float(number(r"wall time +setup ([0-9.]+) s", log)),
                  "solve": float(number(r"solve ([0-9.]+) s", log)),
                  "steps": int(number(r"steps +([0-9]+)", log)),
                  "residuals": int(number(r"residual evaluations +([0-9]+)", log)),
                  "jacobians": int(number(r"Jacobian evaluations +([0-9]+)", log))}
        if best is None:
            best = sample
        else:
            for key in ("wall", "compile", "setup", "solve"):
                best[key] = min(best[key], sample[key])
    return best


def reference_command(build, case, repeat):
    """The whole reference_sim command's best wall time."""
    command = [f"{build}/bench/reference_sim", case.kind, "--n", str(case.n)] + case.run_options()
    return min(run(command)[0] for _ in range(repeat))


def measure(build, case, repeat, directory, whole_commands=True):
    model = sized_model(case, directory)
    hand = in_process([f"{build}/bench/reference_sim", case.kind, "--n", str(case.n)] + case.run_options(),
                      repeat, directory)
    vm = in_process([f"{build}/bench/vm_solve", model] + case.run_options(), repeat, directory)
    # The atol agree to rounding, not bit for bit: the velocities' scales follow the lowest frequency
    # of each program's own linearization at the start (docs/accuracy.md), whose Jacobians agree to
    # rounding (check_reference).
    for key in ("atolMin", "atolMedian", "atolMax"):
        if abs(hand[key] - vm[key]) > 1e-12 * abs(vm[key]):
            sys.exit(f"sim_bench: {case.title} n = {case.n}: {key} differs ({hand[key]} vs {vm[key]})")
    for key in ("rows", "calcIC"):
        if hand[key] != vm[key]:
            sys.exit(f"sim_bench: {case.title} n = {case.n}: {key} differs ({hand[key]} vs {vm[key]})")
    cli = qdot_command(build, model, case, repeat) if whole_commands else None
    if cli and (cli["steps"], cli["residuals"]) != (vm["steps"], vm["residuals"]):
        sys.exit(f"sim_bench: qdot run and vm_solve disagree on the counters for {case.title} n = {case.n}")
    hand_wall = reference_command(build, case, repeat) if whole_commands else None
    return hand, vm, cli, hand_wall


def ratio(a, b):
    return f"{a / b:.2f}" if b else "–"


def model_time(result):
    """Seconds per residual and Jacobian call (timed run), the model's share of the best solve
    (per-call times x IDA's counts of the integration) and the rest."""
    b = result["breakdown"]
    per_f, per_j = b["residualSeconds"] / b["residualCalls"], b["jacobianSeconds"] / b["jacobianCalls"]
    model = per_f * result["residuals"] + per_j * result["jacobians"]
    return {"F": per_f, "J": per_j, "model": model, "rest": result["solve"] - model}


def print_tables(results, repeat):
    print(f"\n### Solve time: qdot VM / hand-written (best of {repeat}; solve = IDASolve over the output grid "
          "plus writing the rows)\n")
    print("| case | n | unknowns | stop [s] | rows | hand-written [ms] | qdot VM [ms] | **solve ratio** "
          "| steps ratio | residual evals ratio | Jacobian evals ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for case, hand, vm, _, _ in results:
        print(f"| {case.title} | {case.n} | {2 * case.n} | {case.stop:g} | {hand['rows']} | {hand['solve'] * 1e3:.1f} "
              f"| {vm['solve'] * 1e3:.1f} | **{ratio(vm['solve'], hand['solve'])}** | {ratio(vm['steps'], hand['steps'])} "
              f"| {ratio(vm['residuals'], hand['residuals'])} | {ratio(vm['jacobians'], hand['jacobians'])} |")

    print("\n### IDA counters: hand-written / qdot, and the solve time per step\n")
    print("| case | n | steps | residual evals | Jacobian evals | nonlinear iterations | error-test failures "
          "| hand-written [µs/step] | qdot VM [µs/step] |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for case, hand, vm, _, _ in results:
        pair = lambda key: f"{hand[key]} / {vm[key]}"
        print(f"| {case.title} | {case.n} | {pair('steps')} | {pair('residuals')} | {pair('jacobians')} "
              f"| {pair('iterations')} | {pair('errorTestFailures')} | {hand['solve'] / hand['steps'] * 1e6:.1f} "
              f"| {vm['solve'] / vm['steps'] * 1e6:.1f} |")

    print("\n### Where the solve time goes (wall clock, one more run with the model's functions timed)\n")
    print("| case | n | residual [µs/call] hand / qdot | ratio | Jacobian [µs/call] hand / qdot | ratio "
          "| F and J in the solve [ms] hand / qdot | rest of the solve (IDA, linear solver, rows) [ms] hand / qdot |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for case, hand, vm, _, _ in results:
        h, q = model_time(hand), model_time(vm)
        print(f"| {case.title} | {case.n} | {h['F'] * 1e6:.2f} / {q['F'] * 1e6:.2f} | {ratio(q['F'], h['F'])} "
              f"| {h['J'] * 1e6:.1f} / {q['J'] * 1e6:.1f} | {ratio(q['J'], h['J'])} "
              f"| {h['model'] * 1e3:.1f} / {q['model'] * 1e3:.1f} | {h['rest'] * 1e3:.1f} / {q['rest'] * 1e3:.1f} |")

    print(f"\n### Whole commands (best of {repeat}): `qdot run --backend bytecode --stats` and `reference_sim`\n")
    print("| case | n | qdot compile [ms] | qdot setup [s] | qdot solve [s] (--stats) | qdot total wall [s] "
          "| reference_sim total wall [s] | total ratio |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for case, _, _, cli, hand_wall in results:
        print(f"| {case.title} | {case.n} | {cli['compile'] * 1e3:.1f} | {cli['setup']:.3f} | {cli['solve']:.3f} "
              f"| {cli['wall']:.3f} | {hand_wall:.3f} | {ratio(cli['wall'], hand_wall)} |")


def print_agreement(build, repeat, directory):
    print("\n### Step-for-step agreement on shorter horizons (hand-written / qdot)\n")
    print("| case | n | stop [s] | steps | residual evals | Jacobian evals | error-test failures | identical |")
    print("|---|---:|---:|---:|---:|---:|---:|---|")
    for case in agreement_cases():
        hand, vm, _, _ = measure(build, case, 1, directory, whole_commands=False)
        keys = ("steps", "residuals", "jacobians", "errorTestFailures")
        same = all(hand[k] == vm[k] for k in keys)
        cells = " | ".join(f"{hand[k]} / {vm[k]}" for k in keys)
        print(f"| {case.title} | {case.n} | {case.stop:g} | {cells} | {'yes' if same else '**no**'} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="build directory (default: build)")
    parser.add_argument("--quick", action="store_true", help="smaller chain, one repetition")
    args = parser.parse_args()
    repeat = 1 if args.quick else 3
    print("\n## Simulation: qdot run --backend bytecode against hand-written IDA programs\n")
    print("Hand-written residuals and Jacobians against qdot's at random states (`check_reference`):\n")
    sys.stdout.flush()
    if subprocess.run([f"{args.build}/bench/check_reference"]).returncode != 0:
        sys.exit("sim_bench: the hand-written models do not match qdot's; no timings")
    with tempfile.TemporaryDirectory(prefix="qdot-sim-bench-") as directory:
        results = []
        for case in cases(args.quick):
            hand, vm, cli, hand_wall = measure(args.build, case, repeat, directory)
            results.append((case, hand, vm, cli, hand_wall))
        print_tables(results, repeat)
        print_agreement(args.build, repeat, directory)


if __name__ == "__main__":
    main()
