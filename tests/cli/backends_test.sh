#!/usr/bin/env bash
# The JIT and the bytecode VM compute the same kernels bit for bit (tests/unit/llvm), so a whole
# simulation must come out the same on the JIT alone (--backend llvm --jit-wait), on the VM alone
# (--backend bytecode) and by default (the VM, then the JIT if the tiering policy starts it): for every
# example model, byte-identical CSV (all variables, outputs and invariants at every output time)
# and identical solver counters (steps, residual and Jacobian evaluations, failures).
# Usage: backends_test.sh QDOT_BINARY SOURCE_DIR
set -u
qdot=$1
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
pass=0
# The solver counters of --stats (wall times differ between runs, so they are left out).
counters() { grep -E '^  (steps|residual evaluations|Jacobian evaluations|nonlinear iterations|error-test failures|convergence failures|rows written) ' "$1"; }
while IFS= read -r model; do
  name=${model#"$src"/examples/}
  for backend in llvm bytecode default; do
    case $backend in
      llvm) options=(--backend llvm --jit-wait) ;;
      bytecode) options=(--backend bytecode) ;;
      default) options=() ;;
    esac
    if ! "$qdot" run "$model" "${options[@]}" --invariants --stats -o "$work/$backend.csv" 2>"$work/$backend.log"; then
      echo "FAIL $name: qdot run ${options[*]} failed"; sed 's/^/    /' "$work/$backend.log"; fail=$((fail + 1)); continue 2
    fi
  done
  if ! cmp -s "$work/llvm.csv" "$work/bytecode.csv" || ! cmp -s "$work/default.csv" "$work/bytecode.csv"; then
    echo "FAIL $name: the CSV of the JIT, the VM and the default differ"; diff "$work/llvm.csv" "$work/bytecode.csv" | head -5; fail=$((fail + 1))
  elif ! diff <(counters "$work/llvm.log") <(counters "$work/bytecode.log") >"$work/diff" ||
       ! diff <(counters "$work/default.log") <(counters "$work/bytecode.log") >>"$work/diff"; then
    echo "FAIL $name: solver counters differ"; cat "$work/diff"; fail=$((fail + 1))
  elif [ "$(counters "$work/llvm.log" | wc -l)" -ne 7 ]; then
    echo "FAIL $name: --stats did not print the solver counters"; cat "$work/llvm.log"; fail=$((fail + 1))
  else
    pass=$((pass + 1))
    echo "ok   $name: $(wc -l <"$work/llvm.csv") rows identical, $(counters "$work/llvm.log" | head -1 | tr -s ' ');" \
      "default: $(grep -o 'tiering: \(compile started\|stayed on the VM\)' "$work/default.log" | head -1)"
  fi
done < <(find "$src/examples" -name '*.qd' | sort)
echo "backends: $pass models identical, $fail failed"
[ "$fail" -eq 0 ] && [ "$pass" -gt 10 ]
