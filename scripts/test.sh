#!/usr/bin/env bash
# The whole test suite: installs dependencies (the build set and the test tools), checks the
# formatting (clang-format, the repository's .clang-format), builds with ASan+UBSan and
# -Werror, builds the Release configuration (-Werror at -O2 sees more), runs the fuzzers for a
# bounded time (side by side), the threaded renders under ThreadSanitizer, then every ctest
# test with the core tests under valgrind beside them.
# It prints each phase's time and the ten slowest tests.
# DRIFT_TEST_INTENSITY scales statistical sample counts; DRIFT_FUZZ_SECONDS the fuzz time
# (10 s a target, the targets run side by side); DRIFT_CTEST_ARGS passes ctest options, e.g.
# DRIFT_CTEST_ARGS="-L unit" or "-LE slow" (README: test labels).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --test
jobs=$(nproc)
# ccache, when installed, makes a rebuild of unchanged files free.
launcher=()
if command -v ccache >/dev/null 2>&1; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi
# The sanitized builds (ASan+UBSan, fuzz, TSan) compile at -O1, as the sanitizers' own docs
# advise: the suite's tests take 2.0x fewer CPU-s than at -O0 (unit.hybrid 77 -> 27 CPU-s,
# every test 612 -> 310; docs/lab/2026-12-07-issue-45-s3.md) and every check still runs.
# valgrind's build stays at -O0, where memcheck reports no optimiser artefacts.
sanitized_opt=(-DCMAKE_C_FLAGS_DEBUG="-g -O1" -DCMAKE_CXX_FLAGS_DEBUG="-g -O1")
t_start=$(date +%s)
t_phase=$t_start
phases=""
times_file=$(mktemp)
trap 'rm -f "$times_file"' EXIT
# cpu_ms: sets cpu_now to the CPU time (user + sys, ms) of every finished child of this shell
# so far: the second line of the `times` builtin (run here, not in a $(...) subshell, whose
# children it would count instead).
cpu_ms() {
  times >"$times_file"
  cpu_now=$(awk 'NR == 2 { t = 0; for (i = 1; i <= 2; ++i) { split($i, a, /[ms]/); t += a[1] * 60 + a[2] }
                 printf "%d\n", t * 1000 }' "$times_file")
}
cpu_ms
cpu_phase=$cpu_now
cpu_start=$cpu_now
phase() { # phase NAME: ends the previous phase (its wall time and CPU time), names the next
  local now cpu
  now=$(date +%s)
  cpu_ms
  cpu=$cpu_now
  [ -n "${current:-}" ] &&
    phases="$phases$(printf '%6d s wall %7.1f CPU-s  %s' $((now - t_phase)) \
      "$(((cpu - cpu_phase) / 1000)).$((((cpu - cpu_phase) % 1000) / 100))" "$current")\n"
  t_phase=$now
  cpu_phase=$cpu
  current="$1"
  echo "== $1"
}

phase "format (clang-format --dry-run -Werror over every tracked .c and .h)"
git ls-files -z '*.c' '*.h' | xargs -0 -P "$jobs" -n 40 clang-format --dry-run -Werror

phase "build (Debug, ASan+UBSan, -Werror)"
cmake -S . -B build/dev -DCMAKE_BUILD_TYPE=Debug -DDRIFT_SANITIZE=address,undefined -DDRIFT_WERROR=ON \
  "${sanitized_opt[@]}" "${launcher[@]}" >/dev/null
cmake --build build/dev -j"$jobs"

phase "build (Release, -Werror)"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DDRIFT_BUILD_TESTS=OFF -DDRIFT_WERROR=ON \
  "${launcher[@]}" >/dev/null
cmake --build build/release -j"$jobs"

# The smoke run is reproducible: a fixed seed and a fixed number of runs a target
# (DRIFT_FUZZ_RUNS, default 3000) over the corpus, so CI's result does not depend on the
# machine's speed; DRIFT_FUZZ_SECONDS caps a target's time (a hang guard). Longer fuzzing
# (-max_total_time=N without -runs) is for finding new inputs: assimp 5.2's OBJ/MTL/PLY
# readers still crash on some (docs/reliability.md).
phase "fuzz smoke (libFuzzer, seed 1, ${DRIFT_FUZZ_RUNS:-3000} runs per target, $jobs at a time)"
# fuzzer-no-link instruments the library too, so libFuzzer sees coverage inside drift.
# CXX too: the library's one C++ file (src/io/image_exr_dwa.cpp) makes its links C++ links.
CC=clang CXX=clang++ cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=Debug -DDRIFT_BUILD_FUZZERS=ON \
  -DCMAKE_C_FLAGS=-fsanitize=fuzzer-no-link -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link \
  -DDRIFT_BUILD_TESTS=OFF -DDRIFT_SANITIZE=address,undefined -DDRIFT_WERROR=ON \
  "${sanitized_opt[@]}" "${launcher[@]}" >/dev/null
cmake --build build/fuzz -j"$jobs"
# shellcheck disable=SC2317 # run by xargs through export -f
fuzz_one() {
  local fuzzer=$1 name corpus work
  name=$(basename "$fuzzer")
  corpus=tests/fuzz/corpus/${name#fuzz_}
  work=$(mktemp -d)
  [ -d "$corpus" ] && cp -r "$corpus"/. "$work"/
  local runs=${DRIFT_FUZZ_RUNS:-3000}
  # assimp reads these two (its OBJ/MTL and PLY readers): their corpora, with every crashing
  # input found so far, run as regression tests; new mutants are exploratory fuzzing, since
  # assimp 5.2 still crashes on some (docs/reliability.md).
  case $name in fuzz_scene_mtl | fuzz_scene_ply) runs=0 ;; esac
  "$fuzzer" -seed=1 -runs="$runs" -max_total_time="${DRIFT_FUZZ_SECONDS:-120}" \
    -rss_limit_mb=4096 "$work" >"build/fuzz/$name.log" 2>&1 \
    || { tail -40 "build/fuzz/$name.log"; echo "fuzz: $name failed"; rm -rf "$work"; return 1; }
  rm -rf "$work"
  echo "fuzz: $name ok ($(grep -o 'Done [0-9]* runs' "build/fuzz/$name.log" || echo 'ran'))"
}
export -f fuzz_one
# Leaks inside assimp itself are suppressed (tests/fuzz/lsan.supp says which and why).
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
export DRIFT_FUZZ_SECONDS DRIFT_FUZZ_RUNS
for f in build/fuzz/fuzz_*; do [[ "$f" == *.log ]] || echo "$f"; done | xargs -P "$jobs" -I{} bash -c 'fuzz_one {}'

phase "tsan (ThreadSanitizer: the threaded renders at --threads 1, 2, 16, 256)"
cmake -S . -B build/tsan -DCMAKE_BUILD_TYPE=Debug -DDRIFT_SANITIZE=thread -DDRIFT_BUILD_TESTS=OFF \
  -DDRIFT_WERROR=ON "${sanitized_opt[@]}" "${launcher[@]}" >/dev/null
cmake --build build/tsan -j"$jobs" --target drift_cli
bash tests/tsan/test_tsan.sh build/tsan/bin/drift

phase "valgrind build (memcheck on a plain Debug build of the core tests, run beside ctest)"
cmake -S . -B build/valgrind -DCMAKE_BUILD_TYPE=Debug "${launcher[@]}" >/dev/null
cmake --build build/valgrind -j"$jobs" --target test_core test_sampling
# memcheck is one thread and about 60 CPU-s (test_sampling's chi-square quadrature, slowed
# ~50x): run before ctest, it left a core idle for a minute. It runs beside ctest instead, and
# the suite waits for it (and fails with it) after ctest.
valgrind_log=build/valgrind/memcheck.log
(
  for t in test_core test_sampling; do
    DRIFT_TEST_INTENSITY=0.1 valgrind --quiet --error-exitcode=9 --leak-check=full \
      --errors-for-leak-kinds=definite,indirect "build/valgrind/$t" >/dev/null ||
      { echo "valgrind: $t failed"; exit 1; }
    echo "valgrind: $t clean"
  done
) >"$valgrind_log" 2>&1 &
valgrind_pid=$!

phase "tests (ctest -j$jobs, memcheck beside it)"
status=0
# shellcheck disable=SC2086 # DRIFT_CTEST_ARGS is words
(cd build/dev && ctest -j"$jobs" --output-on-failure ${DRIFT_CTEST_ARGS:-}) || status=$?
phase "valgrind (the rest of memcheck after ctest; its CPU-s are all counted here)"
valgrind_status=0
wait "$valgrind_pid" || valgrind_status=$?
cat "$valgrind_log"
[ "$valgrind_status" -eq 0 ] || { echo "valgrind: failed"; status=1; }
phase "end"
echo "== the ten slowest tests (ctest's last run)"
bash scripts/slowest-tests.sh build/dev 10 || true
printf "== time by phase (CPU-s: user + sys of everything the phase ran; on 2 idle cores a
   phase takes at least CPU-s / 2)\n%b" "$phases"
cpu_ms
cpu_all=$((cpu_now - cpu_start))
echo "test.sh: $(($(date +%s) - t_start)) s in all (apt excluded), $((cpu_all / 1000)) CPU-s, exit $status"
exit "$status"
