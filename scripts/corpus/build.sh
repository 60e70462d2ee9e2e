#!/usr/bin/env bash
# Builds the corpus of issue 40 (scenes/corpus/README.md) into a folder:
#
#   scripts/corpus/build.sh [--out DIR] [--quick] [--only NAME,NAME]
#
# - models the Blender scenes (@NAME in scenes/corpus/corpus.json) with Blender 3.4's Python
#   API and its glTF exporter (scripts/corpus/blender_corpus.py) into DIR (default
#   build/corpus); without Blender they are left out, with a warning;
# - writes DIR/corpus.txt (every scene file, one absolute path a line, in the manifest's
#   order), DIR/corpus-fit.txt and DIR/corpus-judge.txt (the fitting and judging halves), the
#   lists `drift bench frontier --corpus` and the chooser's fit read.
# --quick leaves out the scenes marked large (loading takes tens of seconds: the Breakfast
# Room, the 871k-triangle dragon). Nothing big is committed: the scenes from ../shared are
# .json files in the repository that name the shared meshes.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
out="$root/build/corpus"
quick=0
only=""
while [ $# -gt 0 ]; do
    case "$1" in
    --out) out="$2"; shift 2 ;;
    --quick) quick=1; shift ;;
    --only) only="$2"; shift 2 ;;
    -h | --help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "build.sh: unknown option '$1' (see --help)" >&2; exit 2 ;;
    esac
done
shared="${DRIFT_SHARED:-$root/../shared}/scenes"
if [ ! -d "$shared" ]; then
    echo "build.sh: no shared scenes at $shared (set DRIFT_SHARED)" >&2
    exit 1
fi
mkdir -p "$out"
out="$(cd "$out" && pwd)"
# The manifest's scenes this build takes, as "name role file" lines.
python3 - "$root/scenes/corpus/corpus.json" "$quick" "$only" >"$out/.selected" <<'PY'
import json, sys
manifest, quick, only = sys.argv[1], sys.argv[2] == "1", [s for s in sys.argv[3].split(",") if s]
names = set()
for s in json.load(open(manifest))["scenes"]:
    names.add(s["name"])
    if (only and s["name"] not in only) or (quick and s.get("large")):
        continue
    print(s["name"], s["role"], s["file"])
for n in only:
    if n not in names:
        print("build.sh: --only names '%s', not in %s" % (n, manifest), file=sys.stderr)
        sys.exit(2)
PY
blender_scenes=$(awk '$3 ~ /^@/ { print $1 }' "$out/.selected" | paste -sd, -)
have_blender=0
if [ -n "$blender_scenes" ]; then
    if command -v blender >/dev/null 2>&1; then
        nice blender -b --factory-startup -noaudio --python "$root/scripts/corpus/blender_corpus.py" \
            -- --out "$out" --hdri "$shared/hdri" --only "$blender_scenes" >"$out/blender.log" 2>&1 || {
            echo "build.sh: Blender failed (see $out/blender.log)" >&2
            exit 1
        }
        have_blender=1
    else
        echo "build.sh: warning: no blender on PATH; the Blender scenes are left out" >&2
    fi
fi
: >"$out/corpus.txt"
: >"$out/corpus-fit.txt"
: >"$out/corpus-judge.txt"
while read -r name role file; do
    if [ "${file#@}" != "$file" ]; then
        [ "$have_blender" = 1 ] || continue
        path="$out/${file#@}"
    else
        path="$root/$file"
    fi
    if [ ! -f "$path" ]; then
        echo "build.sh: $name: $path is missing" >&2
        exit 1
    fi
    echo "$path" >>"$out/corpus.txt"
    echo "$path" >>"$out/corpus-$role.txt"
done <"$out/.selected"
rm -f "$out/.selected"
echo "build.sh: $(wc -l <"$out/corpus.txt") scenes in $out/corpus.txt" \
    "($(wc -l <"$out/corpus-fit.txt") fit, $(wc -l <"$out/corpus-judge.txt") judge)"
