#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The CI's hardening stages (issue 4), after the main test suite
# (scripts/test.sh, which also does the set-up and the normal build):
#   1. a small end-to-end run under valgrind memcheck: zero errors, no
#      definite leaks (a mesh pack saving its level set, a random pack in that
#      level set, and `vdbpack check`);
#   2. each libFuzzer target for CI_FUZZ_SECONDS (default 30) on its seed
#      corpus (scripts/fuzz.sh; clang, ASan + UBSan);
#   3. the whole CTest suite again on an ASan + UBSan build (clang) in
#      ./build-asan; its CTest summary is the last thing printed.
# Installs what it needs (valgrind, clang) with apt-get when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC=$PWD

PKGS=(valgrind clang libclang-rt-dev)
source scripts/apt_install.sh
apt_install hardening "${PKGS[@]}"

echo "=== 1/3 valgrind memcheck: end-to-end pack"
V=$(mktemp -d); trap 'rm -rf "$V"' EXIT
vg() { # NAME ARGS...
  local name=$1; shift
  local rc=0
  valgrind --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite \
    --suppressions="$SRC/tests/valgrind.supp" "$SRC/build/vdbpack" "$@" >"$V/$name.out" 2>"$V/$name.log" || rc=$?
  # every process (the mesh reader runs in a forked child) must be clean
  if [ "$rc" != 0 ] || grep -E "ERROR SUMMARY: [1-9]" "$V/$name.log" >/dev/null; then
    echo "valgrind: $name: exit $rc"; cat "$V/$name.log"; exit 1
  fi
  echo "  ok: vdbpack $* ($(grep -c 'ERROR SUMMARY: 0 errors' "$V/$name.log") process(es), 0 errors, $(grep -Eo 'definitely lost: [0-9,]+ bytes' "$V/$name.log" | sed -n 1p))"
}
vg mesh pack vdb_samples/box.obj --radius 0.1 -o "$V/box.vdb" --save-container "$V/box_ls.vdb" -q
vg rsa pack "$V/box_ls.vdb" --method rsa --radius 0.05 --count 300 -o "$V/rsa.vdb" -q
vg check check "$V/rsa.vdb" --container "$V/box_ls.vdb"

echo "=== 2/3 fuzzing, ${CI_FUZZ_SECONDS:-30} s per target"
FUZZ_SECONDS=${CI_FUZZ_SECONDS:-30} bash scripts/fuzz.sh

echo "=== 3/3 the test suite under AddressSanitizer + UndefinedBehaviorSanitizer"
B=build-asan
if [ ! -f "$B/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$B" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVP_SANITIZE=ON >/dev/null
fi
cmake --build "$B" -j "${JOBS:-2}"
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$SRC/fuzz/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
cd "$B"
ctest --output-on-failure -j "${CTEST_JOBS:-2}"
