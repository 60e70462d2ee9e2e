#!/usr/bin/env bash
# Colour management through OpenColorIO (issue 42): `drift render --view Filmic` writes the
# PNG Blender itself makes of drift's EXR with its Filmic view (tests/data/ocio/blender_view.py:
# Blender's "Save as Render" of the loaded EXR, display sRGB, exposure 1, no dither), within
# ꟻLIP 0.02; the plain --tonemap PNG is not (the check can fail). Names a config does not
# have are usage errors before any rendering.
# Exits 77 (skipped) where drift was built without OpenColorIO or Blender is not installed.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
src="$(cd "$here/../.." && pwd)"
source "$here/common.sh"

"$drift" render --spp 1 --width 4 --height 4 --quiet --checkpoint 0 --view Standard \
    --out "$tmp/probe.exr" >/dev/null 2>"$tmp/err"
if grep -q "without" "$tmp/err"; then
    echo "cli.ocio_view: SKIPPED: drift was built without OpenColorIO (libopencolorio-dev)" >&2
    exit 77
fi
if ! command -v blender >/dev/null 2>&1 || ! blender --version >/dev/null 2>&1; then
    echo "cli.ocio_view: SKIPPED: Blender is not installed" >&2
    exit 77
fi

small=(--spp 16 --width 48 --height 36 --threads 2 --checkpoint 0 --quiet --seed 5 --exposure 1)
expect 0 "$drift" render "${small[@]}" --view Filmic --out "$tmp/filmic.exr"
expect 0 "$drift" render "${small[@]}" --out "$tmp/plain.exr"
timeout 300 blender -b --factory-startup -noaudio --python "$src/tests/data/ocio/blender_view.py" \
    -- --in "$tmp/filmic.exr" --out "$tmp/blender.png" --view Filmic --exposure 1 \
    >"$tmp/blender.log" 2>&1 || { tail -20 "$tmp/blender.log" >&2; fail "Blender failed"; }
expect 0 "$drift" diff "$tmp/blender.png" "$tmp/filmic.png" --json
flip=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['flip'])" "$tmp/out")
echo "cli.ocio_view: --view Filmic against Blender's Filmic: FLIP $flip (<= 0.02)"
python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) <= 0.02 else 1)" "$flip" ||
    fail "--view Filmic is not Blender's Filmic (FLIP $flip)"
expect 0 "$drift" diff "$tmp/blender.png" "$tmp/plain.png" --json
python3 -c "import json,sys; sys.exit(0 if json.load(open(sys.argv[1]))['flip'] > 0.05 else 1)" \
    "$tmp/out" || fail "the plain PNG matches Filmic too: the comparison cannot fail"

# Unknown names: exit 2 before rendering, naming what the config has.
expect 2 "$drift" render --spp 1 --width 4 --height 4 --view Filmc --out "$tmp/bad.exr"
grep -q "Filmic" "$tmp/err" || fail "an unknown view does not list the config's views"
expect 2 "$drift" render --spp 1 --width 4 --height 4 --view Filmic --ocio-config "$tmp/none.ocio" \
    --out "$tmp/bad.exr"
expect 2 "$drift" render --spp 1 --width 4 --height 4 --look "High Contrast" --out "$tmp/bad.exr"
[ -e "$tmp/bad.exr" ] && fail "an output was written after a --view usage error"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.ocio_view: ok"
