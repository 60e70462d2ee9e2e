#!/usr/bin/env bash
# CLI tests for `drift view` in a virtual X server (Xvfb): frames of the built-in scene saved
# from the window are a real, non-blank image; the split view, the overlay and key presses
# reach the window; usage errors; and a clear message without a display.
# $1 is the drift binary.
set -u
drift="$1"
source "$(dirname "$0")/common.sh"

# CI installs xvfb and xauth (scripts/install-deps.sh): a missing xvfb-run is a failure, not a skip.
if ! command -v xvfb-run >/dev/null 2>&1; then
    echo "FAIL: xvfb-run not found; install the xvfb and xauth packages (bash scripts/install-deps.sh)" >&2
    exit 1
fi
# The Debug test build uses AddressSanitizer. LeakSanitizer reports memory that SDL, X11, dbus
# and Mesa keep until the process ends (not drift's, and not freeable by SDL_Quit), so leak
# checking is off for this script only; the unit tests keep it on for the view core.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"

# check_shot NAME: the PNG exists, has the PNG signature, and the summary line that
# `drift view --screenshot` prints (see --help) shows a window read-back that is not blank:
# a mean above black and many distinct colours.
check_shot() {
    local png="$tmp/$1.png"
    [ -s "$png" ] || { fail "$1: no screenshot written"; return; }
    [ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] \
        || fail "$1: $png is not a PNG"
    local line
    line=$(grep -E "^wrote $png \([0-9]+x[0-9]+, [0-9]+ frames, window\): mean [0-9.]+, [0-9]+ colours$" "$tmp/out") \
        || { fail "$1: no summary line for a window read-back: $(cat "$tmp/out")"; return; }
    local mean colours
    mean=$(echo "$line" | sed -E 's/.*mean ([0-9.]+),.*/\1/')
    colours=$(echo "$line" | sed -E 's/.* ([0-9]+) colours$/\1/')
    awk -v m="$mean" 'BEGIN { exit !(m > 0.02 && m < 0.98) }' || fail "$1: blank image (mean $mean)"
    [ "$colours" -ge 50 ] || fail "$1: only $colours colours: blank or flat"
}

# Three frames of the built-in Cornell box at 160x120, read back from the window. --indirect
# none: the default indirect light (ism) costs seconds a frame under the sanitizers, and
# these checks are of the window, not of the image.
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --indirect none --frames 3 \
    --screenshot "$tmp/shot.png"
check_shot shot
grep -q "(160x120, 3 frames, window)" "$tmp/out" || fail "screenshot size or frame count wrong"

# Split view with the reference, the overlay off, and a key pressed by name: the image
# differs from the plain one (drift diff: non-zero error).
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --indirect none --frames 2 --no-overlay \
    --screenshot "$tmp/plain.png"
check_shot plain
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --indirect none --frames 2 --no-overlay \
    --split --spp-per-frame 1 --press next-buffer --screenshot "$tmp/split.png"
check_shot split
expect 0 "$drift" diff "$tmp/plain.png" "$tmp/split.png" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse'] > 0 else 1)" \
    || fail "split view with another buffer looks the same as the plain frame"

# Temporal reuse is the viewer's default (a still camera converges; docs/temporal.md): three
# plain frames are --temporal on's, bit for bit, and not --temporal off's.
for t in on off; do
    expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --indirect none --frames 3 \
        --no-overlay --temporal "$t" --screenshot "$tmp/temporal_$t.png"
done
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --indirect none --frames 3 \
    --no-overlay --screenshot "$tmp/temporal_default.png"
cmp -s "$tmp/temporal_default.png" "$tmp/temporal_on.png" || fail "the viewer's default is not --temporal on"
cmp -s "$tmp/temporal_default.png" "$tmp/temporal_off.png" && fail "--temporal off changes nothing"

# The knob panel: a knob of the knob table set from the viewer (knob-next/-prev select,
# knob-up steps: the second knob, --aa, from 1 to 2) gives the frame the command line's
# --aa 2 gives, and not the default frame.
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --frames 2 --no-overlay \
    --press knob-next,knob-prev,knob-next,knob-up,overlay --screenshot "$tmp/knob.png"
check_shot knob
expect 0 xvfb-run -a "$drift" view --width 160 --height 120 --threads 2 --frames 2 --no-overlay \
    --aa 2 --screenshot "$tmp/knob_cli.png"
check_shot knob_cli
expect 0 "$drift" diff "$tmp/knob.png" "$tmp/knob_cli.png" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse'] == 0 else 1)" \
    || fail "--press knob-up does not give the frame of --aa 2"
expect 0 "$drift" diff "$tmp/plain.png" "$tmp/knob.png" --json
python3 -c "import json,sys; d=json.load(open('$tmp/out')); sys.exit(0 if d['mse'] > 0 else 1)" \
    || fail "--press knob-up left the frame as it was"
expect 2 "$drift" view --light-samples 0
grep -q -- "--light-samples" "$tmp/err" || fail "a knob's range error does not name it"

# Usage errors: exit 2 with a message, before any window opens.
expect 2 "$drift" view --bogus
expect 2 "$drift" view --shadows nope
grep -q "pcss" "$tmp/err" || fail "--shadows error does not list the techniques"
expect 2 "$drift" view --screenshot "$tmp/x.jpg"
expect 2 "$drift" view --frames 0
expect 2 "$drift" view --press nokey
expect 0 "$drift" view --help
grep -q -- "--screenshot" "$tmp/out" || fail "--help does not describe --screenshot"
grep -q "xvfb-run" "$tmp/out" || fail "--help does not mention xvfb-run"

# No display: a clear error naming xvfb-run, exit 1 (SDL's windowless fallback driver does
# not count as a display).
expect 1 env -u DISPLAY -u WAYLAND_DISPLAY -u SDL_VIDEODRIVER "$drift" view --frames 1
grep -q "xvfb-run" "$tmp/err" || fail "no-display error does not suggest xvfb-run: $(cat "$tmp/err")"

# A missing scene fails clearly, naming the file. drift exits at once here, and xvfb-run's own
# clean-up can then race its X server and exit 5 ("problem while cleaning up temporary
# directory"), so the status checked is drift's, passed out through a file.
drift_under_xvfb() {
    xvfb-run -a sh -c '"$@"; echo $? >"$0"' "$tmp/status" "$@"
    return "$(cat "$tmp/status" 2>/dev/null || echo 99)"
}
expect 1 drift_under_xvfb "$drift" view "$tmp/nope.json" --frames 1
grep -q "nope.json" "$tmp/err" || fail "missing scene not named in the error"

if [ "$failures" -ne 0 ]; then
    echo "$failures view CLI check(s) failed"
    exit 1
fi
echo "view CLI: all checks passed"
