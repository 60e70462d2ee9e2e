#!/usr/bin/env bash
# docs/reference/cli.md, knobs.md and scene-formats.md are what scripts/gen-reference.sh prints
# from this drift's option, knob and scene-reader tables: regenerated into a temp dir, they
# must equal the committed pages (a diff and the command that fixes them otherwise), and every table row must have its header's
# columns (an unescaped '|' in a help text would break it). So must the technique pages'
# generated blocks (their knobs and measured rows, scripts/gen-technique-blocks.py).
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"
src="${DRIFT_SOURCE_DIR:-$(cd "$(dirname "$0")/../.." && pwd)}"

if ! "$drift" view --help >/dev/null 2>&1; then
    echo "SKIP: drift was built without the viewer; the reference is generated with it"
    exit 77
fi
bash "$src/scripts/gen-reference.sh" "$drift" "$tmp/ref" || fail "scripts/gen-reference.sh failed"
for page in cli.md knobs.md scene-formats.md; do
    if ! diff -u "$src/docs/reference/$page" "$tmp/ref/$page" >"$tmp/$page.diff"; then
        fail "docs/reference/$page is stale: run scripts/gen-reference.sh build/dev/bin/drift and commit it"
        head -40 "$tmp/$page.diff" >&2
    fi
done
pages=0
for page in "$tmp"/ref/pages/*.md; do
    [ -e "$page" ] || continue
    pages=$((pages + 1))
    name=$(basename "$page")
    if ! diff -u "$src/docs/$name" "$page" >"$tmp/$name.diff"; then
        fail "docs/$name's generated blocks are stale: run scripts/gen-reference.sh build/dev/bin/drift and commit it"
        head -40 "$tmp/$name.diff" >&2
    fi
done
[ "$pages" -ge 5 ] || fail "only $pages technique pages have generated blocks"
grep -q -- '--isg-search' "$tmp/ref/pages/isg.md" || fail "docs/isg.md's knob block has no --isg-search"
python3 - "$tmp/ref/cli.md" "$tmp/ref/knobs.md" "$tmp/ref/scene-formats.md" <<'PY' || fail "a Markdown table row has the wrong number of columns"
import re, sys
bad = 0
for path in sys.argv[1:]:
    columns, fence = None, False
    for n, line in enumerate(open(path), 1):
        fence ^= line.startswith("```")
        cells = len(re.findall(r"(?<!\\)\|", line)) if line.startswith("|") and not fence else 0
        if not cells:
            columns = None
        elif columns is None:
            columns = cells
        elif cells != columns:
            print(f"{path}:{n}: {cells - 1} columns, the header has {columns - 1}", file=sys.stderr)
            bad += 1
sys.exit(bad > 0)
PY
grep -q -- '--ism-vpls' "$tmp/ref/knobs.md" || fail "knobs.md does not list --ism-vpls"
grep -q '^## drift bench isg' "$tmp/ref/cli.md" || fail "cli.md has no drift bench isg"
# The scene-format reference lists every reader's table.
for want in '^| `.json` ' '^### light spot' '^| `fov_y` ' '^| `KHR_texture_transform` ' \
    '^| `map_Kd` ' '^| `bsdf plastic, roughplastic'; do
    grep -q "$want" "$tmp/ref/scene-formats.md" || fail "scene-formats.md has no line matching $want"
done
# Every JSON key the reader accepts is explained on docs/scene-format.md.
for key in $(sed -n '/^## JSON scene file keys/,/^## glTF/s/^| `\([a-z_]*\)` .*/\1/p' \
    "$tmp/ref/scene-formats.md" | sort -u); do
    grep -q "\`$key\`\|\"$key\"" "$src/docs/scene-format.md" \
        || fail "docs/scene-format.md does not explain the JSON key '$key'"
done
exit $((failures > 0))
