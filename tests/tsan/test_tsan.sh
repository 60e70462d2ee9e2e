#!/usr/bin/env bash
# The threaded paths under ThreadSanitizer (issue 43): the path tracer, the hybrid frame with
# the techniques that keep per-thread state (ISM, micro-rendering, AAF) at small settings and
# the glare filter, each at --threads 1, 2, 16 and 256 on a 16x16 image. A data race (TSan's report)
# or a run that fails ends the script with status 1. $1 is a drift binary built with
# -DDRIFT_SANITIZE=thread (scripts/test.sh builds build/tsan). About half a minute on 2 cores.
set -u
drift=${1:?usage: test_tsan.sh path/to/tsan/drift}
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
# TBB and Embree are not instrumented: their internal synchronisation is invisible to TSan.
printf 'called_from_lib:libtbb.so.12\ncalled_from_lib:libembree3.so.3\n' >"$tmp/suppressions"
export TSAN_OPTIONS="halt_on_error=1 exitcode=66 suppressions=$tmp/suppressions ${TSAN_OPTIONS:-}"
failures=0
small=(--width 16 --height 16 --quiet)
runs=(
    "render --spp 1"
    "render --mode hybrid --indirect ism --ism-vpls 16 --ism-points 64 --ism-map-size 16"
    "render --mode hybrid --indirect micro --reflections micro --micro-points 2000 --micro-size 8"
    "render --mode hybrid --shadows aaf --spp 1 --indirect none"
)
# one NAME CMD...: runs a drift command under TSan into $tmp/NAME.*; a race or a failure leaves
# $tmp/NAME.fail with its report.
one() {
    local name=$1
    shift
    if ! timeout -k 2 120 "$drift" "$@" >/dev/null 2>"$tmp/$name.err"; then
        { echo "FAIL: drift $*"; head -40 "$tmp/$name.err"; } >"$tmp/$name.fail"
    fi
}
# Two commands at a time (the machine's cores; TSan's runs are mostly one thread busy): the
# glare run of a thread count reads that count's first render.
jobs=${DRIFT_TSAN_JOBS:-2}
for threads in 1 2 16 256; do
    k=0
    for r in "${runs[@]}"; do
        # shellcheck disable=SC2086
        one "t$threads-$k" $r "${small[@]}" --threads "$threads" --out "$tmp/t$threads-$k.exr" &
        k=$((k + 1))
        while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
    done
    wait
    one "g$threads" glare "$tmp/t$threads-0.exr" --out "$tmp/g$threads.exr" --psf-size 32 \
        --threads "$threads"
done
for f in "$tmp"/*.fail; do
    [ -e "$f" ] || continue
    cat "$f" >&2
    failures=$((failures + 1))
done
[ "$failures" -eq 0 ] || { echo "tsan: $failures failure(s)" >&2; exit 1; }
echo "tsan: no race in ${#runs[@]} renders and glare at --threads 1, 2, 16, 256"
