#!/usr/bin/env bash
# The corpus scripts (issue 40, scenes/corpus/README.md): every scene of the manifest names a
# file that exists or a scene the Blender script models, with a role and a licence; and
# scripts/corpus/build.sh, at a small size (two Blender scenes and one shared one), writes the
# lists and scenes that drift renders. Skips (77) without Blender or ../shared.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
root="${DRIFT_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"

python3 - "$root" <<'PY' || fail "the corpus manifest is incomplete"
import json, os, re, sys
root = sys.argv[1]
scenes = json.load(open(os.path.join(root, "scenes/corpus/corpus.json")))["scenes"]
modelled = set(re.findall(r'"(bl-[a-z-]+)": ', open(os.path.join(root, "scripts/corpus/blender_corpus.py")).read()))
assert len(scenes) >= 12, len(scenes)
for s in scenes:
    assert s["role"] in ("fit", "judge") and s["stresses"] and s["licence"], s
    f = s["file"]
    if f.startswith("@"):
        assert f[1:].rsplit(".", 1)[0] in modelled, f
    else:
        assert os.path.isfile(os.path.join(root, f)), f
assert {s["role"] for s in scenes} == {"fit", "judge"}
PY

if ! command -v blender >/dev/null 2>&1 || [ ! -d "$root/../shared/scenes" ]; then
    echo "SKIP: no blender or no ../shared/scenes"
    exit 77
fi
expect 0 bash "$root/scripts/corpus/build.sh" --out "$tmp/corpus" --only bl-emissive,bl-textured,veach-mi
[ "$(wc -l <"$tmp/corpus/corpus.txt")" = 3 ] || fail "build.sh listed $(wc -l <"$tmp/corpus/corpus.txt") scenes, not 3"
while read -r scene; do
    # Cheap techniques: the test is that the scene loads and renders without a warning.
    expect 0 "$drift" render "$scene" --mode hybrid --width 24 --height 16 --threads 2 --quiet \
        --indirect ambient --shadows hard --out "$tmp/r.exr"
    grep -qi "warning" "$tmp/err" && fail "$scene: $(cat "$tmp/err")"
    [ -s "$tmp/r.exr" ] || fail "$scene: no image"
done <"$tmp/corpus/corpus.txt"
expect 2 bash "$root/scripts/corpus/build.sh" --out "$tmp/corpus" --only no-such-scene
exit $((failures > 0))
