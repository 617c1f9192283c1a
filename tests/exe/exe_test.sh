#!/usr/bin/env bash
# qdot build, with either backend (llvm, the default, and bytecode): the executable writes the
# same CSV as `qdot run` with the same backend, lists the parameters in --help, needs no LLVM at
# run time, exits 2 on a bad command line and 3 with the model's error when the run fails.
# Usage: exe_test.sh QDOT_BINARY SOURCE_DIR WORK_DIR
set -u
qdot=$1
src=$2
work=$3
fail=0
pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL $*"; fail=$((fail + 1)); }
check() {  # check NAME EXPECTED_EXIT COMMAND...
  local name=$1 want=$2
  shift 2
  "$@" >"$work/out.txt" 2>&1
  local got=$?
  if [ "$got" -eq "$want" ]; then ok; else bad "$name: exit $got, expected $want"; sed 's/^/    /' "$work/out.txt"; fi
}
same() {  # same NAME FILE1 FILE2
  if [ -s "$2" ] && cmp -s "$2" "$3"; then ok; else bad "$1: $2 and $3 differ"; diff "$2" "$3" | head -5; fi
}

mkdir -p "$work"
utube=$src/examples/textbook/utube.qd
for backend in llvm bytecode; do
  exe=$work/utube-$backend
  rm -f "$exe"
  check "build-$backend" 0 "$qdot" build "$utube" -o "$exe" --backend $backend
  [ -x "$exe" ] && ok || bad "build: no executable $exe"

  # Same CSV as qdot run: overridden parameter and stop time, the experiment annotation's defaults,
  # selected columns with invariants, -o FILE.
  "$exe" --stop 5 -p h=0.2 >"$work/$backend-exe.csv"
  "$qdot" run "$utube" --backend $backend --stop 5 -p h=0.2 >"$work/$backend-run.csv"
  same csv-p-$backend "$work/$backend-exe.csv" "$work/$backend-run.csv"
  "$exe" >"$work/$backend-exe-default.csv"
  "$qdot" run "$utube" --backend $backend >"$work/$backend-run-default.csv"
  same csv-experiment-$backend "$work/$backend-exe-default.csv" "$work/$backend-run-default.csv"
  # qdot run --outputs compiles only what the columns need (E is left out), as qdot build --outputs does.
  check "build-outputs-$backend" 0 "$qdot" build "$utube" -o "$exe-o" --backend $backend --outputs x,jacobi
  # A name the model lacks is a usage error, as qdot run's --outputs (not an executable keeping all).
  check "build-outputs-unknown-$backend" 2 "$qdot" build "$utube" -o "$exe-typo" --backend $backend --outputs x,jacobj
  "$exe-o" --stop 2 --interval 0.1 --rtol 1e-8 --invariants --outputs x,jacobi -o "$work/$backend-exe-o.csv"
  "$qdot" run "$utube" --backend $backend --stop 2 --interval 0.1 --rtol 1e-8 --invariants --outputs x,jacobi -o "$work/$backend-run-o.csv"
  same csv-outputs-$backend "$work/$backend-exe-o.csv" "$work/$backend-run-o.csv"
  "$exe" --stop 2 --interval 0.1 --rtol 1e-8 --invariants --outputs x,jacobi -o "$work/$backend-exe-whole.csv"
  close_enough() {  # the whole model (E integrated too) against the pruned one: the tolerance's difference
    python3 - "$1" "$2" <<'PY' || return 1
import csv, sys
a = list(csv.reader(open(sys.argv[1]))); b = list(csv.reader(open(sys.argv[2])))
assert a[0] == b[0] and len(a) == len(b)
worst = max(abs(float(x) - float(y)) for ra, rb in zip(a[1:], b[1:]) for x, y in zip(ra, rb))
sys.exit(0 if worst < 1e-6 else 1)
PY
  }
  close_enough "$work/$backend-exe-whole.csv" "$work/$backend-run-o.csv" && ok || bad "csv-outputs-whole-$backend: the pruned run differs from the whole model's"

  # --help: every parameter with its default and description.
  check help-$backend 0 "$exe" --help
  for line in "rho = 1000" "A = 0.0001" "l = 1" "g = 9.81" "h = 0.1" "density [kg/m3]" "initial level difference [m]" \
    "--stop" "--linear-solver"; do
    grep -qF -- "$line" "$work/out.txt" && ok || bad "help: no '$line'"
done

# No LLVM at run time.
if ldd "$exe" >"$work/ldd.txt" 2>&1; then
  grep -qi llvm "$work/ldd.txt" && bad "ldd: the executable needs LLVM" || ok
  grep -q "not found" "$work/ldd.txt" && bad "ldd: a library is missing" || ok
else
  bad "ldd failed"
fi

# Command-line mistakes: exit 2, as qdot run.
check bad-parameter 2 "$exe" -p nope=1
check bad-value 2 "$exe" -p h=abc
check no-equals 2 "$exe" -p h
check bad-option 2 "$exe" --bogus
check bad-stop 2 "$exe" --stop -1
grep -qF "did you mean" <("$exe" -p hh=1 2>&1) && ok || bad "bad-parameter: no suggestion"

# A run that fails: exit 3 and the same error sentence as qdot run.
"$qdot" build "$src/tests/exe/sqrt_fails.qd" -o "$work/fails-$backend" --backend $backend
"$work/fails-$backend" >/dev/null 2>"$work/$backend-exe-err.txt"
[ $? -eq 3 ] && ok || bad "fails-$backend: exit code"
"$qdot" run "$src/tests/exe/sqrt_fails.qd" --backend $backend >/dev/null 2>"$work/$backend-run-err.txt"
same "fails-$backend-message" "$work/$backend-exe-err.txt" "$work/$backend-run-err.txt"
grep -qF "sqrt of a negative number" "$work/$backend-exe-err.txt" && ok || bad "fails-$backend: no diagnosis"
done

# The default backend is llvm.
check build-default 0 "$qdot" build "$utube" -o "$work/utube-default"
"$work/utube-default" --stop 1 >"$work/default-exe.csv"
"$qdot" run "$utube" --backend llvm --stop 1 >"$work/default-run.csv"
same csv-default-backend "$work/default-exe.csv" "$work/default-run.csv"

# On a machine with only the runtime libraries: a root file system holding nothing but the
# executable and the shared libraries ldd lists (all from Debian's runtime packages, none -dev,
# no LLVM) runs the model and writes the same CSV. Needs chroot (root); skipped otherwise.
for pkg in $(ldd "$work/utube-default" | grep -o '/[^ ]*\.so[^ ]*' | xargs -r readlink -f | xargs -r dpkg -S 2>/dev/null | cut -d: -f1 | sort -u); do
  case $pkg in *-dev | *llvm*) bad "runtime-packages: the executable needs $pkg" ;; *) ok ;; esac
done
if [ "$(id -u)" -eq 0 ] && command -v chroot >/dev/null; then
  root=$work/runtime-only-root
  rm -rf "$root" && mkdir -p "$root/bin"
  cp "$work/utube-default" "$root/bin/utube"
  for lib in $(ldd "$root/bin/utube" | grep -o '/[^ ]*'); do mkdir -p "$root$(dirname "$lib")" && cp -L "$lib" "$root$lib"; done
  if chroot "$root" /bin/utube --stop 1 >"$work/chroot.csv" 2>"$work/chroot.err"; then
    same csv-runtime-only-root "$work/chroot.csv" "$work/default-run.csv"
    echo "runtime-only root: $(find "$root" -type f | wc -l) files, $(du -sh "$root" | cut -f1)"
  elif grep -q "Operation not permitted" "$work/chroot.err"; then
    echo "skipped: chroot is not permitted here"
  else
    bad "runtime-only root: the executable failed"; sed 's/^/    /' "$work/chroot.err"
  fi
else
  echo "skipped: the runtime-only root needs chroot as root"
fi

# qdot build's own mistakes.
check build-no-output 2 "$qdot" build "$utube"
check build-bad-backend 2 "$qdot" build "$utube" -o "$work/x" --backend jvm
check build-missing-file 2 "$qdot" build "$src/does/not/exist.qd" -o "$work/x"
check build-model-error 1 "$qdot" build "$src/tests/diagnostics/unknown_name.qd" -o "$work/x"
[ -e "$work/x" ] && bad "build-model-error: wrote an executable" || ok
check build-unwritable-output 2 "$qdot" build "$utube" -o /proc/qdot-exe

# Integer parameters size the model: qdot build -p fixes them, the executable says so and refuses -p.
nlink=$src/examples/pendulum/nlink.qd
check build-structural 0 "$qdot" build "$nlink" -p n=2 -o "$work/nlink2"
"$work/nlink2" --stop 0.01 >"$work/nlink2.csv"
[ "$(head -1 "$work/nlink2.csv")" = "time,th[1],th[2],der(th[1]),der(th[2])" ] && ok || bad "nlink2: header $(head -1 "$work/nlink2.csv")"
"$qdot" run "$nlink" -p n=2 --backend llvm --stop 0.01 >"$work/nlink2-run.csv"
same nlink2-csv "$work/nlink2.csv" "$work/nlink2-run.csv"
grep -qF "n = 2" <("$work/nlink2" --help) && ok || bad "nlink2 --help: no 'n = 2'"
check exe-structural-p 2 "$work/nlink2" -p n=3
grep -qF "rebuild it with qdot build -p n=3" <("$work/nlink2" -p n=3 2>&1) && ok || bad "exe -p n=3: no advice"

# A model whose sums stay loops (the undamped chain): the executable writes what qdot run writes,
# with its Jacobi integral (a sum over every element, looped like the rows) as qdot run has it. The
# integral is T + V of the chain: at t = 0, x[i] = 0.01 i at rest, ½·100·0.01² for the wall spring
# and each of the 29 others, 0.15 J; then conserved to the tolerance's order.
chain=$src/tests/exe/undamped_chain.qd
check build-loops 0 "$qdot" build "$chain" -p n=30 -o "$work/chain30"
grep -qF "Jacobi" "$work/out.txt" && bad "build-loops: a note on the Jacobi integral" || ok
"$work/chain30" --stop 1 >"$work/chain30.csv"
"$qdot" run "$chain" -p n=30 --backend llvm --stop 1 >"$work/chain30-run.csv"
same chain30-csv "$work/chain30.csv" "$work/chain30-run.csv"
"$work/chain30" --stop 1 --invariants --outputs 'x[1]' >"$work/chain30i.csv"
"$qdot" run "$chain" -p n=30 --backend llvm --stop 1 --invariants --outputs 'x[1]' >"$work/chain30i-run.csv"
same chain30i-csv "$work/chain30i.csv" "$work/chain30i-run.csv"
awk -F, 'NR == 1 { ok = ($NF == "jacobi") } NR == 2 { j0 = $NF } NR > 1 { d = $NF - j0; if (d < 0) d = -d; if (d > m) m = d }
         END { e = j0 - 0.15; if (e < 0) e = -e; exit !(ok && e <= 1e-12 && m <= 1e-4 * j0) }' "$work/chain30i.csv" \
  && ok || bad "chain30i: no jacobi column equal to T + V and conserved"

# Repeated structure is written once (runtime/vm/Runs.h): the executable of 30 000 masses is the
# size of the one of 30 (names, pattern and index tables as runs; the native code reads its index
# tables from the embedded module), and writes what qdot run writes.
check build-loops-large 0 "$qdot" build "$chain" -p n=30000 -o "$work/chain30000"
small=$(stat -c %s "$work/chain30") large=$(stat -c %s "$work/chain30000")
[ $((large - small)) -le 4096 ] && [ $((small - large)) -le 4096 ] && ok ||
  bad "chain30000: $large bytes, against $small for n = 30"
"$work/chain30000" --stop 0.01 --outputs 'x[1],x[30000],der(x[15000])' >"$work/chain30000.csv"
"$qdot" run "$chain" -p n=30000 --backend llvm --stop 0.01 --outputs 'x[1],x[30000],der(x[15000])' >"$work/chain30000-run.csv"
same chain30000-csv "$work/chain30000.csv" "$work/chain30000-run.csv"

# Programs that run once (parameters, start values) run on the embedded bytecode, as in qdot run's
# JIT: the chain of 2 000 Vibration parts (one parameter binding each, straight-line code) builds
# without compiling them, and a parameter given at run time still counts.
parts=$src/tests/sim/models/chain_components.qd
check build-parts 0 "$qdot" build "$parts" -p n=2000 -o "$work/parts"
"$work/parts" --stop 0.05 -p 'ms[3].m=2' -p 'links[7].k=500' --outputs 'ms[1].s,ms[3].s,ms[2000].s,links[7].b.f' >"$work/parts.csv"
"$qdot" run "$parts" -p n=2000 --backend llvm --stop 0.05 -p 'ms[3].m=2' -p 'links[7].k=500' \
  --outputs 'ms[1].s,ms[3].s,ms[2000].s,links[7].b.f' >"$work/parts-run.csv"
same parts-csv "$work/parts.csv" "$work/parts-run.csv"
# --help lists a component array's members as ranges: 8 lines, not 6 001.
"$work/parts" --help >"$work/parts-help.txt"
grep -qF "ms[1..2000].m = 1" "$work/parts-help.txt" && grep -qF "links[2..2000].s0 = 0" "$work/parts-help.txt" &&
  [ "$(sed -n '/^Parameters/,/^$/p' "$work/parts-help.txt" | grep -c ' = ')" -eq 8 ] && ok ||
  bad "parts --help: the members of the component arrays are not listed as ranges"

echo "$pass passed, $fail failed"
[ "$fail" -eq 0 ]
