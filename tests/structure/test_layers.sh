#!/usr/bin/env bash
# The library's folders form one-way layers: a file in src/A includes a private header of
# src/B ("B/x.h") only when B is A or comes before A in CMakeLists.txt's DRIFT_MODULES (the
# layer order, lowest first). Fails, naming the file and the include, on any include that
# points up or sideways: the include cycles the technique table removed cannot come back.
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
modules=$(sed -n 's/^set(DRIFT_MODULES \(.*\))$/\1/p' "$root/CMakeLists.txt")
[ -n "$modules" ] || { echo "layers: no DRIFT_MODULES in CMakeLists.txt"; exit 1; }
declare -A rank
i=0
for m in $modules; do rank[$m]=$i; i=$((i + 1)); done
bad=0
checked=0
for m in $modules; do
  [ -d "$root/src/$m" ] || continue
  for file in "$root/src/$m"/*.[ch]; do
    [ -e "$file" ] || continue
    while IFS= read -r line; do
      dep=${line#*\"}
      dep=${dep%%/*}
      checked=$((checked + 1))
      if [ -z "${rank[$dep]+x}" ]; then
        echo "layers: ${file#$root/} includes \"$dep/...\", which is not a module in DRIFT_MODULES"
        bad=1
      elif [ "${rank[$dep]}" -gt "${rank[$m]}" ]; then
        echo "layers: ${file#$root/} ($m) includes ${line#*#include } from a higher layer ($dep)"
        bad=1
      fi
    done < <(grep -E '^#include "[a-z_]+/' "$file" | grep -v '^#include "drift/' || true)
  done
done
[ "$checked" -gt 0 ] || { echo "layers: no private includes found under $root/src"; exit 1; }
# The commands: tools/ (the commands and what they share) sits below bench/ (drift bench ...):
# a command may not reach up into a benchmark's header (drift report takes the frontier's
# whole-frame path tracer from tools/render_whole_frame.c, not from bench/).
bench_headers=$(cd "$root/bench" && ls *.h 2>/dev/null | tr '\n' '|')
for file in "$root"/tools/*.[ch] "$root"/tools/*/*.[ch]; do
  [ -e "$file" ] || continue
  while IFS= read -r line; do
    echo "layers: ${file#$root/} (tools) includes $line from bench/, a higher layer"
    bad=1
  done < <(grep -E '^#include "[a-z_]+\.h"' "$file" | grep -E "\"(${bench_headers%|})\"" || true)
done
# The knob tables: each technique folder's knobs.c includes the rows' header of src/frame, a
# lower layer (checked above with every private include), and nothing of src/hybrid.
for file in "$root"/src/*/knobs.c; do
  [ -e "$file" ] || continue
  grep -q '^#include "frame/knob_rows.h"' "$file" \
    || { echo "layers: ${file#$root/} does not declare its rows with frame/knob_rows.h"; bad=1; }
done
[ "$bad" -eq 0 ] && echo "layers: $checked private includes, every one points down or within its folder"
exit "$bad"
