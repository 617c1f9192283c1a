#!/usr/bin/env bash
# Command-line behaviour of qdot: exit codes (0 ok, 1 model errors, 2 bad command line or output), output
# of the README's first command, JSON that parses. Usage: cli_test.sh QDOT_BINARY SOURCE_DIR
set -u
qdot=$1
src=$2
fail=0
pass=0
check() {  # check NAME EXPECTED_EXIT COMMAND...
  local name=$1 want=$2
  shift 2
  "$@" >/tmp/qdot_cli_out.$$ 2>&1
  local got=$?
  if [ "$got" -eq "$want" ]; then pass=$((pass + 1)); else
    echo "FAIL $name: exit $got, expected $want"; sed 's/^/    /' /tmp/qdot_cli_out.$$; fail=$((fail + 1)); fi
}
contains() {  # contains NAME TEXT COMMAND...
  local name=$1 text=$2
  shift 2
  if "$@" 2>&1 | grep -qF -- "$text"; then pass=$((pass + 1)); else echo "FAIL $name: no '$text'"; fail=$((fail + 1)); fi
}

check version 0 "$qdot" --version
check help 0 "$qdot" --help
check no-arguments 2 "$qdot"
check unknown-command 2 "$qdot" frobnicate
check missing-file 2 "$qdot" check "$src/does/not/exist.qd"
check unknown-option 2 "$qdot" equations "$src/examples/textbook/utube.qd" --bogus
check model-ok 0 "$qdot" check "$src/examples/textbook/utube.qd"
check model-error 1 "$qdot" check "$src/tests/diagnostics/unknown_name.qd"
check unknown-model 1 "$qdot" equations "$src/examples/textbook/utube.qd" --model Nope
check emit-ast 0 "$qdot" check "$src/examples/textbook/utube.qd" --emit=ast
check emit-unknown-stage 2 "$qdot" run "$src/examples/textbook/utube.qd" --emit=assembly
if "$qdot" --help | grep -q '^  build'; then  # --emit needs no executable; without it, -o is required
  check build-emit 0 "$qdot" build "$src/examples/textbook/utube.qd" --emit=llvm
  check build-needs-output 2 "$qdot" build "$src/examples/textbook/utube.qd"
fi
# The README's first command: the U-tube's equation of motion, rho*A*(l ẍ + 2 g x) = 0 (checked
# numerically against the textbook in TextbookExamplesTest; here: that it is what gets printed).
contains utube-equation "x:  rho*A*l*der(der(x)) + 2*rho*A*g*x = 0" "$qdot" equations "$src/examples/textbook/utube.qd"
contains utube-integral "jacobi (Jacobi integral, conserved)" "$qdot" equations "$src/examples/textbook/utube.qd"
contains caret "^~~" "$qdot" check "$src/tests/diagnostics/unknown_name.qd"
contains location "unknown_name.qd:6:17: error[E0202]: unknown name 'mas'" "$qdot" check "$src/tests/diagnostics/unknown_name.qd"
contains energy-help "write it in the mechanics section" "$qdot" check "$src/tests/diagnostics/energy_in_equation_section.qd"
# A chain of 10^5 definitions (parameters) a0 = a1 + 1, ..., declared so that every use is a forward
# reference: no stage may recurse along it (4 500 links overflowed the flattener's stack). The run
# writes y = a0 = a_N + 10^5 at t = 0.
chain() {  # chain FILE DECLARATION LAST
  awk -v decl="$2" -v last="$3" 'BEGIN {
    n = 100000
    print "model Chain\n  coordinate Real x(start = 1);\n  output Real y = a0;"
    for (i = 0; i < n; i++) printf "  %s a%d = a%d + 1;\n", decl, i, i + 1
    printf "  %s a%d = %s;\n", decl, n, last
    print "mechanics\n  kinetic = 0.5*der(x)^2;\n  potential = 0.5*x^2;\nend Chain;" }' >"$1"
}
chain /tmp/qdot_cli_chain.$$.qd "Real" "x"
chain /tmp/qdot_cli_pchain.$$.qd "parameter Real" "1"
for f in /tmp/qdot_cli_chain.$$.qd /tmp/qdot_cli_pchain.$$.qd; do
  check "chain-check" 0 "$qdot" check "$f"
  check "chain-equations" 0 "$qdot" equations "$f"
  contains "chain-run" "0,1,0,100001" "$qdot" run "$f" --stop 0.1
done
rm -f /tmp/qdot_cli_chain.$$.qd /tmp/qdot_cli_pchain.$$.qd
# A binary file given by mistake (here qdot itself): one short error, not a screenful per byte run.
head -c 300000 "$qdot" >/tmp/qdot_cli_binary.$$.qd
check binary-file 1 "$qdot" check /tmp/qdot_cli_binary.$$.qd
bytes=$("$qdot" check /tmp/qdot_cli_binary.$$.qd 2>&1 | wc -c)
if [ "$bytes" -lt 2000 ]; then pass=$((pass + 1)); else echo "FAIL binary-file-short: $bytes bytes of diagnostics"; fail=$((fail + 1)); fi
contains binary-file-says "this is not a text file" "$qdot" check /tmp/qdot_cli_binary.$$.qd
rm -f /tmp/qdot_cli_binary.$$.qd
contains csv-names-identifier "time,th_1," "$qdot" run "$src/examples/pendulum/nlink.qd" --stop 0.01 --csv-names=identifier
check csv-names-bad 2 "$qdot" run "$src/examples/pendulum/nlink.qd" --csv-names=python
# A misspelt flow of a chain of parts asked for: a usage error that suggests the flow (the parts are
# not summed for a name that is near one of their variables).
check outputs-misspelt-flow 2 "$qdot" run "$src/tests/sim/models/chain_components.qd" -p n=5 --outputs 'links[3].b.ff'
contains outputs-misspelt-flow-suggests "did you mean 'links[3].b.f'?" "$qdot" run "$src/tests/sim/models/chain_components.qd" -p n=5 --outputs 'links[3].b.ff'
check parameter-out-of-range 2 "$qdot" run "$src/examples/textbook/utube.qd" -p rho=1e400
contains parameter-out-of-range-says "out of range" "$qdot" run "$src/examples/textbook/utube.qd" -p rho=1e400
# --outputs: only what the results need (the oscillator of two uncoupled subsystems).
contains equations-outputs "kept 2 of 5 unknowns and 2 of 5 equations" \
  "$qdot" equations "$src/tests/sim/models/two_subsystems.qd" --outputs x
contains equations-outputs-unknown "nothing pruned: no variable, output or invariant is named 'nope'" \
  "$qdot" equations "$src/tests/sim/models/two_subsystems.qd" --outputs nope
# qdot equations --json: a start set by an initial equation is reported as such.
contains equations-json-initial '"name": "der(phi)", "kind": "state", "role": "velocity", "start": "10", "startFrom": "initial equation", "fixed": true' \
  "$qdot" equations "$src/examples/textbook/governor_free.qd" --json
# -p on a component's Integer parameter (structural, by its dotted path).
contains component-integer-parameter "306.1467459" "$qdot" modes "$src/tests/sim/models/string_component.qd" -p str.n=3
# A zero mass is named before IDA runs (exit 3: the simulation cannot start), flat or from components.
check zero-mass 3 "$qdot" run "$src/examples/vibration/two_mass.qd" -p m=0 --stop 0.1
contains zero-mass-says "the equations do not determine der(der(x1)), der(der(x2)) at t = 0" \
  "$qdot" run "$src/examples/vibration/two_mass.qd" -p m=0 --stop 0.1
contains zero-mass-component-says "the equations do not determine der(der(m1.s)) at t = 0" \
  "$qdot" run "$src/examples/vibration/two_dof.qd" -p m1.m=0 --stop 0.1
# qdot check: every check short of solving, then one summary line (or nothing with --quiet).
contains check-summary "model UTube is valid: 3 equations in 3 unknowns (2 states, 1 algebraic), 5 parameters" \
  "$qdot" check "$src/examples/textbook/utube.qd"
[ -z "$("$qdot" check --quiet "$src/examples/textbook/utube.qd" 2>&1)" ] && pass=$((pass + 1)) || {
  echo "FAIL check-quiet: printed something"; fail=$((fail + 1)); }
check check-kernel-errors 1 "$qdot" check "$src/tests/diagnostics/initial_conflicts.qd"
# A model read from standard input (-): the same output as from the file.
check stdin-check 0 sh -c "'$qdot' check - < '$src/examples/textbook/utube.qd'"
if [ "$("$qdot" run - --stop 0.5 < "$src/examples/textbook/utube.qd")" = "$("$qdot" run "$src/examples/textbook/utube.qd" --stop 0.5)" ]; then
  pass=$((pass + 1)); else echo "FAIL stdin-run: differs from the file's run"; fail=$((fail + 1)); fi
contains stdin-located "<stdin>:6:17: error[E0202]" sh -c "'$qdot' check - < '$src/tests/diagnostics/unknown_name.qd'"
# qdot build checks its output path before compiling: a clear message and exit 2, no linker noise.
check build-to-directory 2 "$qdot" build "$src/examples/textbook/utube.qd" -o .
check build-to-proc 2 "$qdot" build "$src/examples/textbook/utube.qd" -o /proc/qdot-x
contains build-to-proc-says "cannot write the executable" "$qdot" build "$src/examples/textbook/utube.qd" -o /proc/qdot-x
check run-unwritable-output 2 "$qdot" run "$src/examples/textbook/utube.qd" -o /does/not/exist/out.csv
check build-no-folder 2 "$qdot" build "$src/examples/textbook/utube.qd" -o /does/not/exist/x
# Integer parameters are structural: applied before compiling; others stay run-time inputs.
contains structural-p "time,th[1],th[2],th[3],der(th[1])" "$qdot" run "$src/examples/pendulum/nlink.qd" -p n=3 --stop 0.01
check structural-p-fraction 2 "$qdot" run "$src/examples/pendulum/nlink.qd" -p n=2.5
check build-runtime-p 2 "$qdot" build "$src/examples/pendulum/nlink.qd" -p m=2 -o /tmp/qdot_cli_exe.$$
rm -f /tmp/qdot_cli_exe.$$
# qdot modes: the two-mass system's out-of-phase frequency √(3k/m) = √300; JSON parses; no equilibrium: exit 1.
contains modes-two-mass "17.32050808" "$qdot" modes "$src/examples/vibration/two_mass_modes.qd"
check modes-json 0 sh -c "'$qdot' modes '$src/examples/vibration/two_mass_modes.qd' --json | python3 -m json.tool"
check modes-no-equilibrium 1 "$qdot" modes "$src/examples/textbook/wedge.qd"
check modes-bad-at 2 "$qdot" modes "$src/examples/textbook/utube.qd" --at nowhere
# qdot linearize: the damped oscillator's row der(x) of A (−k/m, −c/m) as CSV; a forced mass's A and
# B (1/m for its input u) as JSON, exactly; -p sets an input (the equilibrium moves to u/k).
contains linearize-csv "der(x),-100,-2" "$qdot" linearize "$src/examples/vibration/damped_oscillator.qd"
forced=/tmp/qdot_cli_forced.$$.qd
cat >"$forced" <<'QD'
model Forced
  parameter Real m = 2, k = 50;
  input Real u;
  coordinate Real x;
mechanics
  kinetic = 0.5*m*der(x)^2;
  potential = 0.5*k*x^2;
  force(x) = u;
end Forced;
QD
expect='import json, sys; d = json.load(sys.stdin); assert (d["states"], d["inputs"], d["A"], d["B"], d["point"]) == (["x", "der(x)"], ["u"], [[0, 1], [-25, 0]], [[0], [0.5]], [0.1, 0]), d'
check linearize-json 0 sh -c "'$qdot' linearize '$forced' --json -p u=5 | python3 -c '$expect'"
contains linearize-csv-input "B,u" "$qdot" linearize "$forced"
rm -f "$forced"
check linearize-no-equilibrium 1 "$qdot" linearize "$src/examples/textbook/wedge.qd"
check linearize-at-start 0 "$qdot" linearize "$src/examples/textbook/wedge.qd" --at start
check linearize-bad-p 2 "$qdot" linearize "$src/examples/textbook/utube.qd" -p nope=1
for f in "$src"/examples/*/*.qd; do
  check "json-$(basename "$f")" 0 sh -c "'$qdot' equations '$f' --json | python3 -m json.tool"
done
# Guards (issue 11 §5): an --interval that would write 10^10 rows is refused with the count; with
# --max-steps the run stops with an error naming the limit and keeps the rows written so far.
check rows-refused 2 "$qdot" run "$src/examples/textbook/utube.qd" --interval 1e-9
contains rows-count "would write 10000000001 rows" "$qdot" run "$src/examples/textbook/utube.qd" --interval 1e-9
check max-steps 3 "$qdot" run "$src/examples/textbook/utube.qd" --max-steps 50
contains max-steps-message "reached --max-steps 50" "$qdot" run "$src/examples/textbook/utube.qd" --max-steps 50
contains max-steps-rows "rows up to t =" "$qdot" run "$src/examples/textbook/utube.qd" --max-steps 50
# --emit shows what the run compiles: the rod's `for` equation as one loop, also with --invariants
# (the chain's Jacobi integral is a loop of stadd), scalar rows with --no-loops, and the same CSV.
contains emit-kernel-loop "equations of elements" "$qdot" run "$src/examples/heat/rod.qd" --emit=kernel
contains emit-kernel-loop-invariants "equations of elements" "$qdot" run "$src/examples/heat/rod.qd" --emit=kernel --invariants
contains emit-kernel-jacobi-loop "stadd" "$qdot" run "$src/tests/exe/undamped_chain.qd" --emit=kernel --invariants
check emit-kernel-no-loops 1 sh -c "'$qdot' run '$src/examples/heat/rod.qd' --emit=kernel --no-loops | grep -q 'equations of elements'"
"$qdot" run "$src/examples/heat/rod.qd" --backend bytecode --stop 0.1 -o /tmp/qdot_loops.$$ 2>/dev/null
"$qdot" run "$src/examples/heat/rod.qd" --backend bytecode --stop 0.1 --no-loops -o /tmp/qdot_noloops.$$ 2>/dev/null
awk -F, 'NR == FNR { row[FNR] = $0; next } FNR == 1 { same = ($0 == row[1]); next }
         { n = split(row[FNR], a, ","); if (n != NF) same = 0
           for (i = 1; i <= NF; ++i) { d = $i - a[i]; if (d < 0) d = -d; if (d > 1e-9 * (1 + (a[i] < 0 ? -a[i] : a[i]))) same = 0 } }
         END { exit !(same && FNR > 2) }' /tmp/qdot_loops.$$ /tmp/qdot_noloops.$$ && pass=$((pass + 1)) || { echo "FAIL no-loops: the rod's CSV differs beyond 1e-9"; fail=$((fail + 1)); }
rm -f /tmp/qdot_loops.$$ /tmp/qdot_noloops.$$
# The beating oscillators' six connector flows are defined explicitly by their components' rows:
# `qdot run` integrates the four states alone and says so; `qdot equations` shows the flows.
contains stats-solved-out "system: 6 algebraic unknowns" "$qdot" run "$src/examples/vibration/beating.qd" --stop 0.01 -o /dev/null --stats
contains equations-keep-flows "k1.b.f" "$qdot" equations "$src/examples/vibration/beating.qd"
# KLU with each mass's kinematic row der(x) = v eliminated first: the chain's reduced matrix is
# tridiagonal (bandwidth 1); --no-row-elimination factors the whole 2n x 2n matrix (bandwidth 3).
contains klu-rows-eliminated "band ordering, bandwidth 1; 100 two-entry rows eliminated first, the rest by a band LU with partial pivoting" "$qdot" run "$src/examples/vibration/spring_chain.qd" -p n=100 --stop 0.01 --linear-solver klu --stats -o /dev/null
contains klu-whole-matrix "klu (as requested; band ordering, bandwidth 3)" "$qdot" run "$src/examples/vibration/spring_chain.qd" -p n=100 --stop 0.01 --linear-solver klu --stats -o /dev/null --no-row-elimination
check emit-kernel-no-flow-unknowns 1 sh -c "'$qdot' run '$src/examples/vibration/beating.qd' --emit=kernel | grep '^variables' | grep -q 'k1.b.f'"
rm -f /tmp/qdot_cli_out.$$
echo "cli: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
