#!/usr/bin/env bash
# drift render --reflection-edits: the worked example renders in both modes, and bad edit
# files (a bad field, an unknown mesh, NaN, an unknown key) exit 2 naming the file and line.
# Usage: test_reflection_edits.sh path/to/drift
set -u
drift=${1:?usage: test_reflection_edits.sh path/to/drift}
source "$(dirname "$0")/common.sh"
root=${DRIFT_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}
scene="$root/scenes/edit-teapot/edit_teapot.json"
edits="$root/scenes/edit-teapot/edit_teapot.edit.json"
small=(--width 32 --height 24 --spp 1 --quiet)

expect 0 "$drift" render "$scene" --reflection-edits "$edits" "${small[@]}" --out "$tmp/ref.exr"
expect 0 "$drift" render "$scene" --mode hybrid --reflections sharp --reflection-edits "$edits" \
    "${small[@]}" --ism-vpls 8 --out "$tmp/hyb.exr"

# bad NAME LINE TEXT...: the file NAME holding TEXT is refused at line LINE with exit 2.
bad() {
    local name=$1 line=$2
    shift 2
    printf '%s\n' "$@" >"$tmp/$name"
    expect 2 "$drift" render "$scene" --reflection-edits "$tmp/$name" "${small[@]}" \
        --out "$tmp/bad.exr"
    if ! grep -qF "$tmp/$name:$line:" "$tmp/err"; then
        fail "$name: no message naming $name:$line:"
        sed 's/^/    /' "$tmp/err" >&2
    fi
    if grep -qE "AddressSanitizer|LeakSanitizer|runtime error" "$tmp/err"; then
        fail "$name: sanitizer report"
    fi
}
point='"point": [0, 1.4, 2.0], "view": [0, 4.5, 7.5]'
bad bad_field.edit.json 3 '{' ' "constraints": [' \
    "  { \"mesh\": \"defaultobject\", $point, \"target\": \"left\" }" ' ]' '}'
bad unknown_mesh.edit.json 4 '{' ' "constraints": [' '  {' \
    "   \"mesh\": \"teapot\", $point, \"target\": [-8, 3, 6] }" ' ]' '}'
bad nan.edit.json 2 '{' " \"constraints\": [{ \"mesh\": \"defaultobject\", $point, \"target\": [NaN, 3, 6] }]" '}'
bad unknown_key.edit.json 2 '{' ' "colour": 1' '}'
bad hidden.edit.json 3 '{' ' "constraints": [' \
    '  { "mesh": "defaultobject", "point": [0, 1.4, -2.0], "view": [0, 4.5, 7.5], "target": [0, 9, 0] }' \
    ' ]' '}'

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "reflection edits: renders, and bad edit files rejected with file:line"
