#!/usr/bin/env bash
# The Python module over the installed libdrift (python/drift, docs/python.md): installed
# into a fresh prefix, imported from there with numpy; a hybrid frame it renders with a
# technique and a knob set by name is the CLI's image of the same options exactly; diff gives
# 0 against itself and a FLIP in (0, 1) against a reference; a bad knob raises drift.Error.
# Exits 77 (skipped) when no python3 with numpy is found.
# $1: the build folder, $2: the source folder, $3: cmake.
set -u
build="$1" src="$2" cmake="$3"
source "$src/tests/cli/common.sh"

py=""
for p in python3 /usr/bin/python3; do
    if command -v "$p" >/dev/null && "$p" -c "import numpy" 2>/dev/null; then py="$p"; break; fi
done
[ -n "$py" ] || { echo "python.module: SKIPPED: no python3 with numpy (python3-numpy)" >&2; exit 77; }

"$cmake" --install "$build" --prefix "$tmp/prefix" >"$tmp/install.log" 2>&1 ||
    { cat "$tmp/install.log"; fail "cmake --install failed"; exit 1; }
lib=$(find "$tmp/prefix" -name 'libdrift.so*' -type f | head -1)
# A library built with the sanitizers needs their runtimes loaded before Python.
preload=""
for rt in asan ubsan; do
    so=$(ldd "$lib" | sed -n "s/.*lib$rt.so[^ ]* => \([^ ]*\).*/\1/p" | head -1)
    [ -n "$so" ] && preload="$preload $so"
done
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
scene="$src/scenes/cornell-box/cornell_box.json"

"$tmp/prefix/bin/drift" render "$scene" --mode hybrid --width 32 --height 32 --shadows pcf \
    --ism-vpls 8 --quiet --out "$tmp/cli.exr" >/dev/null || fail "the CLI render failed"

LD_PRELOAD="${preload# }" PYTHONPATH="$(dirname "$(find "$tmp/prefix" -path '*python/drift/__init__.py')")/.." \
    "$py" - "$scene" "$tmp" <<'PY' || fail "the Python checks failed"
import sys
import numpy as np
import drift

scene_path, tmp = sys.argv[1], sys.argv[2]
assert drift.library_path.startswith(tmp), drift.library_path  # the installed library
assert drift.version().count(".") == 2, drift.version()
assert "pcf" in drift.techniques()["shadows"] and drift.knobs()["ism-vpls"] == "int"
with drift.Context(threads=2) as ctx:
    scene = ctx.load_scene(scene_path)
    frame = scene.render_hybrid(width=32, height=32, shadows="pcf", ism_vpls=8)
    assert frame.shape == (32, 32, 3) and frame.dtype == np.float32
    cli = drift.load_image(ctx, tmp + "/cli.exr")
    assert np.array_equal(frame, cli), "not the CLI's image: max |d| %g" % np.abs(frame - cli).max()
    drift.save_exr(ctx, tmp + "/py.exr", frame)
    assert np.array_equal(drift.load_image(ctx, tmp + "/py.exr"), frame)
    same = drift.diff(frame, frame, ctx=ctx)
    assert same["mse"] == 0 and same["flip"] == 0, same
    ref = scene.render_reference(width=32, height=32, spp=4)
    d = drift.diff(ref, frame, ctx=ctx)
    assert 0 < d["flip"] < 1 and d["mse"] > 0, d
    for bad in ({"shadows": "soft"}, {"ism_vpls": -1}, {"ism_vpls": 1e9}, {"no_such_knob": 1}):
        try:
            scene.render_hybrid(width=8, height=8, **bad)
            raise AssertionError("accepted %r" % bad)
        except drift.Error as e:
            assert list(bad)[0] in str(e), str(e)
print("python: frame = CLI bytes, flip against a 4 spp reference %.3f" % d["flip"])
PY

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "python.module: all checks passed"
