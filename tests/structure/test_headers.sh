#!/usr/bin/env bash
# Every public header (include/drift/*.h, and the generated drift/version.h) compiles alone,
# first in its translation unit, as C11 and as C++17, warnings as errors.
# $1: the include folder, $2: the generated include folder, $3: the C compiler, $4: the C++ one.
set -u
inc="$1" gen="$2" cc="$3" cxx="$4"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
failures=0
headers=$(cd "$inc" && ls drift/*.h; cd "$gen" && ls drift/*.h)
for h in $headers; do
    printf '#include "%s"\nint drift_header_check_%s;\n' "$h" "$(basename "$h" .h)" >"$tmp/t.c"
    cp "$tmp/t.c" "$tmp/t.cpp"
    "$cc" -std=c11 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$inc" -I"$gen" "$tmp/t.c" \
        2>"$tmp/err" || { echo "FAIL: $h as C11:"; cat "$tmp/err"; failures=$((failures + 1)); }
    "$cxx" -std=c++17 -Wall -Wextra -Werror -fsyntax-only -I"$inc" -I"$gen" "$tmp/t.cpp" \
        2>"$tmp/err" || { echo "FAIL: $h as C++17:"; cat "$tmp/err"; failures=$((failures + 1)); }
done
[ "$failures" -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "structure.headers: $(echo "$headers" | wc -w) headers compile alone as C11 and C++17"
