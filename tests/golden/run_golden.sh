#!/usr/bin/env bash
# Golden files of every stage: for each tests/golden/<stage>/NAME.qd, the exact stdout of
#   qdot check --emit=<stage> NAME.qd
# run inside tests/golden/<stage> (so file names in the output are relative) must equal
# NAME.expected. Shows a unified diff for every difference.
# Usage: run_golden.sh QDOT_BINARY SOURCE_DIR [--bless]
#   --bless: write the current output as the expected output instead (review `git diff tests/golden`).
set -u
if [ $# -lt 2 ] || { [ $# -eq 3 ] && [ "$3" != "--bless" ]; } || [ $# -gt 3 ]; then
  echo "usage: $0 QDOT_BINARY SOURCE_DIR [--bless]" >&2
  exit 2
fi
qdot=$(realpath "$1")
golden=$2/tests/golden
bless=${3:-}
out=$(mktemp)
err=$(mktemp)
trap 'rm -f "$out" "$err"' EXIT
pass=0 fail=0 blessed=0
for dir in "$golden"/*/; do
  stage=$(basename "$dir")
  [ "$stage" = models ] && continue
  for model in "$dir"*.qd; do
    name=$(basename "$model" .qd)
    expected=$dir$name.expected
    (cd "$dir" && "$qdot" check --emit="$stage" "$name.qd") >"$out" 2>"$err"
    code=$?
    if [ $code -ne 0 ]; then
      echo "FAIL $stage/$name: qdot exited with $code"
      sed 's/^/    /' "$err"
      fail=$((fail + 1))
    elif [ -n "$bless" ]; then
      cmp -s "$out" "$expected" || { cp "$out" "$expected" && blessed=$((blessed + 1)) && echo "blessed $stage/$name"; }
    elif [ ! -f "$expected" ]; then
      echo "FAIL $stage/$name: no $stage/$name.expected (create it with scripts/bless-golden)"
      fail=$((fail + 1))
    elif ! diff -u --label "$stage/$name.expected" --label "qdot check --emit=$stage $name.qd" "$expected" "$out"; then
      echo "FAIL $stage/$name: the output differs from $stage/$name.expected (diff above)"
      fail=$((fail + 1))
    else
      pass=$((pass + 1))
    fi
  done
done
if [ -n "$bless" ]; then
  echo "golden: $blessed files rewritten, $fail failed; review them with: git diff tests/golden"
else
  echo "golden: $pass passed, $fail failed"
  [ $fail -gt 0 ] && echo "after a reviewed change: scripts/bless-golden, then review git diff tests/golden"
fi
[ $fail -eq 0 ]
