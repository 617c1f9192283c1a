#!/usr/bin/env python3
"""LLVM JIT benchmark: `qdot run --backend llvm` against the hand-written IDA programs and the VM,
printed as markdown tables (bench/README.md, section "The LLVM JIT backend").

  1. solve and total time against reference_sim (same cases and settings as sim_bench.py);
  2. residual and Jacobian ns per call, JIT vs VM, on a fixed state (eval_bench), and with
     --profile the same as callgrind instruction counts per call;
  3. compile latency stage by stage, file to first step;
  4. compile and solve time against n, both backends, with growth exponents;
  5. whole `qdot run` wall time for short runs (U-tube, N-link n = 8): where the VM wins.
Usage: jit_bench.py --build DIR [--quick] [--profile]   (from the repository root)"""
import argparse
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(__file__))
from sim_bench import CHAIN, PENDULUM, Case, number, run, sized_model  # noqa: E402

UTUBE = "examples/textbook/utube.qd"


def main_cases(quick):
    pendulum = Case("N-link pendulum, dense", "nlink", PENDULUM, 8, 10.0, 0.01)
    chain1k = Case("spring chain, KLU", "chain", CHAIN, 1000, 40.0, outputs=["x[1]", "x[1000]"])
    big = (Case("spring chain, KLU", "chain", CHAIN, 10000, 2.0, outputs=["x[1]", "x[10000]"]) if quick else
           Case("spring chain, KLU", "chain", CHAIN, 100000, 0.5, outputs=["x[1]", "x[100000]"]))
    return [pendulum, chain1k, big]


def json_of(command, directory):
    path = os.path.join(directory, "result.json")
    run(command + ["--json", path])
    with open(path) as f:
        return json.load(f)


def solve_run(build, model, case, backend, repeat, directory):
    """vm_solve --backend: best solve of `repeat`, counters, compile stages (one compile)."""
    return json_of([f"{build}/bench/vm_solve", model, "--backend", backend, "--repeat", str(repeat)]
                   + case.run_options(), directory)


def reference_run(build, case, repeat, directory):
    return json_of([f"{build}/bench/reference_sim", case.kind, "--n", str(case.n), "--repeat", str(repeat)]
                   + case.run_options(), directory)


MODES = {"bytecode": ["--backend", "bytecode"], "llvm": ["--backend", "llvm", "--jit-wait"], "default": []}


def qdot_wall(build, model, options, mode, repeat):
    """`qdot run --stats` as a command: best wall, compile [s] and solve [s] (--stats). mode: bytecode (the
    VM only), llvm (the JIT, compiled before the first step: --jit-wait) or default (VM, then JIT)."""
    best = None
    for _ in range(repeat):
        wall, log = run([f"{build}/qdot", "run", model, "--stats"] + MODES[mode] + options)
        stages = number(r"compile \[ms\]: (.*)", log).split(";")[0].split(",")
        sample = {"wall": wall, "compile": sum(float(s.split()[-1]) for s in stages) / 1e3,
                  "solve": float(number(r"solve ([0-9.]+) s", log)),
                  "setup": float(number(r"wall time +setup ([0-9.]+) s", log)),
                  "steps": int(number(r"steps +([0-9]+)", log))}
        best = sample if best is None else {k: min(best[k], sample[k]) for k in sample}
    return best


def eval_bench(build, model, directory, *extra):
    out = subprocess.run([f"{build}/bench/eval_bench", model, *extra], capture_output=True, text=True)
    if out.returncode != 0:
        sys.exit(f"jit_bench: eval_bench {model} failed:\n{out.stderr}")
    return json.loads(out.stdout)


def exponent(x0, y0, x1, y1):
    if min(x0, y0, x1, y1) <= 0:
        return "–"
    return f"{math.log(y1 / y0) / math.log(x1 / x0):.2f}"


def ratio(a, b):
    return f"{a / b:.2f}" if b else "–"


def table_against_hand(build, quick, repeat, directory):
    print(f"\n### JIT against the hand-written programs (best of {repeat}; settings as the VM comparison)\n")
    print("| case | n | hand-written solve [ms] | JIT solve [ms] | **solve ratio** (≤ 1.15) | steps hand / JIT "
          "| JIT µs/step ÷ hand µs/step | JIT compile [s] | JIT setup [s] | `qdot run --jit-wait` wall [s] "
          "| `qdot run` (default) wall [s] | reference_sim wall [s] | **total ratio** wait / default (≤ 1.5 if ≥ 1 s) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    results = {}
    for case in main_cases(quick):
        model = sized_model(case, directory)
        hand = reference_run(build, case, repeat, directory)
        jit = solve_run(build, model, case, "llvm", repeat, directory)
        for key in ("atolMin", "atolMedian", "atolMax", "rows", "calcIC"):
            if hand[key] != jit[key]:
                sys.exit(f"jit_bench: {case.title} n = {case.n}: {key} differs ({hand[key]} vs {jit[key]})")
        cli = qdot_wall(build, model, case.run_options(), "llvm", repeat)
        tiered = qdot_wall(build, model, case.run_options(), "default", repeat)
        if cli["steps"] != jit["steps"]:
            sys.exit(f"jit_bench: qdot run and vm_solve --backend llvm disagree on steps for {case.title}")
        hand_wall = min(run([f"{build}/bench/reference_sim", case.kind, "--n", str(case.n)] + case.run_options())[0]
                        for _ in range(repeat))
        per_step = (jit["solve"] / jit["steps"]) / (hand["solve"] / hand["steps"])
        print(f"| {case.title} | {case.n} | {hand['solve'] * 1e3:.1f} | {jit['solve'] * 1e3:.1f} "
              f"| **{ratio(jit['solve'], hand['solve'])}** | {hand['steps']} / {jit['steps']} | {per_step:.2f} "
              f"| {cli['compile']:.3f} | {cli['setup']:.3f} | {cli['wall']:.3f} | {tiered['wall']:.3f} | {hand_wall:.3f} "
              f"| **{ratio(cli['wall'], hand_wall)} / {ratio(tiered['wall'], hand_wall)}** |")
        sys.stdout.flush()
        results[(case.kind, case.n)] = (case, jit)
    return results


def table_eval(build, quick, profile, directory, solved):
    print("\n### Residual and Jacobian evaluation: JIT vs VM (ns per call on one fixed state, best of 3 batches)\n")
    print("Residual at codegen level 2, Jacobian at level 0 (the defaults, compiler/llvm/README.md). "
          "*Per solve*: residual + Jacobian time of one simulation, each call count as IDA made them in the "
          "first table (residuals / Jacobians), VM time ÷ JIT time.\n")
    print("| model | n | unknowns | Jacobian nonzeros | residual VM [ns] | residual JIT [ns] | **speed-up** "
          "| Jacobian VM [ns] | Jacobian JIT [ns] | **speed-up** | calls res. / Jac. | **per solve** (≥ 5) "
          "| max \\|F_VM − F_JIT\\| | max \\|J_VM − J_JIT\\| |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    cases = [("N-link pendulum", PENDULUM, "nlink", 8), ("spring chain", CHAIN, "chain", 1000)]
    models = []
    for title, source, kind, n in cases:
        model = sized_model(Case(title, kind, source, n, 1.0), directory)
        models.append((title, model, n))
        r = eval_bench(build, model, directory, "--min-time", "0.05" if quick else "0.2")
        f, j = r["residualNs"], r["jacobianNs"]
        counts = solved.get((kind, n), (None, None))[1]
        if counts:
            nf, nj = counts["residuals"], counts["jacobians"]
            weighted = ratio(nf * f["bytecode"] + nj * j["bytecode"], nf * f["llvm"] + nj * j["llvm"])
            calls = f"{nf} / {nj}"
        else:
            weighted, calls = "–", "–"
        print(f"| {title} | {n} | {r['variables']} | {r['nonzeros']} | {f['bytecode']:.0f} | {f['llvm']:.0f} "
              f"| **{ratio(f['bytecode'], f['llvm'])}** | {j['bytecode']:.0f} | {j['llvm']:.0f} "
              f"| **{ratio(j['bytecode'], j['llvm'])}** | {calls} | **{weighted}** "
              f"| {r['maxDiffF']:.1e} | {r['maxDiffJ']:.1e} |")
        sys.stdout.flush()
    if not profile:
        return
    print("\nThe same in instructions per call (callgrind, inclusive, `eval_bench --calls N`):\n")
    print("| model | n | calls | residual VM | residual JIT | **ratio** | Jacobian VM | Jacobian JIT | **ratio** |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for title, model, n in models:
        calls = 2000 if n < 100 else 200
        out = os.path.join(directory, "callgrind.out")
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", f"{build}/bench/eval_bench",
                        model, "--calls", str(calls)], capture_output=True, check=True)
        ann = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--threshold=100", out], capture_output=True,
                             text=True, check=True).stdout
        counts = {}
        for name in ("evalVmResidual", "evalJitResidual", "evalVmJacobian", "evalJitJacobian"):
            match = re.search(r"^\s*([0-9,]+) \([^)]*\)\s+\S*:" + name + r"\s", ann, re.M) or \
                re.search(r"^\s*([0-9,]+)\s.*\b" + name + r"\b", ann, re.M)
            counts[name] = int(match.group(1).replace(",", "")) / calls if match else float("nan")
        c = counts
        print(f"| {title} | {n} | {calls} | {c['evalVmResidual']:,.0f} | {c['evalJitResidual']:,.0f} "
              f"| **{ratio(c['evalVmResidual'], c['evalJitResidual'])}** | {c['evalVmJacobian']:,.0f} "
              f"| {c['evalJitJacobian']:,.0f} | **{ratio(c['evalVmJacobian'], c['evalJitJacobian'])}** |")
        sys.stdout.flush()


def table_latency(build, quick, repeat, directory, solved):
    print(f"\n### Compile latency with the JIT: file to first step (best of {repeat} per stage, in one process)\n")
    print("| model | n | kernel instr. | LLVM functions | parse | check | flatten | derive | dae | kernel "
          "| JIT lower | JIT codegen | **compile** | setup (IDA, IDACalcIC) | **file to first step** | target "
          "| for comparison: bytecode codegen |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|")
    big = 10000 if quick else 100000
    for title, source, kind, n, target in (("N-link pendulum", PENDULUM, "nlink", 8, 0.05),
                                             ("spring chain", CHAIN, "chain", big, 5.0)):
        model = sized_model(Case(title, kind, source, n, 1.0), directory)
        r = eval_bench(build, model, directory, "--no-eval", "--repeat", str(repeat if n < 100000 else 1))
        s = r["stages"]
        setup = solved[(kind, n)][1]["setup"] if (kind, n) in solved else float("nan")
        first = r["compileLlvm"] + setup
        ms = lambda x: f"{x * 1e3:.1f}" if x < 1 else f"{x:.2f} s"
        print(f"| {title} | {n} | {r['instructions']:,} | {r['functions']} | {ms(s['parse'])} | {ms(s['check'])} "
              f"| {ms(s['flatten'])} | {ms(s['derive'])} | {ms(s['dae'])} | {ms(s['kernel'])} | {ms(s['llvmLower'])} "
              f"| {ms(s['llvmCodegen'])} | **{ms(r['compileLlvm'])}** | {ms(setup)} | **{ms(first)}** "
              f"| < {ms(target)}: {'met' if first < target else '**missed**'} | {ms(s['bytecode'])} |")
        sys.stdout.flush()
    print("\n(times in ms unless marked s; `qdot` itself also pays its process start, see the last table)")


def table_scaling(build, quick, directory, solved):
    chain_ns = [10, 100, 1000, 10000] if quick else [10, 100, 1000, 10000, 100000]
    nlink_ns = [2, 4, 8, 16] if quick else [2, 4, 8, 16, 32, 64]
    sets = [("spring chain (KLU), stop 0.5 s, interval 0.001 s, columns x[1], x[n]", CHAIN, "chain", chain_ns),
            ("N-link pendulum (dense), stop 1 s, interval 0.01 s, all columns", PENDULUM, "nlink", nlink_ns)]
    for title, source, kind, ns in sets:
        print(f"\n### Scaling: {title}\n")
        print("Compile = parse .. codegen in one process (best of 3, 1 at n = 100 000); solve = best of 3 "
              "(1 at n = 100 000); exponent = growth from the previous row.\n")
        print("| n | kernel instr. | compile VM [s] | compile JIT [s] | exp. VM | exp. JIT | JIT codegen [s] "
              "| steps VM / JIT | solve VM [s] | solve JIT [s] | exp. VM | exp. JIT | solve VM / JIT |")
        print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        prev = None
        for n in ns:
            case = (Case(title, kind, source, n, 0.5, 0.001, outputs=["x[1]", f"x[{n}]"]) if kind == "chain" else
                    Case(title, kind, source, n, 1.0, 0.01))
            model = sized_model(case, directory)
            rep = 1 if n >= 100000 or quick else 3
            r = eval_bench(build, model, directory, "--no-eval", "--repeat", str(rep))
            vm = solve_run(build, model, case, "bytecode", rep, directory)
            jit = solve_run(build, model, case, "llvm", rep, directory)
            row = (n, r["compileBytecode"], r["compileLlvm"], vm["solve"], jit["solve"])
            e = lambda i: exponent(prev[0], prev[i], row[0], row[i]) if prev else "–"
            print(f"| {n} | {r['instructions']:,} | {row[1]:.4f} | {row[2]:.4f} | {e(1)} | {e(2)} "
                  f"| {r['stages']['llvm']:.4f} | {vm['steps']} / {jit['steps']} | {row[3]:.4f} | {row[4]:.4f} "
                  f"| {e(3)} | {e(4)} | {ratio(row[3], row[4])} |")
            sys.stdout.flush()
            prev = row


def table_short_runs(build, quick, repeat, directory):
    print(f"\n### Time to first result: whole `qdot run` wall time (best of {repeat}), VM, JIT and default\n")
    start = min(run([f"{build}/qdot", "--version"])[0] for _ in range(repeat))
    print(f"Process start (`qdot --version`; LLVM is linked statically): {start * 1e3:.1f} ms. VM = `--backend "
          "bytecode`; JIT = `--jit-wait` (compiled before the first step); default = the VM until the JIT is ready "
          "(background thread), then the JIT.\n")
    print("| model | stop [s] | rows | VM compile [ms] | VM solve [s] | **VM wall [s]** | JIT compile [ms] "
          "| JIT solve [s] | **JIT wall [s]** | **default wall [s]** | fastest |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    pendulum = sized_model(Case("", "nlink", PENDULUM, 8, 1.0), directory)
    chain = sized_model(Case("", "chain", CHAIN, 1000, 1.0), directory)
    sets = [("U-tube", UTUBE, [0.1, 1, 10, 100] if not quick else [0.1, 10], []),
            ("N-link pendulum n = 8", pendulum, [0.1, 1, 10, 100] if not quick else [0.1, 10], []),
            ("spring chain n = 1 000", chain, [0.1, 1, 10] if not quick else [0.1, 1], ["--outputs", "x[1],x[1000]"])]
    for title, model, stops, extra in sets:
        fits = {}
        for stop in stops:
            options = ["--stop", repr(float(stop)), "--interval", "0.01", "-o", os.devnull] + extra
            r = {mode: qdot_wall(build, model, options, mode, repeat) for mode in ("bytecode", "llvm", "default")}
            for mode in r:
                fits.setdefault(mode, []).append((stop, r[mode]["wall"]))
            vm, jit = r["bytecode"], r["llvm"]
            fastest = min(r, key=lambda m: r[m]["wall"])
            print(f"| {title} | {stop:g} | {round(stop / 0.01) + 1} | {vm['compile'] * 1e3:.1f} | {vm['solve']:.3f} "
                  f"| **{vm['wall']:.3f}** | {jit['compile'] * 1e3:.1f} | {jit['solve']:.3f} | **{jit['wall']:.3f}** "
                  f"| **{r['default']['wall']:.3f}** | {'VM' if fastest == 'bytecode' else 'JIT' if fastest == 'llvm' else 'default'} |")
            sys.stdout.flush()
        # wall = a + b * stop between the shortest and longest run, VM against JIT
        (s0, v0), (s1, v1) = fits["bytecode"][0], fits["bytecode"][-1]
        (_, j0), (_, j1) = fits["llvm"][0], fits["llvm"][-1]
        bv, bj = (v1 - v0) / (s1 - s0), (j1 - j0) / (s1 - s0)
        av, aj = v0 - bv * s0, j0 - bj * s0
        if bv > bj:
            print(f"| {title}: fit wall = a + b·stop | | | | | a = {av * 1e3:.1f} ms, b = {bv * 1e3:.2f} ms/s | "
                  f"| | a = {aj * 1e3:.1f} ms, b = {bj * 1e3:.2f} ms/s | | VM/JIT crossover ≈ {max(0, (aj - av) / (bv - bj)):.3g} s |")
        else:
            print(f"| {title}: fit | | | | | b = {bv * 1e3:.2f} ms/s | | | b = {bj * 1e3:.2f} ms/s | | no crossover |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--profile", action="store_true", help="also callgrind instruction counts")
    parser.add_argument("--only", default="1,2,3,4,5", help="which tables (comma-separated 1-5)")
    args = parser.parse_args()
    repeat = 1 if args.quick else 3
    only = set(args.only.split(","))
    print("\n## The LLVM JIT backend: `qdot run --backend llvm`\n")
    with tempfile.TemporaryDirectory(prefix="qdot-jit-bench-") as directory:
        solved = table_against_hand(args.build, args.quick, repeat, directory) if "1" in only else {}
        if "2" in only:
            table_eval(args.build, args.quick, args.profile, directory, solved)
        if "3" in only:
            table_latency(args.build, args.quick, repeat, directory, solved)
        if "4" in only:
            table_scaling(args.build, args.quick, directory, solved)
        if "5" in only:
            table_short_runs(args.build, args.quick, repeat, directory)


if __name__ == "__main__":
    main()
