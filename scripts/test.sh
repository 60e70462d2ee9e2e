#!/usr/bin/env bash
# The whole test suite: installs dependencies, checks the formatting (clang-format, the
# repository's .clang-format), builds with ASan+UBSan and -Werror, runs every
# unit and CLI test, builds the Release configuration (-Werror at -O2 sees more), runs the
# fuzzers for a bounded time, the threaded renders under ThreadSanitizer and the core tests
# under valgrind.
# DRIFT_TEST_INTENSITY scales statistical sample counts; DRIFT_FUZZ_SECONDS the fuzz time.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
jobs=$(nproc)

echo "== format (clang-format --dry-run -Werror over every tracked .c and .h)"
git ls-files -z '*.c' '*.h' | xargs -0 clang-format --dry-run -Werror

echo "== build (Debug, ASan+UBSan, -Werror)"
cmake -S . -B build/dev -DCMAKE_BUILD_TYPE=Debug -DDRIFT_SANITIZE=address,undefined -DDRIFT_WERROR=ON >/dev/null
cmake --build build/dev -j"$jobs"

echo "== build (Release, -Werror)"
cmake -S . -B build/release -DCMAKE_BUILD_TYPE=Release -DDRIFT_BUILD_TESTS=OFF -DDRIFT_WERROR=ON >/dev/null
cmake --build build/release -j"$jobs"

echo "== fuzz smoke (libFuzzer, ${DRIFT_FUZZ_SECONDS:-20} s per target)"
# fuzzer-no-link instruments the library too, so libFuzzer sees coverage inside drift.
# CXX too: the library's one C++ file (src/io/image_exr_dwa.cpp) makes its links C++ links.
CC=clang CXX=clang++ cmake -S . -B build/fuzz -DCMAKE_BUILD_TYPE=Debug -DDRIFT_BUILD_FUZZERS=ON \
  -DCMAKE_C_FLAGS=-fsanitize=fuzzer-no-link -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link \
  -DDRIFT_BUILD_TESTS=OFF -DDRIFT_SANITIZE=address,undefined -DDRIFT_WERROR=ON >/dev/null
cmake --build build/fuzz -j"$jobs"
for fuzzer in build/fuzz/fuzz_*; do
  name=$(basename "$fuzzer")
  corpus=tests/fuzz/corpus/${name#fuzz_}
  work=$(mktemp -d)
  [ -d "$corpus" ] && cp -r "$corpus"/. "$work"/
  "$fuzzer" -max_total_time="${DRIFT_FUZZ_SECONDS:-20}" -rss_limit_mb=4096 "$work" >"build/fuzz/$name.log" 2>&1 \
    || { tail -40 "build/fuzz/$name.log"; echo "fuzz: $name failed"; exit 1; }
  rm -rf "$work"
  echo "fuzz: $name ok ($(grep -o 'Done [0-9]* runs' "build/fuzz/$name.log" || echo 'ran'))"
done

echo "== tsan (ThreadSanitizer: the threaded renders at --threads 1, 2, 16, 256)"
cmake -S . -B build/tsan -DCMAKE_BUILD_TYPE=Debug -DDRIFT_SANITIZE=thread -DDRIFT_BUILD_TESTS=OFF \
  -DDRIFT_WERROR=ON >/dev/null
cmake --build build/tsan -j"$jobs" --target drift_cli
bash tests/tsan/test_tsan.sh build/tsan/bin/drift

echo "== valgrind (memcheck) on a plain Debug build of the core tests"
cmake -S . -B build/valgrind -DCMAKE_BUILD_TYPE=Debug >/dev/null
cmake --build build/valgrind -j"$jobs" --target test_core test_sampling
for t in test_core test_sampling; do
  DRIFT_TEST_INTENSITY=0.1 valgrind --quiet --error-exitcode=9 --leak-check=full \
    --errors-for-leak-kinds=definite,indirect "build/valgrind/$t" >/dev/null
  echo "valgrind: $t clean"
done

echo "== tests (ctest)"
cd build/dev
ctest -j"$jobs" --output-on-failure
