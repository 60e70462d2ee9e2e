#!/usr/bin/env bash
# Mitsuba 3 scenes beside 0.6 (issue 42): tests/data/mitsuba/transforms_v3.xml (to_world,
# snake_case names, "x, y, z" values, <default> parameters and $name substitution) loads as its
# Mitsuba 0.6 twin transforms_v06.xml: the same scene summary and a bit-identical render. A
# $name without its <default> is an error naming the line; an unsupported element a warning
# naming its line.
# $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
data="$(cd "$here/../data/mitsuba" && pwd)"
source "$here/common.sh"

for v in v06 v3; do
    expect 0 "$drift" info "$data/transforms_$v.xml"
    grep -v "^scene " "$tmp/out" >"$tmp/info_$v.txt"
    grep -qi "warn" "$tmp/err" && fail "transforms_$v.xml: warnings: $(cat "$tmp/err")"
    expect 0 "$drift" render "$data/transforms_$v.xml" --spp 4 --width 24 --height 18 \
        --threads 2 --checkpoint 0 --quiet --out "$tmp/$v.exr"
done
cmp -s "$tmp/info_v06.txt" "$tmp/info_v3.txt" ||
    fail "the v3 scene is not its 0.6 twin: $(diff "$tmp/info_v06.txt" "$tmp/info_v3.txt")"
# The transforms were applied (the 8 m floor, 1 point + 1 spot + the area quad).
grep -q "^bounds *(-4 .*(4 3 4)" "$tmp/info_v3.txt" || fail "v3 transforms lost: $(cat "$tmp/info_v3.txt")"
grep -q "1 point, 1 spot, 2 triangle" "$tmp/info_v3.txt" || fail "v3 lights lost"
expect 0 "$drift" diff "$tmp/v06.exr" "$tmp/v3.exr" --json
grep -q '"rmse": 0[,}]' "$tmp/out" || fail "the v3 and 0.6 renders differ: $(cat "$tmp/out")"

# A parameter without its <default>: an error naming the line.
sed 's/<default name="red" value="0.7, 0.1, 0.1"\/>//' "$data/transforms_v3.xml" >"$tmp/nodefault.xml"
expect 1 "$drift" info "$tmp/nodefault.xml"
grep -q "nodefault.xml:30:.*red" "$tmp/err" || fail "a missing <default> is not named: $(cat "$tmp/err")"
# An unsupported element: a warning naming its line.
sed 's/<shape type="sphere">/<medium type="homogeneous"\/><shape type="sphere">/' \
    "$data/transforms_v3.xml" >"$tmp/medium.xml"
expect 0 "$drift" info "$tmp/medium.xml"
grep -q "medium.xml:[0-9]*.*medium" "$tmp/err" || fail "an unsupported element is not warned about"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.mitsuba3: ok"
