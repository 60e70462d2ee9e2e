#!/usr/bin/env bash
# slowest-tests.sh [BUILD_DIR [N]]: the N slowest tests of ctest's last run in BUILD_DIR
# (Testing/Temporary/LastTest.log), slowest first, and the sum of all; without a logged run,
# ctest's running averages (Testing/Temporary/CTestCostData.txt).
set -euo pipefail
dir=${1:-build/dev}
n=${2:-10}
tmp="$dir/Testing/Temporary"
times=""
if [ -f "$tmp/LastTest.log" ]; then
  # A "<k>/<m> Test: NAME" line, later "Test time = S sec" for that test.
  times=$(awk '/^[0-9]+\/[0-9]+ Test: / { name = $3 }
               /^Test time = / { if (name != "") { print $4, name; name = "" } }' "$tmp/LastTest.log")
fi
if [ -z "$times" ] && [ -f "$tmp/CTestCostData.txt" ]; then
  echo "(no logged run: ctest's running averages)"
  times=$(awk '$1 == "---" { exit } NF == 3 { print $3, $1 }' "$tmp/CTestCostData.txt")
fi
[ -n "$times" ] || { echo "slowest-tests: no test times in $tmp (run ctest first)" >&2; exit 1; }
echo "$times" | sort -rn | head -n "$n" | awk '{ printf "%8.1f s  %s\n", $1, $2 }'
echo "$times" | awk '{ s += $1 } END { printf "%8.1f s  all %d tests, summed\n", s, NR }'
