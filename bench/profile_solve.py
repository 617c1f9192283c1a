#!/usr/bin/env python3
"""Where the solve's work goes, qdot's VM against the hand-written programs, in instructions
(valgrind --tool=callgrind: reproducible on a noisy machine). For each case both programs run
once natively (--breakdown: how many residual and Jacobian calls) and once under callgrind with
collection switched on only inside the simulation (rt::simulate, bench::simulateReference: IDA
setup, the consistent start, IDASolve over the grid, writing the rows; not the compiler). The
horizons are those on which both take identical steps, so the differences are evaluation costs.
With --backend llvm the qdot side is `vm_solve --backend llvm` (the JIT); the VM rows are then empty.
Usage: profile_solve.py --build DIR [--quick] [--backend bytecode|llvm]   (from the repository root; a few minutes)"""
import argparse
import json
import os
import re
import subprocess
import sys
import tempfile

# (title, kind, source, n, stop, interval, outputs)
CASES = [
    ("N-link pendulum, dense", "nlink", "examples/pendulum/nlink.qd", 8, 2.5, 0.01, None),
    ("spring chain, KLU", "chain", "examples/vibration/spring_chain.qd", 1000, 10.0, None, ["x[1]", "x[1000]"]),
    ("spring chain, KLU", "chain", "examples/vibration/spring_chain.qd", 10000, 0.5, None, ["x[1]", "x[10000]"]),
]

# Inclusive costs summed per category: (label, hand-written function pattern, qdot function pattern).
CATEGORIES = [
    ("residual (all calls)", r"bench::(NLinkPendulum|SpringChain)::residual\(", r"IdaSession::Impl::evaluateResidual\("),
    ("  of which the VM interpreting bytecode", None, r"qdot::vm::\(anonymous namespace\)::residual\("),
    ("Jacobian (all calls)", r"bench::(NLinkPendulum|SpringChain)::(dense|sparse)Jacobian\(",
     r"IdaSession::Impl::evaluateJacobian\("),
    ("  of which the VM interpreting bytecode", None, r"qdot::vm::\(anonymous namespace\)::jacobian\("),
    ("linear solver: factorisation (SUNLinSolSetup)", r"SUNLinSolSetup_(Dense|KLU)", r"SUNLinSolSetup_(Dense|KLU)"),
    ("linear solver: solves (SUNLinSolSolve)", r"SUNLinSolSolve_(Dense|KLU)", r"SUNLinSolSolve_(Dense|KLU)"),
    ("IDA interpolating y, y' at output times (IDAGetSolution)", r"IDAGetSolution", r"IDAGetSolution"),
    ("writing the CSV rows", r"CsvRows::row\(", r"CsvWriter::row\("),
]


def options(case):
    _, _, _, _, stop, interval, outputs = case
    result = ["--stop", repr(stop), "-o", os.devnull]
    if interval:
        result += ["--interval", repr(interval)]
    if outputs:
        result += ["--outputs", ",".join(outputs)]
    return result


BACKEND = "bytecode"


def commands(build, case, directory):
    title, kind, source, n, *_ = case
    with open(source) as f:
        text = re.sub(r"parameter Integer n = [0-9]+", f"parameter Integer n = {n}", f.read())
    model = os.path.join(directory, f"{kind}{n}.qd")
    with open(model, "w") as f:
        f.write(text)
    hand = [f"{build}/bench/reference_sim", kind, "--n", str(n)] + options(case)
    qdot = [f"{build}/bench/vm_solve", model, "--backend", BACKEND] + options(case)
    return hand, qdot


def native(command, directory):
    path = os.path.join(directory, "calls.json")
    subprocess.run(command + ["--breakdown", "--json", path], check=True, stdout=subprocess.DEVNULL)
    with open(path) as f:
        return json.load(f)


def inclusive_costs(command, toggle, directory):
    """{function: inclusive Ir} of one callgrind run collecting only inside `toggle`."""
    out = os.path.join(directory, "callgrind.out")
    subprocess.run(["valgrind", "--tool=callgrind", f"--toggle-collect={toggle}", f"--callgrind-out-file={out}"]
                   + command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", out], check=True,
                          capture_output=True, text=True).stdout
    costs = {}
    for line in text.splitlines():
        match = re.match(r"\s*([0-9,]+) \([ 0-9.]+%\)\s+\S*?:(.*) \[", line)
        if match:
            costs[match.group(2)] = costs.get(match.group(2), 0) + int(match.group(1).replace(",", ""))
    return costs


def total(costs, pattern):
    if pattern is None:
        return None
    return sum(v for k, v in costs.items() if re.search(pattern, k))


def mega(value):
    return "–" if value is None else f"{value / 1e6:,.1f}"


def print_case(case, hand, qdot, hand_calls, qdot_calls):
    title, _, _, n, stop, *_ = case
    whole_hand = total(hand, r"bench::simulateReference\(")
    whole_qdot = total(qdot, r"qdot::rt::simulate\(")
    print(f"\n#### {title}, n = {n}, stop {stop:g} s ({qdot_calls['steps']} steps either way)\n")
    name = "qdot VM" if BACKEND == "bytecode" else "qdot JIT"
    print(f"| million instructions | hand-written | {name} | qdot − hand | qdot / hand |")
    print("|---|---:|---:|---:|---:|")
    print(f"| **whole simulation** | {mega(whole_hand)} | {mega(whole_qdot)} | {mega(whole_qdot - whole_hand)} "
          f"| **{whole_qdot / whole_hand:.2f}** |")
    rest_hand, rest_qdot = whole_hand, whole_qdot
    for label, hand_pattern, qdot_pattern in CATEGORIES:
        if BACKEND != "bytecode" and "VM interpreting" in label:
            continue
        h, q = total(hand, hand_pattern), total(qdot, qdot_pattern)
        if not label.startswith(" "):
            rest_hand -= h
            rest_qdot -= q
        diff = mega(q - h) if h is not None else "–"
        share = f"{q / h:.2f}" if h else "–"
        print(f"| {label} | {mega(h)} | {mega(q)} | {diff} | {share} |")
    print(f"| IDA itself (vector operations, Newton, error test) and setup | {mega(rest_hand)} | {mega(rest_qdot)} "
          f"| {mega(rest_qdot - rest_hand)} | {rest_qdot / rest_hand:.2f} |")
    for what, key in (("residual", "residual"), ("Jacobian", "jacobian")):
        h = total(hand, CATEGORIES[0 if key == "residual" else 2][1]) / hand_calls["breakdown"][key + "Calls"]
        q = total(qdot, CATEGORIES[0 if key == "residual" else 2][2]) / qdot_calls["breakdown"][key + "Calls"]
        print(f"| instructions per {what} call | {h:,.0f} | {q:,.0f} | | {q / h:.1f} |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--quick", action="store_true", help="the N-link pendulum only")
    parser.add_argument("--backend", default="bytecode", choices=["bytecode", "llvm"])
    parser.add_argument("--max-n", type=int, default=None, help="only cases with n up to this")
    args = parser.parse_args()
    global BACKEND
    BACKEND = args.backend
    which = "VM" if BACKEND == "bytecode" else "LLVM JIT"
    print(f"\n### Profile: instructions inside the simulation (callgrind), qdot {which}")
    with tempfile.TemporaryDirectory(prefix="qdot-profile-") as directory:
        for case in CASES[:1] if args.quick else [c for c in CASES if args.max_n is None or c[3] <= args.max_n]:
            hand_cmd, qdot_cmd = commands(args.build, case, directory)
            hand_calls, qdot_calls = native(hand_cmd, directory), native(qdot_cmd, directory)
            if (hand_calls["steps"], hand_calls["residuals"]) != (qdot_calls["steps"], qdot_calls["residuals"]):
                sys.exit(f"profile_solve: {case[0]} n = {case[3]}: the step sequences differ; shorten the horizon")
            hand = inclusive_costs(hand_cmd, "qdot::bench::simulateReference*", directory)
            qdot = inclusive_costs(qdot_cmd, "qdot::rt::simulate*", directory)
            print_case(case, hand, qdot, hand_calls, qdot_calls)
            sys.stdout.flush()


if __name__ == "__main__":
    main()
