#!/usr/bin/env python3
"""Scaling of the whole pipeline on the spring-damper chain, n = 10^3 ... 10^6 (issue 15 §3).

    bench/scaling_bench.py --build DIR [--quick] [--sizes 1000,10000,...]

For each n, one fresh process each (peak memory by wait4's ru_maxrss):
  * qdot run examples/vibration/spring_chain.qd -p n=N --jit-wait  (compile every stage, the JIT,
    then IDA) with a horizon of 1e-4 s: what is measured is the way from the file to the first steps;
    the compile stages' times come from --stats;
  * the hand-written C++ program on the same IDA and KLU (build/bench/reference_sim chain), same
    horizon, same tolerances.
Prints a markdown table (time per stage, file to first step, peak memory, both programs side by
side) and the fitted exponent of each column between consecutive sizes (t ~ n^k).

Then the ways of writing repeated structure (FORMS: energies with arrays of parameters, `for`
equations with implicit rows or algebraic unknowns, arrays of components, whose rows are rerolled)
as templates against expanded to scalars (--no-loops, which also leaves rows unrerolled).

Then standalone executables (`qdot build`): build time, size and the way to the first step per n
(--exe-sizes), for the chain (next to the hand-written program) and the chain of Vibration parts.

Then the time to the first step with glibc's defaults (QDOT_REUSE_FREED_MEMORY=0), with the memory
that the compiler frees reused by the solver (QDOT_PREFAULT_HEAP=0), and as qdot runs by default
(reused, and the heap prefaulted by a second thread), side by side (--reuse-sizes).

Then peak memory and the time to the first step in each backend mode (the default, VM first with
the JIT in the background; --backend bytecode; --jit-wait) next to the hand-written program's peak
(--mode-sizes): the 2x memory target holds in every mode.

Then the whole process at issue 15's setting (rtol 1e-6, 1 s, KLU, columns x[1] and x[n]) for
n = 10^3 ... 10^5 (--whole-sizes): `qdot run` in its default mode (tiering) against the hand-written
program, wall time and peak memory, best of --repeat runs (one fresh process each).
"""
import argparse
import math
import os
import re
import subprocess
import sys
import time

CHAIN = "examples/vibration/spring_chain.qd"
STAGES = ["flatten", "derive", "dae", "kernel"]


def peak_of(command, env=None, faults=None):
    # ru_maxrss of RUSAGE_CHILDREN is the largest child so far: measure each run in its own
    # Python child so earlier (bigger) runs do not hide it. faults: a list that gets the run's page
    # faults (ru_minflt: pages first touched).
    code = ("import resource,subprocess,sys,time;t=time.perf_counter();"
            "p=subprocess.run(sys.argv[1:],stdout=subprocess.DEVNULL,stderr=subprocess.PIPE,text=True);"
            "w=time.perf_counter()-t;u=resource.getrusage(resource.RUSAGE_CHILDREN);"
            "print(w, u.ru_maxrss/1024.0, p.returncode, u.ru_minflt);"
            "sys.stderr.write(p.stderr)")
    p = subprocess.run([sys.executable, "-c", code] + command, capture_output=True, text=True,
                       env=None if env is None else {**os.environ, **env})
    wall, peak, rc, minflt = p.stdout.split()
    if int(rc) != 0:
        sys.exit(f"failed ({rc}): {' '.join(command)}\n{p.stderr}")
    if faults is not None:
        faults.append(int(minflt))
    return float(wall), float(peak), p.stderr


def number(pattern, text, default=float("nan")):
    m = re.search(pattern, text)
    return float(m.group(1)) if m else default


def first_step(wall, err):
    """Process start -> IDA's first completed step: what --stats says ("done X s after the process
    started", the kernel's record of the start, to 10 ms); else, from an older build, the whole
    process less the solve after the first step (which also counts the exit's unmapping)."""
    said = number(r"done ([0-9.e+-]+) s after the process started", err)
    if not math.isnan(said):
        return said
    return wall - number(r"solve ([0-9.e+-]+) s", err) + number(r"first step ([0-9.e+-]+) s", err)


def measure(build, n, stop, env=None, mode=("--jit-wait",), hand_first=False):
    qdot = [f"{build}/qdot", "run", CHAIN, "-p", f"n={n}", "--stop", str(stop), "--interval", str(stop),
            "--outputs", "x[1]", "-o", "/dev/null", "--stats", *mode, "--no-progress"]
    hand = [f"{build}/bench/reference_sim", "chain", "--n", str(n), "--stop", str(stop), "--interval", str(stop),
            "--outputs", "x[1]", "-o", "/dev/null", "--stats"]
    if hand_first:
        hand_run = peak_of(hand)
    faults = []
    wall, peak, err = peak_of(qdot, env, faults)
    stages = {s: number(rf"{s} ([0-9.e+-]+)", err) / 1e3 for s in STAGES}
    stages["codegen"] = number(r"codegen \([^)]*\) ([0-9.e+-]+)", err) / 1e3
    setup = number(r"setup ([0-9.e+-]+) s", err)
    solve = number(r"solve ([0-9.e+-]+) s", err)
    step1 = number(r"first step ([0-9.e+-]+) s", err)
    hwall, hpeak, herr = hand_run if hand_first else peak_of(hand)
    hsetup = number(r"setup ([0-9.e+-]+) s", herr)
    hstep1 = number(r"first step ([0-9.e+-]+) s", herr)
    # file -> first step: from the process's start to IDA's first completed step (its first matrix
    # factorization, KLU's analysis included, belongs to the way there).
    return {"n": n, "wall": wall, "peak": peak, "faults": faults[0], "setup": setup, "solve": solve, "step1": step1,
            **stages,
            "first": first_step(wall, err), "hwall": hwall, "hpeak": hpeak,
            "hfirst": first_step(hwall, herr), "hsetup": hsetup, "hstep1": hstep1}


def measure_best(build, n, stop, repeat):
    """measure() `repeat` times, each program's best run (by file -> first step). The order
    alternates: on a virtual machine the run after a pause pays up to 3x for its page faults (the
    host took back the memory the guest freed; the 10^6 chain: 1.8 s against 1.0 s right after
    another large run), so whichever program ran first in every round would be handicapped."""
    runs = [measure(build, n, stop, hand_first=k % 2 == 1) for k in range(repeat)]
    best = min(runs, key=lambda r: r["first"])
    hand = min(runs, key=lambda r: r["hfirst"])
    return {**best, **{k: hand[k] for k in ("hwall", "hpeak", "hfirst", "hsetup", "hstep1")}}


def reuse(build, sizes, stop, repeat):
    """File -> first step three ways, alternating, best of `repeat` by file -> first step: glibc's
    defaults (QDOT_REUSE_FREED_MEMORY=0), freed memory reused without the heap prefaulter
    (QDOT_PREFAULT_HEAP=0), and qdot's default (reused, prefaulter on; runtime/sim/MemoryReuse.h)."""
    variants = [("glibc", {"QDOT_REUSE_FREED_MEMORY": "0"}), ("reused", {"QDOT_PREFAULT_HEAP": "0"}), ("default", None)]
    print(f"\n## Freed memory reused, heap prefaulted: the spring chain from the file to the first step (horizon {stop:g} s, "
          f"--jit-wait, best of {repeat})\n")
    print("| n | way | compile / IDA setup / first step / **file → first step** [s] | peak [MiB] | page faults "
          "| **time / glibc's defaults** | hand-written: **start → first step** [s] |")
    print("| ---: | --- | ---: | ---: | ---: | ---: | ---: |")
    names = {"glibc": "glibc's defaults", "reused": "freed memory reused",
             "default": "reused + heap prefaulted (default)"}
    for n in sizes:
        runs = {k: [] for k, _ in variants}
        for _ in range(repeat):
            for key, env in variants:
                runs[key].append(measure(build, n, stop, env))
        best = {k: min(v, key=lambda r: r["first"]) for k, v in runs.items()}
        hand = min(r["hfirst"] for v in runs.values() for r in v)
        for key, _ in variants:
            r = best[key]
            compile_ = sum(r[s] for s in STAGES) + r["codegen"]
            print(f"| {n:,} | {names[key]} | {compile_:.2f} / {r['setup']:.2f} / {r['step1']:.2f} / **{r['first']:.2f}** "
                  f"| {r['peak']:.0f} | {r['faults']:,} | **{r['first'] / best['glibc']['first']:.2f}** "
                  f"| {hand:.2f} |".replace(",", " "))


MODES = [("default (VM first, JIT in the background)", ()), ("--backend bytecode", ("--backend", "bytecode")),
         ("--jit-wait", ("--jit-wait",))]


def modes(build, sizes, stop, repeat):
    """Peak memory and file -> first step in each backend mode, alternating, best of `repeat` (by
    peak), beside the hand-written program's whole run: the 2x memory target holds for every mode."""
    print(f"\n## Backend modes: peak memory and file → first step of the spring chain (horizon {stop:g} s, "
          f"best of {repeat})\n")
    print("| n | mode | peak [MiB] | **peak / hand-written** | file → first step [s] | hand-written peak [MiB] |")
    print("| ---: | --- | ---: | ---: | ---: | ---: |")
    for n in sizes:
        runs = {name: [] for name, _ in MODES}
        for _ in range(repeat):
            for name, mode in MODES:
                runs[name].append(measure(build, n, stop, mode=mode))
        hand = min(r["hpeak"] for v in runs.values() for r in v)
        for name, _ in MODES:
            best = min(runs[name], key=lambda r: r["peak"])
            size = f"{n:,}".replace(",", " ")
            print(f"| {size} | {name} | {best['peak']:.0f} | **{best['peak'] / hand:.2f}** | {best['first']:.2f} "
                  f"| {hand:.0f} |")


def whole(build, n, stop, repeat):
    """Whole process at the issue's setting: qdot run (default mode) and the hand-written program."""
    common = ["--stop", str(stop), "--outputs", f"x[1],x[{n}]", "-o", "/dev/null"]
    qdot = [f"{build}/qdot", "run", CHAIN, "-p", f"n={n}", "--no-progress"] + common
    hand = [f"{build}/bench/reference_sim", "chain", "--n", str(n)] + common
    best = {}
    for _ in range(repeat):
        for key, command in (("qdot", qdot), ("hand", hand)):
            wall, peak, _ = peak_of(command)
            w, p = best.get(key, (float("inf"), float("inf")))
            best[key] = (min(w, wall), min(p, peak))
    return {"n": n, "qwall": best["qdot"][0], "qpeak": best["qdot"][1], "hwall": best["hand"][0], "hpeak": best["hand"][1]}


SMALL = [("N-link pendulum n = 8", "examples/pendulum/nlink.qd", ["-p", "n=8"]),
         ("double pendulum", "examples/pendulum/double_pendulum.qd", []),
         ("spring chain n = 10", CHAIN, [])]


def small_models(build, repeat):
    """Small models stay small: file -> first step on the VM (`--backend bytecode`, horizon 1e-4 s),
    best of `repeat` fresh processes, with the compile time --stats reports."""
    rows = []
    for name, path, extra in SMALL:
        command = [f"{build}/qdot", "run", path, *extra, "--stop", "1e-4", "--interval", "1e-4", "--backend", "bytecode",
                   "-o", "/dev/null", "--stats", "--no-progress"]
        best_wall, best_inside = float("inf"), float("inf")
        for _ in range(repeat):
            wall, _, err = peak_of(command)
            best_wall = min(best_wall, wall)
            inside = (number(r"; total ([0-9.e+-]+)", err) / 1e3 + number(r"setup ([0-9.e+-]+) s", err) +
                      number(r"first step ([0-9.e+-]+) s", err))
            best_inside = min(best_inside, inside)
        rows.append((name, best_wall, best_inside))
    print(f"\n## Small models: file to first step on the VM (best of {repeat} processes)\n")
    print("| model | **file → first step**: compile + IDA setup + first step (--stats) [ms] | whole process to t = 1e-4 s, with the process start [ms] |")
    print("| --- | ---: | ---: |")
    for name, wall, inside in rows:
        print(f"| {name} | {inside * 1e3:.2f} | {wall * 1e3:.1f} |")


# Models whose repeated structure is written other ways than the chain's energies (docs/loops.md):
# each as templates (qdot run's default) and expanded to scalars (--no-loops), at n = 10^5, to
# t = 1e-4 s.
FORMS = [("spring chain, energies", CHAIN, "x[1]"),
         ("non-uniform chain, energies with m[i], k[i]", "examples/vibration/nonuniform_chain.qd", "x[1]"),
         ("spring chain, `m*der(v[i]) = …` equations", "examples/vibration/spring_chain_equations.qd", "x[1]"),
         ("spring chain, link forces f[i] as unknowns", "tests/sim/models/chain_forces.qd", "x[1]"),
         ("heat rod, `der(T[i]) = …`", "examples/heat/rod.qd", "T[1]"),
         ("graded chain: index as a number, forces in a loop", "tests/sim/models/graded_forced_chain.qd", "x[1]"),
         ("heat rod, an initial equation per node", "tests/sim/models/rod_initial_profile.qd", "T[1]"),
         ("damped chain, energy and power as outputs of sums", "tests/sim/models/chain_energy_outputs.qd", "E,P"),
         ("chain through definitions and factors (`kinetic = T`, `0.5*m*sum(…)`)",
          "tests/sim/models/chain_definitions.qd", "E,P"),
         ("chain, energies and forces in `for` loops", "tests/sim/models/chain_for_energies.qd", "x[1]"),
         ("chain of `Vibration` parts (arrays of components): energies summed over the connections, templates",
          "tests/sim/models/chain_components.qd", "ms[1].s"),
         ("chain of parallel `Spring` and `Damper` parts (three flanges a node)",
          "tests/sim/models/parallel_chain_components.qd", "ms[1].s")]


def forms(build, n, repeat):
    """Each FORMS model as templates and as scalars: compile time (--stats), whole process, peak."""
    size = f"{n:,}".replace(",", " ")
    print(f"\n## Ways of writing repeated structure, n = {size}: templates against scalars "
          f"(to t = 1e-4 s, --jit-wait, best of {repeat})\n")
    print("| model | compile, templates [s] | whole, templates [s] | peak, templates [MiB] | compile, scalars [s] "
          "| whole, scalars [s] | peak, scalars [MiB] | **whole: scalars / templates** |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, path, column in FORMS:
        cells = []
        for extra in ([], ["--no-loops"]):
            command = [f"{build}/qdot", "run", path, "-p", f"n={n}", "--stop", "1e-4", "--interval", "1e-4",
                       "--outputs", column, "-o", "/dev/null", "--stats", "--jit-wait", "--no-progress"] + extra
            best = (float("inf"), float("inf"), float("inf"))
            for _ in range(repeat):
                wall, peak, err = peak_of(command)
                compile_s = number(r"; total ([0-9.e+-]+)", err) / 1e3
                best = tuple(min(a, b) for a, b in zip(best, (compile_s, wall, peak)))
            cells.append(best)
        (tc, tw, tp), (sc, sw, sp) = cells
        print(f"| {name} | {tc:.2f} | {tw:.2f} | {tp:.0f} | {sc:.2f} | {sw:.2f} | {sp:.0f} | **{sw / tw:.1f}** |")


# (name, model, column, largest n: the parts' chain is expanded to scalars before the DAE, 10^6 of
# them would take minutes and tens of GB to compile)
EXECUTABLES = [("spring chain", CHAIN, "x[1]", 10**9),
               ("chain of `Vibration` parts", "tests/sim/models/chain_components.qd", "ms[1].s", 100000)]


def executables(build, sizes, stop, tmp):
    """qdot build: build time, the executable's size and its way to the first step, per n (one
    fresh process each), next to the hand-written program's way to the first step."""
    print(f"\n## Standalone executables (`qdot build`, --backend llvm): size and time per n (horizon {stop:g} s)\n")
    print("| model | n | qdot build [s] | build peak [MiB] | executable [MB] | executable: start → first step [s] "
          "| hand-written: start → first step [s] |")
    print("| --- | ---: | ---: | ---: | ---: | ---: | ---: |")
    for name, path, column, largest in EXECUTABLES:
        for n in (n for n in sizes if n <= largest):
            exe = os.path.join(tmp, f"qdot-bench-exe-{n}")
            bwall, bpeak, _ = peak_of([f"{build}/qdot", "build", path, "-p", f"n={n}", "-o", exe])
            size = os.path.getsize(exe) / 1e6
            wall, _, err = peak_of([exe, "--stop", str(stop), "--interval", str(stop), "--outputs", column, "-o",
                                    "/dev/null", "--stats"])
            first = first_step(wall, err)
            hand = "—"
            if path == CHAIN:
                hwall, _, herr = peak_of([f"{build}/bench/reference_sim", "chain", "--n", str(n), "--stop", str(stop),
                                          "--interval", str(stop), "--outputs", "x[1]", "-o", "/dev/null", "--stats"])
                hand = f"{first_step(hwall, herr):.3g}"
            os.remove(exe)
            print(f"| {name} | {n:,} | {bwall:.2f} | {bpeak:.0f} | {size:.2f} | {first:.3g} | {hand} |".replace(",", " "))


PARTS = "tests/sim/models/chain_components.qd"


def components(build, sizes, stop, repeat):
    """The chain of Vibration parts (arrays of components) in the default mode, whole process: asked
    for two masses (energies summed over the connections, templates), and for a link force too
    (the parts and their flows expanded, rows rerolled), next to the spring chain written with energies
    and the hand-written program; compile time from --stats."""
    print(f"\n## Arrays of components as templates: the chain of `Vibration` parts, whole process "
          f"(rtol 1e-6, {stop:g} s, default mode, best of {repeat})\n")
    print("| n | parts, masses asked for: compile / whole [s] / peak [MiB] | parts, a link force too: compile / whole "
          "[s] / peak [MiB] | spring chain, energies: whole [s] / peak [MiB] | hand-written: whole [s] / peak [MiB] |")
    print("| ---: | ---: | ---: | ---: | ---: |")
    for n in sizes:
        masses = f"ms[1].s,ms[{n}].s"
        runs = {"summed": [f"{build}/qdot", "run", PARTS, "-p", f"n={n}", "--outputs", masses],
                "flows": [f"{build}/qdot", "run", PARTS, "-p", f"n={n}", "--outputs", masses + ",links[1].b.f"],
                "chain": [f"{build}/qdot", "run", CHAIN, "-p", f"n={n}", "--outputs", f"x[1],x[{n}]"],
                "hand": [f"{build}/bench/reference_sim", "chain", "--n", str(n), "--outputs", f"x[1],x[{n}]"]}
        best = {}
        for _ in range(repeat):
            for key, command in runs.items():
                extra = [] if key == "hand" else ["--no-progress", "--stats"]
                wall, peak, err = peak_of(command + ["--stop", str(stop), "-o", "/dev/null"] + extra)
                compile_s = number(r"; total ([0-9.e+-]+)", err, 0.0) / 1e3
                old = best.get(key, (float("inf"),) * 3)
                best[key] = tuple(min(a, b) for a, b in zip(old, (compile_s, wall, peak)))
        cell = lambda k: f"{best[k][0]:.2f} / {best[k][1]:.2f} / {best[k][2]:.0f}"
        print(f"| {n:,} | {cell('summed')} | {cell('flows')} | {best['chain'][1]:.2f} / {best['chain'][2]:.0f} | "
              f"{best['hand'][1]:.2f} / {best['hand'][2]:.0f} |".replace(",", " "))


def print_whole(rows, stop, repeat):
    print(f"\n## Whole process, issue 15's setting (rtol 1e-6, {stop:g} s, KLU, columns x[1], x[n]; "
          f"default mode; best of {repeat})\n")
    print("| n | qdot [s] | hand-written [s] | **time ratio** | qdot peak [MiB] | hand-written peak [MiB] | **memory ratio** |")
    print("| ---: | ---: | ---: | ---: | ---: | ---: | ---: |")
    for r in rows:
        print(f"| {r['n']:,} | {r['qwall']:.2f} | {r['hwall']:.2f} | **{r['qwall'] / r['hwall']:.2f}** | "
              f"{r['qpeak']:.0f} | {r['hpeak']:.0f} | **{r['qpeak'] / r['hpeak']:.2f}** |".replace(",", " "))


def exponent(a, b, key):
    if a[key] <= 0 or b[key] <= 0 or any(map(math.isnan, (a[key], b[key]))):
        return float("nan")
    return math.log(b[key] / a[key]) / math.log(b["n"] / a["n"])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build", default="build")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--sizes", default=None)
    ap.add_argument("--stop", type=float, default=1e-4)
    ap.add_argument("--whole-sizes", default=None, help="n for the whole-process table (default 1000,10000,100000; 'none' skips it)")
    ap.add_argument("--whole-stop", type=float, default=1.0)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--forms-n", type=int, default=100000, help="n of the ways-of-writing table (0 skips it)")
    ap.add_argument("--parts-sizes", default=None, help="n for the arrays-of-components table (default 1000,10000,100000; 'none' skips it)")
    ap.add_argument("--exe-sizes", default=None, help="n for the executables table (default 1000,100000,1000000; 'none' skips it)")
    ap.add_argument("--reuse-sizes", default=None,
                    help="n for the freed-memory table (default 100000,1000000, with --quick 100000; 'none' skips it)")
    ap.add_argument("--mode-sizes", default=None,
                    help="n for the backend-modes table (default 1000000, with --quick 100000; 'none' skips it)")
    a = ap.parse_args()
    sizes = [int(s) for s in a.sizes.split(",")] if a.sizes else ([1000, 10000, 100000] if a.quick else
                                                                   [1000, 10000, 100000, 1000000])
    rows = [measure_best(a.build, n, a.stop, a.repeat) for n in sizes]
    print("\n## Scaling: the spring chain from the file to the first steps (bench/scaling_bench.py)\n")
    print(f"Horizon {a.stop:g} s, rtol 1e-6, KLU; qdot with --jit-wait (every stage, then native code); "
          f"each program's best of {a.repeat} runs, the two taking turns to run first. "
          "File → first step: the process from its start to IDA's first completed step (IDA setup, then "
          "the first step with its matrix factorization). Times in seconds, memory = peak RSS.\n")
    cols = ["flatten", "derive", "dae", "kernel", "codegen", "setup", "step1", "first", "peak", "hsetup", "hstep1",
            "hfirst", "hpeak"]
    head = ["n", "flatten", "derive", "dae", "kernel", "codegen+JIT", "IDA setup", "first step", "**file → first step**",
            "peak [MiB]", "hand setup", "hand first step", "**hand: start → first step**", "hand peak [MiB]",
            "time ratio", "memory ratio"]
    print("| " + " | ".join(head) + " |")
    print("|" + "---:|" * len(head))
    for r in rows:
        cells = [f"{r['n']:,}".replace(",", " ")] + [f"{r[c]:.3g}" for c in cols]
        cells += [f"{r['first'] / r['hfirst']:.2f}", f"{r['peak'] / r['hpeak']:.2f}"]
        print("| " + " | ".join(cells) + " |")
    if len(rows) > 1:
        print("\nFitted exponents k (t ~ n^k) between consecutive sizes:\n")
        print("| from → to | " + " | ".join(cols) + " |")
        print("|---|" + "---:|" * len(cols))
        for x, y in zip(rows, rows[1:]):
            print(f"| {x['n']} → {y['n']} | " + " | ".join(f"{exponent(x, y, c):.2f}" for c in cols) + " |")
    small_models(a.build, 10)
    if a.forms_n:
        forms(a.build, a.forms_n, a.repeat)
    if a.parts_sizes != "none":
        parts_sizes = [int(s) for s in a.parts_sizes.split(",")] if a.parts_sizes else (
            [1000, 10000] if a.quick else [1000, 10000, 100000])
        components(a.build, parts_sizes, a.whole_stop, a.repeat)
    if a.exe_sizes != "none":
        exe_sizes = [int(s) for s in a.exe_sizes.split(",")] if a.exe_sizes else (
            [1000, 100000] if a.quick else [1000, 100000, 1000000])
        executables(a.build, exe_sizes, a.stop, os.environ.get("TMPDIR", "/tmp"))
    if a.reuse_sizes != "none":
        reuse_sizes = [int(s) for s in a.reuse_sizes.split(",")] if a.reuse_sizes else (
            [100000] if a.quick else [100000, 1000000])
        reuse(a.build, reuse_sizes, a.stop, max(a.repeat, 2))
    if a.mode_sizes != "none":
        mode_sizes = [int(s) for s in a.mode_sizes.split(",")] if a.mode_sizes else ([100000] if a.quick else [1000000])
        modes(a.build, mode_sizes, a.stop, max(a.repeat, 2))
    if a.whole_sizes != "none":
        whole_sizes = [int(s) for s in a.whole_sizes.split(",")] if a.whole_sizes else (
            [1000, 10000] if a.quick else [1000, 10000, 100000])
        print_whole([whole(a.build, n, a.whole_stop, a.repeat) for n in whole_sizes], a.whole_stop, a.repeat)


if __name__ == "__main__":
    main()
