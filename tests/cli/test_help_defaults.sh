#!/usr/bin/env bash
# `drift render --help` prints each effect's real default (issue 40): the technique marked
# "(default)" for every --<effect> is the one a `drift render --mode hybrid` with no technique
# flag reports in --stats, and the same for `drift view --help` (which starts from the same
# drift_hybrid_params_recommended). $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

"$drift" render --help >"$tmp/render-help.txt" 2>&1 || fail "render --help failed"
"$drift" view --help >"$tmp/view-help.txt" 2>&1 || fail "view --help failed"
expect 0 "$drift" render --mode hybrid --width 16 --height 12 --threads 2 --quiet \
    --out "$tmp/d.exr" --stats "$tmp/d.json"
python3 - "$tmp/d.json" "$tmp/render-help.txt" "$tmp/view-help.txt" <<'PY' || fail "--help defaults differ from the renderer's"
import json, re, sys
used = json.load(open(sys.argv[1]))["techniques"]
for path in sys.argv[2:]:
    marked = {}
    for line in open(path):
        m = re.match(r"\s+--(\w+) (?:T|NAME)\s+(.*)", line)
        if m and m.group(1) in used:
            d = re.findall(r"(\w+) \(default\)", m.group(2))
            assert len(d) == 1, (path, line)
            marked[m.group(1)] = d[0]
    assert set(marked) == set(used), (path, marked, used)
    assert marked == used, (path, marked, used)
print("help defaults:", used)
PY
exit $((failures > 0))
