#!/usr/bin/env bash
# Every JSON the CLI writes is valid JSON, whatever the scene path holds: a folder named with
# a quote, a backslash and a tab (render --stats, hybrid and refine stats, info --json,
# bench --json), and bad option values are named with the value (exit status 2).
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
odd="$tmp/quo\"te\\back	tab"
mkdir -p "$odd"
cp "$(dirname "$0")/../../scenes/cornell-box/"* "$odd/"
scene="$odd/cornell_box.json"
small=(--width 16 --height 12 --spp 1 --threads 2 --quiet)

# valid FILE KEY: FILE parses and its KEY field is the scene path, byte for byte.
valid() {
    python3 - "$1" "$scene" "$2" <<'PY' || fail "$1 is not valid JSON naming the scene"
import json, sys
d = json.load(open(sys.argv[1]))
assert d[sys.argv[3]] == sys.argv[2], d[sys.argv[3]]
PY
}

expect 0 "$drift" render "$scene" "${small[@]}" --checkpoint 0 --out "$tmp/r.exr" --stats "$tmp/r.json"
valid "$tmp/r.json" scene
expect 0 "$drift" render "$scene" "${small[@]}" --mode hybrid --shadows pcss --ism-vpls 8 \
    --out "$tmp/h.exr" --stats "$tmp/h.json"
valid "$tmp/h.json" scene
expect 0 "$drift" render "$scene" "${small[@]}" --mode hybrid --shadows pcss --refine sir \
    --budget 50 --out "$tmp/s.exr" --stats "$tmp/s.json"
valid "$tmp/s.json" scene
expect 0 "$drift" info "$scene" --json
valid "$tmp/out" scene
expect 0 "$drift" bench frame "$scene" --width 16 --height 12 --frames 1 --json
valid "$tmp/out" scene
# The stats files are written whole: no temporary file is left beside them.
ls "$tmp" | grep -q "\.tmp" && fail "a temporary stats file was left: $(ls "$tmp")"

# Bad values: the message names the option and the value.
expect 2 "$drift" render --spp many --out "$tmp/x.exr"
grep -q -- "--spp .*'many'" "$tmp/err" || fail "bad --spp value not named"
expect 2 "$drift" render --mode hybrid --dof blurry --out "$tmp/x.exr"
grep -q -- "--dof .*'blurry'" "$tmp/err" || fail "bad --dof value not named"
expect 2 "$drift" render --tonemap hable --out "$tmp/x.exr"
grep -q -- "--tonemap .*'hable'" "$tmp/err" || fail "bad --tonemap value not named"
expect 2 "$drift" view --shadows soft
grep -q -- "--shadows .*'soft'" "$tmp/err" || fail "bad view --shadows value not named"
expect 2 "$drift" bench frame --frames 0
grep -q -- "--frames .*'0'" "$tmp/err" || fail "bad bench --frames value not named"
[ -e "$tmp/x.exr" ] && fail "an output was written after a usage error"

# Every technique of every effect is in render's and view's --help (from the technique table).
expect 0 "$drift" render --help
cp "$tmp/out" "$tmp/render-help"
expect 0 "$drift" view --help
for effect in shadows reflections dof indirect; do
    for help in "$tmp/render-help" "$tmp/out"; do
        line=$(grep -E "^  --$effect " "$help")
        for t in aaf isg reference; do
            case "$effect:$t" in dof:aaf | indirect:isg) continue ;; esac
            echo "$line" | grep -qw "$t" || fail "--$effect help in $(basename "$help") lacks $t"
        done
    done
done

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.json: every JSON valid, every bad value named"
