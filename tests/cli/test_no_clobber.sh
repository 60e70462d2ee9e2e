#!/usr/bin/env bash
# Outputs never overwrite inputs (issue 18): an output that is the same file as an input (the
# scene, a texture it reads, an image diff or glare reads) or as another output is refused
# with exit 2, a message naming both, and nothing written. Files are compared by identity
# (./x, hard and symbolic links), not by spelling. $1 is the drift binary.
set -u
drift="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
source "$(dirname "$0")/common.sh"
cd "$tmp" || exit 1

"$drift" render --spp 1 --width 8 --height 8 --quiet --out tex.exr >/dev/null 2>&1 ||
    fail "cannot make the texture"
cat >s.json <<'JSON'
{ "camera": { "position": [0, 0, 1], "target": [0, 0, 0], "fov_y": 40, "width": 8, "height": 8 },
  "environment": { "map": "tex.exr" } }
JSON
ln tex.exr hard.exr
ln -s s.json link.json
sums() { cksum s.json tex.exr tex.png 2>/dev/null; }
sums >before

# refused WHAT CMD...: exit 2, the clash explained, the inputs unchanged, no new file.
refused() {
    local what="$1"
    shift
    ls >files.before
    expect 2 "$@"
    grep -q "same file\|refusing to overwrite" "$tmp/err" || fail "$what: no reason given"
    sums | cmp -s - before || fail "$what: an input was changed"
    local new
    new="$(ls | grep -v -x -f files.before | grep -v -x -e out -e err)"
    [ -n "$new" ] && fail "$what: wrote $new"
}

refused "--stats the scene" "$drift" render s.json --spp 1 --quiet --out o.exr --stats s.json
refused "--stats a link to the scene" "$drift" render s.json --spp 1 --quiet --out o.exr --stats link.json
refused "--stats ./the scene" "$drift" render s.json --spp 1 --quiet --out o.exr --stats ./s.json
refused "--stats the --out" "$drift" render s.json --spp 1 --quiet --out o.exr --stats ./o.exr
refused "--stats the --out's PNG" "$drift" render s.json --spp 1 --quiet --out o.exr --stats o.png
refused "--out the texture" "$drift" render s.json --spp 1 --quiet --out tex.exr
refused "--out a hard link to the texture" "$drift" render s.json --spp 1 --quiet --out hard.exr
refused "--aov the --out" "$drift" render s.json --mode hybrid --quiet --out h.exr --aov ./h.exr
refused "--aov the scene's texture" "$drift" render s.json --mode hybrid --quiet --out h.exr --aov tex.exr
refused "--heatmap the test image" "$drift" diff tex.png tex.png --heatmap tex.png
refused "--heatmap the reference" "$drift" diff tex.png tex.exr --heatmap ./tex.png
refused "glare --out IN" "$drift" glare tex.exr --out ./tex.exr
refused "glare --out a hard link to IN" "$drift" glare tex.exr --out hard.exr
refused "glare --psf the --out" "$drift" glare tex.exr --out g.png --psf g.png

# Different files still work.
expect 0 "$drift" render s.json --spp 1 --quiet --out o.exr --stats o.json
[ -s o.exr ] && [ -s o.json ] || fail "a render with distinct outputs writes them"
expect 0 "$drift" diff tex.png o.png --heatmap heat.png
[ -s heat.png ] || fail "diff with a distinct heat map writes it"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.no_clobber: all checks passed"
