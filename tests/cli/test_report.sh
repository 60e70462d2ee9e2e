#!/usr/bin/env bash
# CLI tests for `drift report` (issue 20): usage errors; a tiny report of the built-in Cornell
# box opened in headless Chromium (tests/cli/report_browser.py: no console error, no network,
# images exist, slider, plot marks (the sir cell: raster + 2 iteration counts, one curve),
# screenshot, numbers equal drift diff's); the cache (a rerun renders nothing, --time-budget
# keeps what is finished and a rerun goes on); Ctrl-C;
# a scene that fails to load and an effect without reference get cells saying so and a
# non-zero exit. Without chromium (or with DRIFT_TEST_BROWSER=OFF, CMake's option) the browser
# checks are left out and said so. $1 is the drift binary.
set -u
drift="$1"
here="$(dirname "$0")"
source "$here/common.sh"

browser_checks=1
if [[ "${DRIFT_TEST_BROWSER:-ON}" =~ ^(OFF|off|0|FALSE|false|NO|no)$ ]] ||
    { ! command -v chromium >/dev/null && ! command -v chromium-browser >/dev/null; }; then
    echo "cli.report: the browser checks are off: chromium is not installed (bash scripts/install-deps.sh --test) or DRIFT_TEST_BROWSER=OFF" >&2
    browser_checks=0
fi

small=(--size 40 --ref-spp 16 --sweep-spp 2 --threads 2)
browser() { python3 "$here/report_browser.py" "$drift" "$@"; }

# Usage errors name the option.
expect 2 "$drift" report
grep -q -- "--out DIR is required" "$tmp/err" || fail "no --out: no message naming --out"
expect 2 "$drift" report --out "$tmp/r" --effects shadows,fog
grep -q -- "--effects expects effects from" "$tmp/err" || fail "bad --effects: no message"
expect 2 "$drift" report --out "$tmp/r" --size 0
grep -q -- "--size" "$tmp/err" || fail "bad --size: no message naming --size"

# The budget: nothing started after the first render, the page says what is missing.
expect 1 "$drift" report --out "$tmp/r" --effects shadows,sir "${small[@]}" \
    --time-budget 0.000001
grep -q "time-budget" "$tmp/err" || fail "--time-budget: no message"
finished=$(python3 -c "import json; print(len(json.load(open('$tmp/r/manifest.json'))['renders']))")
[ "$finished" -eq 1 ] || fail "--time-budget: $finished renders finished, expected the first one"
grep -q "not rendered: --time-budget spent" "$tmp/r/index.html" ||
    fail "--time-budget: the page does not say what was not rendered"

# The full report renders only what is missing (and the sir cell: the raster frame and 2
# iteration counts against the whole-frame truth), then the page passes the browser checks.
# Shadows and the sir cell: two kinds of cell at a third of the time indirect light's seven
# techniques took (every technique's run is cli.render_hybrid's).
with_sir=(--effects shadows,sir --sir-iterations 2,1)
expect 0 "$drift" report --out "$tmp/r" "${with_sir[@]}" "${small[@]}"
cached=$(grep -c ": cached, ETA" "$tmp/err")
[ "$cached" -eq "$finished" ] || fail "rerun: $cached renders reused, expected $finished"
grep -q "wrote $tmp/r/index.html (complete)" "$tmp/out" || fail "report does not say where"
cp -r "$tmp/r" "$tmp/good"

# A rerun with the same options renders nothing.
expect 0 "$drift" report --out "$tmp/r" "${with_sir[@]}" "${small[@]}"
if grep -q " s, ETA" "$tmp/err"; then fail "an unchanged rerun rendered again"; fi

# A missing scene and an effect with no reference: cells say so, the rest renders, exit 1.
expect 1 "$drift" report "$DRIFT_SOURCE_DIR/scenes/cornell-box/cornell_box.json" \
    "$tmp/no-such-scene.json" --out "$tmp/r" --effects shadows,glare "${small[@]}"
grep -q "shadows-hard" "$tmp/r/index.html" || fail "the failing report lost the scene that loads"
# Both pages in one browser (it takes seconds to start).
if [ "$browser_checks" -eq 1 ]; then
    browser "$tmp/good" --sir-marks 3 "$tmp/r" --expect-error "no-such-scene.json: the scene failed to load" \
        --expect-error "glare: glare has no path-traced reference" --no-numbers || fail "the browser checks failed"
fi

# Ctrl-C during a long reference: exit 130 and a page that says it was interrupted.
"$drift" report --out "$tmp/int" --effects shadows --size 200 --ref-spp 4096 --threads 1 \
    >"$tmp/out" 2>"$tmp/err" &
pid=$!
for _ in $(seq 100); do [ -d "$tmp/int" ] && break; sleep 0.1; done
sleep 1
kill -INT "$pid"
wait "$pid"
status=$?
[ "$status" -eq 130 ] || fail "SIGINT: exit $status, expected 130"
grep -q "interrupted" "$tmp/int/index.html" 2>/dev/null || fail "SIGINT: no page saying so"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.report: all checks passed"
