#!/usr/bin/env python3
"""Largest difference between two CSV snapshots (tools/csv_snapshot.sh output folders), per file:
max over rows and columns of |a - b| / (atol + rtol*|a|) with qdot's default tolerances, i.e. the
difference in units of the solver tolerance. Usage: csv_diff.py REF_DIR NEW_DIR [--rtol R --atol A]"""
import argparse, csv, math, os, sys

p = argparse.ArgumentParser()
p.add_argument("ref"); p.add_argument("new")
p.add_argument("--rtol", type=float, default=1e-6); p.add_argument("--atol", type=float, default=1e-8)
p.add_argument("--states", action="store_true", help="skip accelerations der(der(..)) and multipliers lambda[..], which IDA does not control")
a = p.parse_args()
worst_all, rows = 0.0, []
for name in sorted(os.listdir(a.ref)):
    fa, fb = os.path.join(a.ref, name), os.path.join(a.new, name)
    if not os.path.exists(fb): rows.append((name, "missing")); continue
    ra, rb = list(csv.reader(open(fa))), list(csv.reader(open(fb)))
    if len(ra) != len(rb) or (ra and ra[0] != rb[0]): rows.append((name, f"shape {len(ra)} vs {len(rb)} rows")); continue
    worst, absmax = 0.0, 0.0
    skip = {i for i, h in enumerate(ra[0]) if a.states and (h.startswith("der(der(") or h.startswith("lambda"))}
    for x, y in zip(ra[1:], rb[1:]):
        for i, (u, v) in enumerate(zip(x, y)):
            if i in skip: continue
            u, v = float(u), float(v)
            if math.isnan(u) and math.isnan(v): continue
            d = abs(u - v); absmax = max(absmax, d)
            worst = max(worst, d / (a.atol + a.rtol * abs(u)))
    worst_all = max(worst_all, worst)
    if worst > 0: rows.append((name, f"{worst:.3g} tolerances (max abs {absmax:.3g})"))
for n, w in rows: print(f"{n}: {w}")
print(f"files differing: {len(rows)}; worst: {worst_all:.3g} tolerances")
