#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# SIGINT and SIGTERM during a long pack: the run ends within a second or so,
# exits 130 / 143 with one line on stderr, and leaves no file at all in the
# output directory (no partial .vdb, no temporary, no --shape-out file).
set -euo pipefail
: "${VDBPACK:?}"
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }

one() { # SIGNAL EXPECTED_STATUS
  local sig=$1 want=$2
  rm -rf out; mkdir out
  # an explicit, very long placement search (tens of seconds)
  "$VDBPACK" pack sphere:40 --radius 1 --offsets 200000 -o out/p.vdb --shape-out out/s.obj \
    >run.out 2>run.err &
  local pid=$!
  sleep 1.5
  kill -0 "$pid" 2>/dev/null || die "the pack ended before the signal: $(cat run.err)"
  local t0=$EPOCHREALTIME
  kill -"$sig" "$pid"
  set +e; wait "$pid"; local st=$?; set -e
  local dt; dt=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.3f", b - a }')
  [ "$st" = "$want" ] || die "SIG$sig: exit status $st, expected $want ($(cat run.err))"
  [ "$(wc -l <run.err)" = 1 ] || die "SIG$sig: stderr has $(wc -l <run.err) lines: $(cat run.err)"
  grep -q "no output written" run.err || die "SIG$sig: message: $(cat run.err)"
  [ -z "$(ls -A out)" ] || die "SIG$sig: files left behind: $(ls -A out)"
  awk -v d="$dt" 'BEGIN { exit !(d < 1.5) }' || die "SIG$sig: took ${dt}s to end"
  echo "ok: SIG$sig ended the run in ${dt}s, status $st, '$(cat run.err)', nothing left in out/"
}
one INT 130
one TERM 143
echo "PASS: sh_signals"
