#!/usr/bin/env bash
# A run that cannot write one of its outputs writes none of them (issue 18): every output
# path is checked before rendering, the message names the option, the file and the OS's
# reason. And the --stats JSON stays valid whatever the scene path holds. $1: drift binary.
set -u
drift="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
source "$(dirname "$0")/common.sh"
cd "$tmp" || exit 1

cat >s.json <<'JSON'
{ "camera": { "position": [0, 0, 1], "target": [0, 0, 0], "fov_y": 40, "width": 8, "height": 8 },
  "environment": { "color": 1 } }
JSON
mkdir adir
touch afile
fast=(--spp 1 --quiet)

# no_outputs WHAT REASON: nothing but the inputs (and out, err) is left in $tmp.
no_outputs() {
    local left
    left="$(ls | grep -v -x -e s.json -e adir -e afile -e out -e err -e 'q"uote\\.json')"
    [ -n "$left" ] && fail "$1: left $left behind" && rm -f $left
    grep -q "$2" "$tmp/err" || { fail "$1: the reason '$2' is not given"; sed 's/^/  /' err >&2; }
}

expect 1 "$drift" render s.json "${fast[@]}" --out o.exr --stats nodir/s.json
no_outputs "--stats nodir/s.json" "stats 'nodir/s.json': No such file or directory"
expect 1 "$drift" render s.json --mode hybrid --quiet --out h.exr --aov nodir/a.exr
no_outputs "hybrid --aov nodir/a.exr" "aov 'nodir/a.exr': No such file or directory"
expect 1 "$drift" render s.json "${fast[@]}" --out o.exr --stats afile/s.json
no_outputs "--stats under a file" "Not a directory"
expect 1 "$drift" render s.json "${fast[@]}" --out o.exr --stats adir
no_outputs "--stats a folder" "Is a directory"
expect 1 "$drift" diff s.json s.json --heatmap nodir/h.png
no_outputs "diff --heatmap nodir/h.png" "No such file or directory"

# A write that fails after the images were made (here: --stats' folder removed during the
# render) leaves none of the outputs: they are staged and renamed together at the end. The
# checkpoint beside --out keeps the work.
mkdir sub
"$drift" render s.json --spp 16000000 --threads 1 --out o.exr --stats sub/s.json >out 2>err &
pid=$!
for i in $(seq 100); do
    grep -q "spp, depth" err && break
    sleep 0.1
done
rm -r sub
kill -INT "$pid"
wait "$pid"
status=$?
[ "$status" -eq 1 ] || fail "a failed --stats write after rendering exited $status, expected 1"
rm -f o.ckpt
no_outputs "--stats folder removed mid-run" "No such file or directory"

# The same in hybrid mode, plain and refined: --out, its PNG and --aov are staged with
# --stats, so --stats' folder removed while the frames render leaves none of them. The run is
# stopped (SIGSTOP) while the folder goes, so the check holds however fast the frames are; a
# run that had already begun writing when it was stopped is inconclusive and is repeated
# with four times the frames.
for refine in "" "--refine sir"; do
    frames=16
    for attempt in 1 2 3 4; do
        mkdir sub
        # shellcheck disable=SC2086 # $refine is two words or none
        "$drift" render s.json --mode hybrid $refine --frames "$frames" --width 32 --height 32 \
            --out h.exr --aov a.exr \
            --stats sub/s.json >out 2>err &
        pid=$!
        for i in $(seq 500); do
            grep -q "hybrid frame of" err && break
            sleep 0.02
        done
        kill -STOP "$pid" 2>/dev/null
        # Conclusive: the run is still going (not a zombie) and has written nothing into sub.
        state=$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null)
        if [ -n "$state" ] && [ "$state" != Z ] && [ -z "$(ls -A sub)" ]; then
            rm -r sub
            kill -CONT "$pid"
            wait "$pid"
            status=$?
            [ "$status" -eq 1 ] || fail "hybrid $refine: a failed --stats write exited $status, expected 1"
            no_outputs "hybrid $refine: --stats folder removed mid-run" "No such file or directory"
            break
        fi
        kill -CONT "$pid" 2>/dev/null
        wait "$pid"
        rm -rf sub h.exr h.png a.exr
        frames=$((frames * 4))
        [ "$attempt" -eq 4 ] && fail "hybrid $refine: every run ended before it could be stopped"
    done
done

# The stats JSON is escaped (cJSON): a scene path with a quote and a backslash.
cp s.json 'q"uote\.json'
expect 0 "$drift" render 'q"uote\.json' "${fast[@]}" --out o.exr --stats o.json
python3 -c 'import json, sys; assert json.load(open("o.json"))["scene"] == sys.argv[1]' \
    'q"uote\.json' || fail "--stats of a scene path with a quote is valid JSON"

if [ "$failures" -ne 0 ]; then
    echo "$failures failure(s)" >&2
    exit 1
fi
echo "cli.all_or_nothing: all checks passed"
