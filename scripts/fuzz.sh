#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Builds the libFuzzer targets (clang, ASan + UBSan) into ./build-fuzz and
# runs each for FUZZ_SECONDS (default 30) on its seed corpus. Findings
# (crash-*, leak-*, timeout-*, oom-*) land in build-fuzz/findings/TARGET and
# make the script fail. Usage: bash scripts/fuzz.sh [TARGET...]
#   FUZZ_SECONDS=600 bash scripts/fuzz.sh fuzz_mesh    # a 10-minute run
# Needs the normal build (scripts/setup.sh) for a points-grid seed.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC=$PWD

PKGS=(clang libclang-rt-dev python3-openvdb python3-numpy)
source scripts/apt_install.sh
apt_install fuzz "${PKGS[@]}"

B=${FUZZ_BUILD_DIR:-build-fuzz}
if [ ! -f "$B/build.ninja" ]; then
  CC=clang CXX=clang++ cmake -S . -B "$B" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DVP_FUZZ=ON -DBUILD_TESTING=OFF >/dev/null
fi
TARGETS=("$@")
[ ${#TARGETS[@]} -gt 0 ] || TARGETS=(fuzz_mesh fuzz_vdb fuzz_options)
cmake --build "$B" -j "${JOBS:-2}" --target "${TARGETS[@]}"

# seed corpora: committed text seeds, plus .vdb seeds made here
C=$B/corpus
mkdir -p "$C/fuzz_mesh" "$C/fuzz_options" "$C/fuzz_vdb"
cp -n fuzz/seeds/mesh/* "$C/fuzz_mesh/"
cp -n fuzz/seeds/options/* "$C/fuzz_options/"
if [ ! -f "$C/fuzz_vdb/levelset.vdb" ]; then
  /usr/bin/python3 fuzz/make_vdb_seeds.py "$C/fuzz_vdb" >/dev/null
  if [ -x build/vdbpack ]; then
    build/vdbpack pack sphere:1 --radius 0.3 -o "$C/fuzz_vdb/points.vdb" -q
    build/vdbpack pack sphere:1 --radius 0.3 --shape cube -o "$C/fuzz_vdb/points_orient.vdb" -q
    build/vdbpack pack sphere:1 --method rsa --pass count=6,radius=0.3,shape=cube \
      --pass count=6,radius=0.2 -o "$C/fuzz_vdb/points_mixed.vdb" -q
    build/vdbpack pack vdb_samples/box.obj --radius 0.3 --voxel-size 0.2 -o "$B/x.vdb" --save-container "$C/fuzz_vdb/box_ls.vdb" -q
    rm -f "$B/x.vdb"
  fi
fi

SECS=${FUZZ_SECONDS:-30}
# the targets' and libFuzzer's temporary files stay in the build tree (a
# child killed on a timeout cannot remove its own), emptied before and after
rm -rf "$B/tmp" && mkdir -p "$B/tmp"
export TMPDIR=$(cd "$B/tmp" && pwd)
export ASAN_OPTIONS=${ASAN_OPTIONS:-allocator_may_return_null=1:max_allocation_size_mb=512:detect_leaks=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$SRC/fuzz/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
status=0
for t in "${TARGETS[@]}"; do
  F=$B/findings/$t
  mkdir -p "$F"
  mode=()
  case $t in
  # OpenVDB 10's reader overruns buffers, aborts and hangs on some corrupt
  # files; vdbpack contains that by reading every .vdb in a child process
  # first (src/api/probe.c), the in-process fuzz build cannot. As for
  # Assimp: fork mode, and each finding inside OpenVDB is replayed below
  # through vdbpack itself, which must not crash or hang on it.
  fuzz_vdb) maxlen=200000; mode=(-fork=1 -ignore_timeouts=1 -ignore_ooms=0 -ignore_crashes=1) ;;
  # Assimp 5.2 hangs on some malformed files; vdbpack contains that with a
  # child process and a deadline, the in-process fuzz build cannot. Fork
  # mode keeps fuzzing past such timeouts; each one is replayed below
  # through vdbpack itself, which must refuse it with one line.
  fuzz_mesh) maxlen=65536; mode=(-fork=1 -ignore_timeouts=1 -ignore_ooms=0 -ignore_crashes=1) ;;
  *) maxlen=4096 ;;
  esac
  echo "fuzz: $t for ${SECS}s"
  rc=0
  "$B/fuzz/$t" "$C/$t" -max_total_time="$SECS" -max_len=$maxlen -timeout=10 -rss_limit_mb=4096 \
    -close_fd_mask=3 -artifact_prefix="$F/" -print_final_stats=1 "${mode[@]}" >"$F/log.txt" 2>&1 || rc=$?
  grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "$F/log.txt" | sed "s/^/  $t: /" || true
  grep -E "^#[0-9]+: cov" "$F/log.txt" | tail -1 | sed "s/^/  $t: /" || true
  echo "  $t: corpus $(find "$C/$t" -type f | wc -l) inputs"
  # timeouts and crashes of the in-process importer (fuzz_mesh): a crash
  # counts as Assimp's only when its sanitizer report ends in libassimp, and
  # either is contained only when vdbpack itself refuses the file with one
  # line (its importer runs in a child process with a deadline)
  for x in "$F"/timeout-* "$F"/crash-*; do
    [ -e "$x" ] && [ "$t" = fuzz_vdb ] || continue
    # whose finding: the first stack frame outside the sanitizer runtime,
    # libc and libstdc++ must be OpenVDB's (its library or its headers).
    # `sed -n 1p`, never `head`: head exits early, grep then dies of
    # SIGPIPE, and pipefail + errexit ended this script with status 141
    # on a long report
    "$B/fuzz/$t" "$x" -timeout=10 >"$F/replay.txt" 2>&1 || true
    first=$(grep -E "^ +#[0-9]+ 0x" "$F/replay.txt" |
            grep -vE "__interceptor_|__asan|__sanitizer|__ubsan|fuzzer::|AlarmCallback|libc\.so|libstdc\+\+\.so|libgcc_s|/libc/|sysdeps/|fuzz/$t\+0x|fuzz/fuzz_new\.cpp|operator new" |
            sed -n 1p) || true # no stack at all: grep's status 1, fatal under pipefail
    # (frames of the fuzz binary without a source file are the sanitizer
    # runtime's: malloc, memcpy; fuzz_new.cpp is the targets' operator new,
    # see the Fuzzing section of docs/hardening.md; a timeout that does not recur on replay
    # leaves no stack and goes straight to the containment check)
    if [ -n "$first" ] && ! printf '%s\n' "$first" | grep -Eq "libopenvdb\.so|/usr/include/openvdb/"; then
      echo "  $t: $(basename "$x"): a finding outside OpenVDB: ${first:-no stack}"; grep -E "SUMMARY|#[0-3] " "$F/replay.txt" | sed -n 1,6p || true
      continue
    fi
    cp "$x" "$F/replay.vdb"
    ok=1
    for cmd in "info $F/replay.vdb" "check $F/replay.vdb --container sphere:1" \
               "pack $F/replay.vdb --radius 0.1 -o $F/replay-out.vdb"; do
      prc=0
      # shellcheck disable=SC2086
      VDBPACK_READ_TIMEOUT=10 timeout 120 build/vdbpack $cmd >/dev/null 2>"$F/replay.err" || prc=$?
      if [ "$prc" -ge 124 ] || { [ "$prc" != 0 ] && [ "$(wc -l <"$F/replay.err")" != 1 ]; } ||
         [ -e "$F/replay-out.vdb" ]; then
        echo "  $t: $(basename "$x"): vdbpack ${cmd%% *} exit $prc: $(head -c 300 "$F/replay.err")"
        ok=0
      fi
      rm -f "$F/replay-out.vdb"
    done
    if [ $ok = 1 ]; then
      where="no stack on replay"
      [ -z "$first" ] || where="in OpenVDB ($(printf '%s' "$first" | sed -E 's/^ +#[0-9]+ 0x[0-9a-f]+ in //' | cut -c1-90))"
      echo "  $t: $(basename "$x"): $where, contained by vdbpack: $(cat "$F/replay.err")"
      mv "$x" "$F/contained-$(basename "$x")"
    fi
  done
  for x in "$F"/timeout-* "$F"/crash-*; do
    [ -e "$x" ] && [ "$t" = fuzz_mesh ] || continue
    kind=${x##*/}; kind=${kind%%-*}
    if [ "$kind" = crash ]; then
      "$B/fuzz/$t" "$x" >"$F/replay.txt" 2>&1 || true
      grep -Eq "SUMMARY: [A-Za-z]+Sanitizer: .*libassimp\.so" "$F/replay.txt" || {
        echo "  $t: $(basename "$x"): a crash outside Assimp:"; grep -E "SUMMARY|#[0-3] " "$F/replay.txt" | sed -n 1,6p || true
        continue; }
    fi
    case $(( $(head -c 1 "$x" | od -An -tu1 | tr -d ' ') & 7 )) in
    5) ext=ply ;; 6) ext=stl ;; 7) ext=off ;; *) ext=obj ;;
    esac
    tail -c +2 "$x" >"$F/replay.$ext"
    prc=0
    VDBPACK_IMPORT_TIMEOUT=3 build/vdbpack pack "$F/replay.$ext" --radius 0.1 -o "$F/replay.vdb" \
      >/dev/null 2>"$F/replay.err" || prc=$?
    if [ "$prc" = 1 ] && [ "$(wc -l <"$F/replay.err")" = 1 ] && [ ! -e "$F/replay.vdb" ]; then
      echo "  $t: $(basename "$x"): an Assimp $kind, contained by vdbpack: $(cat "$F/replay.err")"
      mv "$x" "$F/contained-$(basename "$x")"
    else
      echo "  $t: $(basename "$x"): vdbpack exit $prc: $(cat "$F/replay.err")"
    fi
  done
  # leaks: the fast unwinder stops at the first frame of a library built
  # without frame pointers (libopenvdb.so), so a leak on one of OpenVDB's
  # error paths can miss its suppression in fuzz/lsan.supp. Replayed with
  # full unwinding, a leak that the suppressions then cover is theirs.
  for x in "$F"/leak-*; do
    [ -e "$x" ] || continue
    if ASAN_OPTIONS="$ASAN_OPTIONS:fast_unwind_on_malloc=0" "$B/fuzz/$t" "$x" >"$F/replay.txt" 2>&1; then
      echo "  $t: $(basename "$x"): a third-party leak of fuzz/lsan.supp once fully unwound"
      mv "$x" "$F/contained-$(basename "$x")"
    else
      echo "  $t: $(basename "$x"): a leak:"; grep -E "SUMMARY|#[0-5] " "$F/replay.txt" | sed -n 1,8p || true
    fi
  done
  found=$(find "$F" -name 'crash-*' -o -name 'leak-*' -o -name 'timeout-*' -o -name 'oom-*' | wc -l)
  if { [ "$rc" != 0 ] && [ ${#mode[@]} = 0 ]; } || [ "$found" != 0 ]; then
    echo "fuzz: $t FAILED (exit $rc, $found finding(s) in $F); log tail:"
    tail -40 "$F/log.txt"
    status=1
  fi
done
rm -rf "$TMPDIR"
exit $status
