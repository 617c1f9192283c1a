#!/usr/bin/env bash
# An installed qdot is complete and relocatable: `cmake --install` into a prefix, the prefix moved
# elsewhere, and then — with the build tree hidden (an empty folder mounted over it in a private
# mount namespace, where the machine allows it) — the installed qdot simulates a model and builds a
# standalone executable, which runs from another directory and writes the same CSV as the
# installed `qdot run`. Usage: install_test.sh BUILD_DIR SOURCE_DIR
# (works in a temporary folder outside the build tree, removed at the end)
set -u
build=$(cd "$1" && pwd)
src=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail=0
pass=0
ok() { pass=$((pass + 1)); }
bad() { echo "FAIL $*"; fail=$((fail + 1)); }

mkdir -p "$work/empty" "$work/elsewhere"
cmake --install "$build" --prefix "$work/stage" >"$work/install.log" 2>&1 || { cat "$work/install.log"; exit 1; }
mv "$work/stage" "$work/moved"
prefix=$work/moved
for f in bin/qdot lib/qdot/libqdot_exe_main.a lib/qdot/libqdot_runtime.a lib/qdot/libqdot_vm.a share/qdot/stdlib; do
  [ -e "$prefix/$f" ] && ok || bad "install: no $f"
done

# Runs a command with the build tree hidden, if this machine lets us make a mount namespace.
hidden=0
if unshare -m --propagation private sh -c "mount --bind '$work/empty' '$build'" 2>/dev/null; then hidden=1; fi
without_build_tree() {
  if [ $hidden -eq 1 ]; then
    unshare -m --propagation private sh -c 'mount --bind "$1" "$2" && shift 2 && exec "$@"' sh "$work/empty" "$build" "$@"
  else
    "$@"
  fi
}
if [ $hidden -eq 1 ]; then  # the hiding works: the build tree's qdot is gone
  without_build_tree test -e "$build/qdot" && bad "the build tree is still visible" || ok
fi
[ $hidden -eq 1 ] || echo "note: cannot hide the build tree here (no mount namespace); testing the moved install only"

utube=$src/examples/textbook/utube.qd
cp "$utube" "$work/elsewhere/utube.qd"
for backend in llvm bytecode; do
  exe=$work/elsewhere/utube-$backend
  if without_build_tree "$prefix/bin/qdot" build "$work/elsewhere/utube.qd" -o "$exe" --backend $backend 2>"$work/build.log"; then
    ok
  else
    bad "installed qdot build --backend $backend failed"; sed 's/^/    /' "$work/build.log"; continue
  fi
  (cd / && without_build_tree "$exe" --stop 2 --interval 0.1 -p h=0.2) >"$work/exe-$backend.csv" || bad "$exe failed"
  without_build_tree "$prefix/bin/qdot" run "$work/elsewhere/utube.qd" --backend $backend --stop 2 --interval 0.1 \
    -p h=0.2 >"$work/run-$backend.csv" 2>"$work/run.log" || bad "installed qdot run failed"
  if [ -s "$work/exe-$backend.csv" ] && cmp -s "$work/exe-$backend.csv" "$work/run-$backend.csv"; then ok; else
    bad "$backend: the executable's CSV differs from qdot run's"; diff "$work/exe-$backend.csv" "$work/run-$backend.csv" | head -5
  fi
done
# The executable's first row is the start value h/2 = 0.1 (physics, not qdot's echo).
grep -q '^0,0.1,0' "$work/exe-llvm.csv" && ok || bad "exe: first row is not x = h/2 = 0.1"

echo "install: $pass checks passed, $fail failed"
[ "$fail" -eq 0 ]
