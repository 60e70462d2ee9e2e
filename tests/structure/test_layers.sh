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
# The technique families (frame/family.h): the conductor (src/hybrid) includes no technique
# folder's header; it reaches a family's settings, inputs, caches and counts only through the
# hooks of the family list (src/hybrid/families.c). Each listed family defines its hooks in
# its own folder's family.c, and each family.c is listed.
listed=$(grep -o '&drift_[a-z_]*_family' "$root/src/hybrid/families.c" | sed 's/^&drift_//; s/_family$//' || true)
listed=$(echo $listed)
[ -n "$listed" ] || { echo "layers: src/hybrid/families.c lists no family"; bad=1; }
technique_dirs=$(echo $listed | tr ' ' '|')
for file in "$root"/src/hybrid/*.[ch]; do
  [ -e "$file" ] || continue
  while IFS= read -r line; do
    echo "layers: ${file#$root/} (the conductor) includes $line: reach the family through its hooks"
    bad=1
  done < <(grep -E "^#include \"(${technique_dirs})/" "$file" || true)
done
for name in $listed; do
  file="$root/src/$name/family.c"
  if [ ! -e "$file" ] || ! grep -q "^const drift_family drift_${name}_family = {" "$file"; then
    echo "layers: family '$name' is listed in src/hybrid/families.c but src/$name/family.c does not define drift_${name}_family"
    bad=1
  fi
done
for file in "$root"/src/*/family.c; do
  [ -e "$file" ] || continue
  name=$(basename "$(dirname "$file")")
  [ "$name" = frame ] && continue # the hooks' own helpers
  echo " $listed " | grep -q " $name " \
    || { echo "layers: ${file#$root/} is not listed in src/hybrid/families.c"; bad=1; }
done
# The families' state (frame/family.h's slots): the frame holds each family's state only as
# an opaque slot, so its buffers (frame/frame.[ch], comments aside) name no family's type and
# hold no technique's cache;
# a family's slot is read through its own accessor, in its own folder (other families and
# SIR call that accessor, an include checked above); a family with a create hook says which
# slot its state goes to.
for name in $listed; do
  while IFS= read -r hit; do
    echo "layers: $hit names family '$name''s internals in the frame's layer: keep them in its slot"
    bad=1
  done < <(cd "$root" && grep -n "\bdrift_${name}_[a-z_]*" src/frame/frame.[ch] \
             | grep -v '^[^:]*:[0-9]*: *//' | cut -d: -f1,2 || true)
done
while IFS= read -r hit; do
  echo "layers: $hit: the frame's state holds a technique's cache; it belongs in its family's slot"
  bad=1
done < <(cd "$root" && grep -nHE '^\s+drift_(shadow_map|envmap|env_prefilter)\b[^;(]*;' src/frame/frame.h \
           | cut -d: -f1,2 || true)
while IFS= read -r hit; do
  echo "layers: $hit reads a family's slot directly: only frame/family.h's drift_family_state and the conductor do"
  bad=1
done < <(cd "$root" && grep -n 'family_state\[' src/*/*.[ch] \
           | grep -v '^src/frame/\(frame\|family\)\.h:' | grep -v '^src/hybrid/frame\.c:' \
           | cut -d: -f1,2 || true)
while IFS= read -r hit; do
  file=${hit%%:*}
  slot=$(echo "$hit" | sed 's/.*DRIFT_FAMILY_\([A-Z_]*\).*/\1/' | tr 'A-Z' 'a-z')
  case "$file" in
    src/frame/family.h | "src/$slot/"*) ;;
    *) echo "layers: $hit reads family '$slot''s slot outside src/$slot: use its accessor"; bad=1 ;;
  esac
done < <(cd "$root" && grep -nE 'DRIFT_FAMILY_(REALTIME|ISG|AAF|SSDO|ISM|MICRO|GLARE)\b' \
           src/*/*.[ch] tools/*.c bench/*.c 2>/dev/null | cut -d: -f1,2,3- || true)
for name in $listed; do
  file="$root/src/$name/family.c"
  [ -e "$file" ] || continue
  if grep -q '^ *\.create = ' "$file" && ! grep -qE '^ *\.slot = DRIFT_FAMILY_[A-Z]+,' "$file"; then
    echo "layers: src/$name/family.c has a create hook but no .slot for its state"
    bad=1
  fi
done
# The scene loaders: drift_scene_load reaches a format's loader only through the registry
# (src/io/scene_formats.c); no other file calls a load function of the registry's rows.
for fn in drift__scene_load_json_file drift__scene_load_mesh_file drift__scene_load_mitsuba; do
  while IFS= read -r hit; do
    echo "layers: $hit calls $fn outside the loaders' registry (src/io/scene_formats.c)"
    bad=1
  done < <(cd "$root" && grep -n "\b$fn(" src/*/*.c tools/*.c 2>/dev/null \
             | grep -v '^src/io/scene_formats.c:' | grep -v ":drift_result $fn(" \
             | cut -d: -f1,2 || true)
done
[ "$bad" -eq 0 ] && echo "layers: $checked private includes, every one points down or within its folder"
exit "$bad"
