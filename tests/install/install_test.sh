#!/usr/bin/env bash
# An installed qdot is complete and relocatable: `cmake --install` into a prefix, the prefix moved
# elsewhere, and then — with the build tree hidden (an empty folder mounted over it in a private
# mount namespace, where the machine allows it) — the installed qdot simulates a model and builds a
# standalone executable, which runs from another directory and writes the same CSV as the
# installed `qdot run`; it finds its installed standard library (`import Vibration.*;`) without
# flags, a user library through QDOT_PATH, and names the folders it searched when a package is
# missing (E0220). Usage: install_test.sh BUILD_DIR SOURCE_DIR
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

# --- libraries: the installed standard library, QDOT_PATH, and the error when a package is missing
# The standard library comes with the install: a model built from Vibration parts runs without
# flags and gives the same CSV as the build tree's qdot (which reads the library from the sources).
# Runs examples/DIR/NAME.qd, copied elsewhere, with the build tree's and with the installed qdot
# (from /, build tree hidden) for STOP seconds; the installed run's CSV must be the build tree's.
runs_like_build_tree() {
  local dir=$1 name=$2 stop=$3 package=$4
  cp "$src/examples/$dir/$name.qd" "$work/elsewhere/$name.qd"
  "$build/qdot" run "$work/elsewhere/$name.qd" --stop "$stop" >"$work/$name-build.csv" 2>"$work/run.log" \
    || { bad "build-tree qdot run $name.qd failed"; sed 's/^/    /' "$work/run.log"; }
  if (cd / && without_build_tree "$prefix/bin/qdot" run "$work/elsewhere/$name.qd" --stop "$stop") \
       >"$work/$name.csv" 2>"$work/run.log"; then ok; else
    bad "installed qdot run of a model with 'import $package.*;' failed"; sed 's/^/    /' "$work/run.log"
  fi
  [ -s "$work/$name.csv" ] && cmp -s "$work/$name.csv" "$work/$name-build.csv" && ok \
    || bad "$name: the installed qdot's CSV differs from the build tree's"
}
runs_like_build_tree vibration two_dof 0.5 Vibration
# released from rest at m1.s = 0.05, m2.s = 0 (the example's start values)
head -1 "$work/two_dof.csv" | grep -q '^time,m1.s,m2.s,' && sed -n 2p "$work/two_dof.csv" | grep -q '^0,0.05,0,' \
  && ok || bad "two_dof: not the columns m1.s, m2.s or not the start 0.05, 0"

# The Fluid package comes with the install too: Torricelli's tank (import Fluid.*;) from another
# directory gives the build tree's CSV.
runs_like_build_tree fluids torricelli 10 Fluid

# A user library on QDOT_PATH, as a folder (MyLib/package.qd, itself importing Vibration) and as a
# file (Extra.qd). MyLib.Oscillator is m = 1 on k = 4 from 0.1: s(t) = 0.1 cos 2t; Extra.Free
# has no force: y stays 1.
mkdir -p "$work/lib/MyLib"
cat >"$work/lib/MyLib/package.qd" <<'EOF'
package MyLib "a user library"
  model Oscillator "a mass on a spring to a wall, from Vibration parts"
    import Vibration.*;
    parameter Real m = 1, k = 1;
    Fixed wall;
    Spring spring(k = k);
    Mass mass(m = m, s(start = 0.1));
  equation
    connect(wall.a, spring.a);
    connect(spring.b, mass.a);
  end Oscillator;
end MyLib;
EOF
cat >"$work/lib/Extra.qd" <<'EOF'
package Extra
  model Free "a free particle at rest"
    coordinate Real y(start = 1);
  mechanics
    kinetic = 0.5*der(y)^2;
  end Free;
end Extra;
EOF
cat >"$work/elsewhere/uselib.qd" <<'EOF'
model UseLib
  import MyLib.*;
  Oscillator o(m = 1, k = 4);
  Extra.Free f;
end UseLib;
EOF
if (cd / && QDOT_PATH="$work/lib" without_build_tree "$prefix/bin/qdot" run "$work/elsewhere/uselib.qd" \
      --stop 1 --interval 0.5 --outputs o.mass.s,f.y) >"$work/uselib.csv" 2>"$work/run.log"; then ok; else
  bad "installed qdot run with QDOT_PATH failed"; sed 's/^/    /' "$work/run.log"
fi
awk -F, 'NR == 4 && $1 == 1 { e = $2 - 0.1 * cos(2); if (e < 0) e = -e; if (e < 1e-5 && $3 == 1) found = 1 }
         END { exit !found }' "$work/uselib.csv" && ok \
  || { bad "uselib: o.mass.s(1) is not 0.1 cos 2 = -0.0416147 or f.y is not 1"; cat "$work/uselib.csv"; }
# Without QDOT_PATH the library is not found: E0220 at the use, its help naming the directories searched.
(cd / && without_build_tree "$prefix/bin/qdot" check "$work/elsewhere/uselib.qd") >/dev/null 2>"$work/nolib.log" \
  && bad "uselib.qd checked without QDOT_PATH" || ok
grep -q "uselib.qd:3:3: error\[E0220\]: unknown class 'Oscillator'" "$work/nolib.log" && ok \
  || { bad "no E0220 at uselib.qd:3:3 without QDOT_PATH"; cat "$work/nolib.log"; }

# A missing package: E0220 whose help lists QDOT_PATH, the model's folder and the installed
# standard library — the install's, not the sources' (the source tree is not hidden).
printf 'model Missing\n  import NoSuchLib.*;\n  NoSuchLib.Part p;\nend Missing;\n' >"$work/elsewhere/missing.qd"
(cd / && QDOT_PATH="$work/lib" without_build_tree "$prefix/bin/qdot" check "$work/elsewhere/missing.qd") \
  >/dev/null 2>"$work/missing.log" && bad "missing.qd checked" || ok
grep -q "missing.qd:3:3: error\[E0220\]: unknown class 'NoSuchLib.Part'" "$work/missing.log" && ok \
  || { bad "missing package: no E0220 at missing.qd:3:3"; cat "$work/missing.log"; }
grep -qF "searched: $work/lib, $work/elsewhere, $prefix/share/qdot/stdlib" "$work/missing.log" && ok \
  || { bad "missing package: the help does not name QDOT_PATH, the model's folder and $prefix/share/qdot/stdlib"
       cat "$work/missing.log"; }

echo "install: $pass checks passed, $fail failed"
[ "$fail" -eq 0 ]
