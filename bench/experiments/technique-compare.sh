#!/usr/bin/env bash
# Compares two folders written by bench/experiments/technique-images.sh byte for byte: prints each file
# that differs or is missing on either side, then a count; exits 1 when any does.
#   bash bench/experiments/technique-compare.sh BEFORE_DIR AFTER_DIR
set -uo pipefail
before=$1
after=$2
differ=0
total=0
for f in "$before"/* "$after"/*; do
  name=$(basename "$f")
  [ "$f" = "$after/$name" ] && [ -e "$before/$name" ] && continue # counted from before
  total=$((total + 1))
  if [ ! -e "$before/$name" ] || [ ! -e "$after/$name" ]; then
    echo "only in one folder: $name"
    differ=$((differ + 1))
  elif ! cmp -s "$before/$name" "$after/$name"; then
    echo "differs: $name"
    differ=$((differ + 1))
  fi
done
echo "$differ of $total files differ"
[ "$differ" -eq 0 ]
