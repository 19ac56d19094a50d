#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 27, defects 4, 5 and 8: inputs that are not regular files, closed
# standard descriptors, and a standard output that cannot be written.
# - every input of every command that is a FIFO, a device, a socket or a
#   directory gets one line at once (a FIFO blocked open() for ever);
# - devices and FIFOs as OUTPUTS stay supported (-o /dev/stdout, a FIFO);
# - with stdin, stdout and stderr closed every command works as with them
#   open (the probe's pipe took descriptors 1 and 2: check exited 1);
# - a result asked for on stdout and lost (/dev/full) is an error: exit 1,
#   one line, and the command's output files are removed.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
PY=/usr/bin/python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
N=0
ok() { N=$((N + 1)); echo "  ok: $*"; }
S="$VP_SRC/vdb_samples"

"$VDBPACK" pack box:1,1,1 --radius 0.2 -o box.vdb -q
"$VDBPACK" convert box.vdb box.csv -q
cp "$S/box.obj" cube.obj

# one line, status 1, within 3 s, nothing new in out/
refused() { # NAME REGEX ARGS...
  local name=$1 re=$2; shift 2
  rm -rf out; mkdir out
  local st=0 t0=$EPOCHREALTIME
  timeout 10 "$VDBPACK" "$@" >run.out 2>run.err </dev/null || st=$?
  local dt; dt=$(awk -v a="$t0" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.2f", b - a }')
  [ "$st" = 1 ] || die "$name: exit status $st (124: it blocked): $(cat run.err)"
  [ "$(wc -l <run.err)" = 1 ] || die "$name: stderr: $(cat run.err)"
  grep -Eq -- "$re" run.err || die "$name: stderr does not match /$re/: $(cat run.err)"
  awk -v d="$dt" 'BEGIN { exit !(d < 3) }' || die "$name: took ${dt}s"
  [ -z "$(ls -A out)" ] || die "$name: files left: $(ls -A out)"
  ok "$name (${dt}s): $(cat run.err)"
}

echo "=== inputs that are not regular files"
mkfifo fifo.obj fifo.vdb fifo.csv fifo.ply
mkdir dir.obj dir.vdb dir.csv
"$PY" -c "import socket; s = socket.socket(socket.AF_UNIX); s.bind('sock.obj')"
FIFO="not a regular file but a FIFO"
refused "pack: mesh container a FIFO" "fifo\.obj: $FIFO" pack fifo.obj --radius 0.1 -o out/p.vdb
refused "pack: .vdb container a FIFO" "fifo\.vdb: $FIFO" pack fifo.vdb --radius 0.1 -o out/p.vdb
refused "pack: --shape a FIFO" "fifo\.obj: $FIFO" pack box:1,1,1 --method rsa --shape fifo.obj --radius 0.1 --count 3 -o out/p.vdb
refused "check: the packing a FIFO" "fifo\.vdb: $FIFO" check fifo.vdb --container box:1,1,1
refused "check: --container a FIFO" "fifo\.obj: $FIFO" check box.vdb --container fifo.obj
refused "check: --container a FIFO .vdb" "fifo\.vdb: $FIFO" check box.vdb --container fifo.vdb
refused "info: a FIFO" "fifo\.vdb: $FIFO" info fifo.vdb
refused "render: a FIFO" "fifo\.vdb: $FIFO" render fifo.vdb -o out/r.png
refused "convert: a FIFO .csv" "fifo\.csv: $FIFO" convert fifo.csv out/c.vdb
refused "convert: a FIFO .ply" "fifo\.ply: $FIFO" convert fifo.ply out/c.vdb
refused "convert: a FIFO .vdb" "fifo\.vdb: $FIFO" convert fifo.vdb out/c.csv
refused "pack: a character device" "/dev/zero: not a regular file but a character device" pack /dev/zero --radius 0.1 -o out/p.vdb
refused "info: /dev/null" "/dev/null: not a regular file but a character device" info /dev/null
refused "convert: /dev/null.csv link" "null\.csv: not a regular file but a character device" convert "$(ln -sf /dev/null null.csv; echo null.csv)" out/c.vdb
refused "pack: a socket" "sock\.obj: not a regular file but a socket" pack sock.obj --radius 0.1 -o out/p.vdb
refused "pack: a directory" "dir\.obj: not a regular file but a directory" pack dir.obj --radius 0.1 -o out/p.vdb
refused "info: a directory" "dir\.vdb: not a regular file but a directory" info dir.vdb
refused "convert: a directory" "dir\.csv: not a regular file but a directory" convert dir.csv out/c.vdb
refused "check: --container a directory" "dir\.obj: not a regular file but a directory" check box.vdb --container dir.obj
# a FIFO with a writer waiting is refused too (not read half-way)
( exec 3>fifo.csv; sleep 3 ) &
wpid=$!
refused "convert: a FIFO with a writer" "fifo\.csv: $FIFO" convert fifo.csv out/c.vdb
kill "$wpid" 2>/dev/null || true; wait "$wpid" 2>/dev/null || true
# a link to a regular file is read like the file
ln -s box.csv link.csv
"$VDBPACK" convert link.csv via_link.vdb -q || die "a link to a regular .csv is not read"
ok "a symbolic link to a regular file is still read"

echo "=== devices and FIFOs as outputs stay supported"
"$VDBPACK" pack box:1,1,1 --radius 0.2 -q -o /dev/stdout --format csv >to_stdout.csv || die "-o /dev/stdout"
"$VDBPACK" pack box:1,1,1 --radius 0.2 -q -o direct.csv
cmp -s to_stdout.csv direct.csv || die "-o /dev/stdout differs from the file written directly"
"$VDBPACK" pack box:1,1,1 --radius 0.2 -q -o /dev/null --format vdb || die "-o /dev/null"
cat fifo.csv >from_fifo.csv & reader=$!
"$VDBPACK" convert box.vdb fifo.csv -q || die "convert into a FIFO"
wait "$reader"
cmp -s from_fifo.csv box.csv || die "the FIFO's reader did not get the CSV"
ok "-o /dev/stdout, -o /dev/null and a FIFO output still written through"

echo "=== closed standard descriptors"
closed() { # NAME ARGS... : status 0 with 0, 1 and 2 closed
  local name=$1; shift
  local st=0
  "$VDBPACK" "$@" <&- >&- 2>&- || st=$?
  [ "$st" = 0 ] || die "$name: exit status $st with stdin, stdout and stderr closed"
  ok "$name with 0, 1 and 2 closed: status 0"
}
closed "check of a .vdb (the issue's case)" check box.vdb --container box:1,1,1
"$VDBPACK" pack cube.obj --radius 0.2 -o mesh.vdb -q
closed "check against a mesh" check mesh.vdb --container cube.obj
closed "info" info box.vdb
closed "pack of a mesh" pack cube.obj --radius 0.2 -o closed_mesh.vdb
closed "pack of a .vdb container with --json" pack "$S/sphere_ls.vdb" --radius 0.1 -o closed_ls.vdb --json
closed "render" render box.vdb -o closed.png --size 32x32
closed "convert" convert box.vdb closed.ply
"$VDBPACK" check closed_mesh.vdb --container cube.obj -q || die "the pack made with closed descriptors does not check"
[ "$(stat -c %s closed.ply)" -gt 100 ] || die "closed.ply is empty"
# only stdout and stderr closed, and a failure: the status says it
st=0; "$VDBPACK" info missing.vdb >&- 2>&- || st=$?
[ "$st" = 1 ] || die "info missing.vdb with 1 and 2 closed: status $st"
ok "a failure with stdout and stderr closed still exits 1"

echo "=== a standard output that cannot be written (/dev/full)"
full() { # NAME OUTPUT|- ARGS...: exit 1, one line, OUTPUT removed
  local name=$1 out=$2; shift 2
  local st=0
  "$VDBPACK" "$@" >/dev/full 2>run.err || st=$?
  [ "$st" = 1 ] || die "$name: exit status $st with stdout on /dev/full: $(cat run.err)"
  [ "$(wc -l <run.err)" = 1 ] || die "$name: stderr: $(cat run.err)"
  grep -Eq "^vdbpack: cannot write the result to the standard output( \(No space left on device\))?$" run.err ||
    die "$name: $(cat run.err)"
  if [ "$out" != - ]; then [ ! -e "$out" ] || die "$name: $out was left"; fi
  [ -z "$(find . -maxdepth 1 -name '.vp-*.tmp')" ] || die "$name: temporary left"
  ok "$name: status 1, $(cat run.err)"
}
full "pack --json" p.vdb pack box:1,1,1 --radius 0.2 -o p.vdb --json
full "pack summary" p.vdb pack box:1,1,1 --radius 0.2 -o p.vdb
full "pack summary, all outputs" p.vdb pack cube.obj --radius 0.2 -o p.vdb --save-container l.vdb --shape-out s.obj --preview v.png
[ ! -e l.vdb ] && [ ! -e s.obj ] && [ ! -e v.png ] || die "pack's other outputs were left: $(ls)"
full "check report" - check box.vdb --container box:1,1,1
full "check --json" - check box.vdb --container box:1,1,1 --json
full "info" - info box.vdb
full "info --json" - info box.vdb --json
full "render summary" r.png render box.vdb -o r.png --size 32x32
full "convert summary" c.ply convert box.vdb c.ply
full "--help" - --help
full "pack --help" - pack --help
full "--version" - --version
# a violation whose report is lost: the loss is the error (1, one line)
"$VDBPACK" pack box:1,1,1 --radius 0.2 -o fat.csv -q
"$PY" - <<'EOF'
rows = open("fat.csv").read().splitlines()
out = [rows[0]] + [",".join(r.split(",")[:4] + ["0.5"] + r.split(",")[5:]) for r in rows[1:]]
open("fat.csv", "w").write("\n".join(out) + "\n")
EOF
"$VDBPACK" convert fat.csv fat.vdb -q
st=0; "$VDBPACK" check fat.vdb --container box:1,1,1 >/dev/null 2>&1 || st=$?
[ "$st" = 3 ] || die "fat.vdb: check exits $st, not 3"
full "check of a violation, report lost" - check fat.vdb --container box:1,1,1 --json
# -q prints nothing: nothing is lost
"$VDBPACK" pack box:1,1,1 --radius 0.2 -o q.vdb -q >/dev/full || die "pack -q >/dev/full failed"
[ -e q.vdb ] || die "pack -q >/dev/full removed its output"
ok "pack -q with stdout on /dev/full: status 0 (nothing asked for on stdout)"
# -o /dev/stdout on /dev/full: the output itself is lost
st=0; "$VDBPACK" pack box:1,1,1 --radius 0.2 -o /dev/stdout --format csv >/dev/full 2>run.err || st=$?
[ "$st" = 1 ] && [ "$(wc -l <run.err)" = 1 ] || die "-o /dev/stdout >/dev/full: $st $(cat run.err)"
ok "-o /dev/stdout with stdout on /dev/full: status 1: $(cat run.err)"
echo "PASS: sh_hostile_streams ($N cases)"
