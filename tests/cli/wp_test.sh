#!/usr/bin/env bash
# qdot wp on the U-tube (x = (h/2) cos(sqrt(2 g / l) t), examples/textbook/utube.qd): the table,
# the CSV and the SVG exist; against --exact the error falls with rtol and stays within 10x of it
# (the calibrated tolerances, docs/accuracy.md); a bad --exact is a located error.
# Usage: wp_test.sh QDOT_BINARY SOURCE_DIR
set -u
qdot=$1
src=$2
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail=0
failed() { echo "FAIL $*"; fail=1; }

"$qdot" wp "$src/examples/textbook/utube.qd" --rtols 1e-3,1e-5,1e-7,1e-9 --exact 'x = h/2*cos(sqrt(2*g/l)*time)' \
  --backend llvm,bytecode -o "$out/utube" >"$out/table.txt" 2>"$out/log.txt" || failed "qdot wp exited $?: $(cat "$out/log.txt")"
grep -q "max |y - y_ref| over the output grid and the columns x" "$out/table.txt" || failed "no error definition in the table"
grep -q "reference: the exact solution x = h/2" "$out/table.txt" || failed "the reference is not stated"
grep -q "llvm/ida: slope of log(error) on log(rtol)" "$out/table.txt" || failed "no proportionality line"
[ "$(grep -c '^bytecode/ida ' "$out/table.txt")" -eq 4 ] || failed "not 4 bytecode rows"
[ -s "$out/utube.csv" ] || failed "no CSV"
[ "$(wc -l <"$out/utube.csv")" -eq 9 ] || failed "the CSV has not 1 + 8 lines"
grep -q '<polyline' "$out/utube.svg" && grep -q '</svg>' "$out/utube.svg" || failed "no SVG diagram"

# The llvm rows of the CSV: the error falls by at least 10x per two decades and stays within 10x of rtol.
awk -F, '$1 == "llvm/ida" {
  if ($18 != "ok") { print "FAIL run at rtol " $4 " failed"; bad = 1 }
  if ($8 > 10) { print "FAIL error/rtol " $8 " at rtol " $4; bad = 1 }
  if (n > 0 && $7 > previous / 10) { print "FAIL error " $7 " at rtol " $4 " did not fall from " previous; bad = 1 }
  previous = $7; n++ } END { exit bad }' "$out/utube.csv" || fail=1
# Both backends compute the same numbers (bit-identical runs): equal error columns.
diff <(awk -F, '$1 == "llvm/ida" {print $7}' "$out/utube.csv") \
     <(awk -F, '$1 == "bytecode/ida" {print $7}' "$out/utube.csv") >/dev/null || failed "backends disagree"

# A mistake in --exact names the column of the --exact text.
"$qdot" wp "$src/examples/textbook/utube.qd" --exact 'x = h/2*cos(omega*time)' -o "$out/bad" >/dev/null 2>"$out/err.txt"
code=$?
[ "$code" -eq 2 ] || failed "bad --exact exited $code, expected 2"
grep -q -- "--exact:1:13: error\[E0202\]: unknown name 'omega'" "$out/err.txt" || failed "no located error: $(cat "$out/err.txt")"
[ ! -e "$out/bad.csv" ] || failed "a CSV was written despite the error"

# Without a reference: a run 100x tighter than the tightest rtol, stated.
"$qdot" wp "$src/examples/textbook/utube.qd" --rtols 1e-4,1e-6 --csv "$out/t.csv" --svg "$out/t.svg" >"$out/t.txt" 2>&1 ||
  failed "wp without reference: $(cat "$out/t.txt")"
grep -q "reference: a run at rtol 1e-08" "$out/t.txt" || failed "tight-run reference not stated"
[ -s "$out/t.csv" ] && [ -s "$out/t.svg" ] || failed "--csv/--svg not written"
exit $fail
