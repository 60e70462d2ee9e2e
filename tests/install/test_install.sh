#!/usr/bin/env bash
# libdrift as an installed product (issue 45): `cmake --install` into a fresh prefix puts the
# shared library, the public headers, drift::drift for find_package(drift) and drift.pc; the
# example (examples/render_frame.c) configures with find_package against that prefix alone,
# builds, runs and writes its hybrid frame and reference; its hybrid frame is the installed
# CLI's `drift render --mode hybrid` image exactly (drift diff: MSE 0); and the same example
# builds with nothing but `pkg-config --cflags --libs drift`.
# $1: the build folder, $2: the source folder, $3: cmake, $4: the C compiler.
set -u
build="$1" src="$2" cmake="$3" cc="$4"
source "$src/tests/cli/common.sh"
prefix="$tmp/prefix"

"$cmake" --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 ||
    { cat "$tmp/install.log"; fail "cmake --install failed"; exit 1; }
for f in include/drift/drift.h include/drift/hybrid.h include/drift/version.h bin/drift; do
    [ -e "$prefix/$f" ] || fail "the install lacks $f"
done
lib=$(find "$prefix" -name 'libdrift.so*' -type f | head -1)
config=$(find "$prefix" -name driftConfig.cmake | head -1)
pc=$(find "$prefix" -name drift.pc | head -1)
[ -n "$lib" ] && [ -n "$config" ] && [ -n "$pc" ] ||
    fail "the install lacks libdrift.so ($lib), driftConfig.cmake ($config) or drift.pc ($pc)"
grep -q "^Version: $(sed -n 's/^#define DRIFT_VERSION *"\(.*\)"/\1/p' "$prefix/include/drift/version.h")$" "$pc" ||
    fail "drift.pc's version is not DRIFT_VERSION"

# find_package(drift) from the prefix only: the example builds and runs.
"$cmake" -S "$src/examples" -B "$tmp/ex" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_C_COMPILER="$cc" \
    -DCMAKE_BUILD_TYPE=Debug >"$tmp/ex.log" 2>&1 && "$cmake" --build "$tmp/ex" >>"$tmp/ex.log" 2>&1 ||
    { cat "$tmp/ex.log"; fail "the example did not configure and build against the install"; exit 1; }
scene="$src/scenes/cornell-box/cornell_box.json"
expect 0 "$tmp/ex/render_frame" "$scene" "$tmp/ex-out" 32 4
for f in hybrid.exr hybrid.png reference.exr reference.png; do
    [ -s "$tmp/ex-out-$f" ] || fail "the example wrote no $f"
done
grep -q "^libdrift [0-9.]* (built against [0-9.]*)$" "$tmp/out" || fail "no version line: $(cat "$tmp/out")"
flip=$(sed -n 's/^FLIP(reference, hybrid) = //p' "$tmp/out")
python3 -c "import sys; f=float(sys.argv[1]); sys.exit(0 if 0 < f < 1 else 1)" "${flip:-x}" ||
    fail "the example's FLIP is not in (0, 1): '$flip'"

# The library gives the CLI's hybrid frame.
expect 0 "$prefix/bin/drift" render "$scene" --mode hybrid --width 32 --height 32 --quiet \
    --out "$tmp/cli.exr"
expect 0 "$prefix/bin/drift" diff "$tmp/cli.exr" "$tmp/ex-out-hybrid.exr" --json
python3 -c "import json,sys; d=json.load(open(sys.argv[1])); sys.exit(0 if d['mse'] == 0 else 1)" \
    "$tmp/out" || fail "the example's hybrid frame is not the CLI's: $(cat "$tmp/out")"

# pkg-config alone.
flags=$(PKG_CONFIG_PATH="$(dirname "$pc")" pkg-config --cflags --libs drift) ||
    fail "pkg-config does not find drift.pc"
# shellcheck disable=SC2086 # the flags are words
"$cc" -std=c11 "$src/examples/render_frame.c" $flags -o "$tmp/pc_example" 2>"$tmp/err" ||
    fail "the example does not build with pkg-config's flags: $(cat "$tmp/err")"
expect 2 "$tmp/pc_example"
grep -q "usage: render_frame" "$tmp/err" || fail "the pkg-config build does not run"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "install.example: all checks passed"
