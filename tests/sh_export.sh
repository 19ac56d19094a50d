#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Export formats (issue 6): PLY and CSV from `pack -o` and `convert`, read
# back by a parser that is not vdbpack's (tests/py/export_check.py: the PLY
# header and records parsed there, the CSV by numpy) and compared with the
# .vdb as OpenVDB itself reads it (tests/dump_points: OpenVDB's API only;
# vdb_tool -vdb2points for positions); the round trip vdb -> ply -> csv ->
# vdb keeps count, ids, groups, pscale, orient and positions (float) and
# still passes `vdbpack check`; OBJ vertex/face counts and vertex places
# (spheres: at pscale from the centre; cubes: the rotated unit vertices);
# --format; and the numpy snippets of docs/import-python.md, run as written.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
DUMP=${VP_DUMP_POINTS:-}
[ -x "$DUMP" ] || { echo "SKIP: tests/dump_points not built"; exit 77; }
command -v vdb_tool >/dev/null || { echo "SKIP: vdb_tool not installed"; exit 77; }
PY=/usr/bin/python3
"$PY" -c 'import numpy' 2>/dev/null || { echo "SKIP: no numpy"; exit 77; }
EC="$VP_SRC/tests/py/export_check.py"
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
# outputs written through (devices, FIFOs, pipes) are staged in $TMPDIR:
# a scratch one here, which must be empty after every case
mkdir "$W/tmp"; export TMPDIR="$W/tmp"
tmp_clean() { [ -z "$(ls -A "$TMPDIR")" ] || die "$1: left in TMPDIR: $(ls -A "$TMPDIR")"; }
die() { echo "FAIL: $*"; exit 1; }

# NAME CONTAINER pack-args...: .vdb, then .ply and .csv both from pack -o and
# from convert (pack -o writes the packer's doubles, convert the .vdb's),
# compared with each other and with OpenVDB's reading of the .vdb
exports() {
  local name=$1 cont=$2; shift 2
  echo "=== $name: pack $cont $*"
  "$VDBPACK" pack "$cont" -q -o "$name.vdb" "$@" || die "$name: pack"
  "$VDBPACK" pack "$cont" -q -o "$name.pack.ply" "$@" || die "$name: pack -o .ply"
  "$VDBPACK" pack "$cont" -q -o "$name.pack.csv" "$@" || die "$name: pack -o .csv"
  "$VDBPACK" convert "$name.vdb" "$name.ply" -q || die "$name: convert to ply"
  "$VDBPACK" convert "$name.vdb" "$name.csv" -q || die "$name: convert to csv"
  "$PY" "$EC" packvsconvert "$name.pack.ply" "$name.pack.csv" "$name.ply" "$name.csv"
  "$DUMP" "$name.vdb" >"$name.dump" || die "$name: dump_points"
  vdb_tool -quiet -read "$name.vdb" grids=points -vdb2points -write "$name.vt.ply" >/dev/null 2>&1 ||
    die "$name: vdb_tool"
  "$PY" "$EC" compare "$name.dump" "$name.ply" "$name.csv" "$name.vt.ply"
}
exports spheres box:1,1,1 --method rsa --pass count=40,radius=0.08 --pass count=400,radius=0.03
exports cubes sphere:1 --method rsa --shape cube --pass count=40,radius=0.12 --pass count=150,radius=0.06 \
  --shape-out cube.obj
exports lattice_cubes sphere:1 --shape cube --radius 0.15 --precision full --rotate --rotations 4

echo "=== round trip vdb -> ply -> csv -> vdb"
roundtrip() { # NAME CONTAINER [--shape S]
  local name=$1 cont=$2; shift 2
  "$VDBPACK" convert "$name.vdb" "$name.rt.ply" -q
  "$VDBPACK" convert "$name.rt.ply" "$name.rt.csv" -q
  "$VDBPACK" convert "$name.rt.csv" "$name.rt.vdb" -q "$@"
  "$DUMP" "$name.rt.vdb" >"$name.rt.dump"
  "$PY" "$EC" roundtrip "$name.dump" "$name.rt.dump"
  "$VDBPACK" check "$name.rt.vdb" --container "$cont" -q || die "$name: check fails after the round trip"
  "$VDBPACK" info "$name.rt.vdb" --json | "$PY" -c '
import json, sys
d = json.load(sys.stdin)
assert d["metadata"]["shape"] == sys.argv[1], d["metadata"]
print("  ok: vdbpack check passes; shape metadata", sys.argv[1])' "${2:-sphere}"
}
roundtrip spheres box:1,1,1
roundtrip cubes sphere:1 --shape cube

echo "=== OBJ"
"$VDBPACK" convert spheres.vdb spheres.obj -q
"$PY" "$EC" obj spheres.obj spheres.csv sphere 2
"$VDBPACK" convert cubes.vdb cubes.obj -q
"$PY" "$EC" obj cubes.obj cubes.csv cube.obj
"$VDBPACK" convert lattice_cubes.csv lattice_cubes.obj --shape cube -q
"$PY" "$EC" obj lattice_cubes.obj lattice_cubes.csv cube.obj
# negative control: the same check with qx and qy swapped fails
sed '1s/qx,qy/qy,qx/' cubes.csv >swapped.csv
if "$PY" "$EC" obj cubes.obj swapped.csv cube.obj >neg.txt; then die "OBJ check passed with swapped orient"; fi
echo "  ok: negative control (qx, qy swapped): $(grep FAIL neg.txt)"

echo "=== --format"
"$VDBPACK" pack box:1,1,1 --radius 0.2 -q -o data.txt --format csv
head -1 data.txt | grep -qx 'id,x,y,z,pscale,group' || die "--format csv: $(head -1 data.txt)"
"$VDBPACK" convert spheres.vdb spheres.dat --format ply -q
head -c 4 spheres.dat | grep -q ply || die "convert --format ply"
"$VDBPACK" pack box:1,1,1 --radius 0.2 -q -o upper.PLY
head -c 4 upper.PLY | grep -q ply || die ".PLY (upper case) is not a PLY"
echo "  ok: pack --format csv, convert --format ply, .PLY by extension"

echo "=== docs/import-python.md snippets"
cp cubes.csv packing.csv
cp cubes.ply packing.ply
n=$(wc -l <cubes.dump)
"$PY" - "$VP_SRC/docs/import-python.md" >snips.py <<'PY'
import re, sys
blocks = re.findall(r"```python\n(.*?)```", open(sys.argv[1]).read(), re.S)
assert len(blocks) == 3, len(blocks)
for i, b in enumerate(blocks):
    print("print('--- snippet %d')" % (i + 1))
    print(b)
PY
"$PY" snips.py >snips.out 2>&1 || die "a snippet fails: $(cat snips.out)"
cat snips.out
[ "$(grep -c "^$n particles; groups: pass1, pass2$" snips.out)" = 2 ] ||
  die "the CSV and PLY snippets should each print '$n particles; groups: pass1, pass2'"
grep -qx True snips.out || die "quat_to_matrix snippet"
echo "  ok: the 3 snippets run and report $n particles in groups pass1, pass2"
echo "=== outputs that would overwrite an input or each other, and convert's inputs"
refused() { # STATUS WORD CMD... : one line, that status, the word
  local want=$1 word=$2; shift 2
  set +e; "$VDBPACK" "$@" >r.out 2>r.err; local st=$?; set -e
  [ "$st" = "$want" ] || die "'$*' exited $st, expected $want: $(cat r.err)"
  [ "$(wc -l <r.err)" = 1 ] && grep -q -- "$word" r.err || die "'$*': $(cat r.err)"
  echo "  ok: $(cat r.err)"
}
cp "$VP_SRC/vdb_samples/torus.obj" mine.obj
refused 2 "container itself" pack mine.obj --radius 0.1 -o o1.vdb --shape-out mine.obj -q
cmp -s mine.obj "$VP_SRC/vdb_samples/torus.obj" || die "--shape-out replaced the container"
refused 2 "name the same file" pack box:1,1,1 --radius 0.1 -o same.png --format vdb --preview same.png -q
refused 2 "name the same file" pack box:1,1,1 --radius 0.1 -o same.obj --shape-out same.obj -q
refused 2 "ending in .obj" pack box:1,1,1 --radius 0.1 -o o2.vdb --shape-out shape.ply -q
refused 2 "ending in .vdb" pack mine.obj --radius 0.1 -o o3.vdb --save-container ls.ply -q
refused 2 "--shape mesh itself" pack box:1,1,1 --method rsa --shape mine.obj --radius 0.1 --count 5 -o mine.obj --format vdb -q
for f in o1.vdb same.png same.obj o2.vdb shape.ply o3.vdb ls.ply; do [ ! -e "$f" ] || die "$f was written"; done
# a points grid without pscale (vdb_tool writes P only): no packing to convert
printf 'ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n' >p_only.ply
vdb_tool -quiet -read p_only.ply -points2vdb -write p_only.vdb >/dev/null 2>&1 || die "vdb_tool -points2vdb"
refused 1 "no positive radius" convert p_only.vdb p_only.csv -q
# orientations given as spheres
printf 'id,x,y,z,pscale,qx,qy,qz,qw,group\n0,0,0,0,0.1,0,0,0,1,pass1\n' >q.csv
refused 1 "spheres do not carry" convert q.csv q.vdb --shape sphere -q
"$VDBPACK" convert q.csv q.vdb --shape cube -q || die "q.csv as cubes"
# PLY far from the origin: float positions round by a part of a radius
"$PY" - <<'PY'
o = (84616.0, 447422.0, 3.0)
v = [(o[0] + x * 20, o[1] + y * 20, o[2] + z * 20) for x in (0, 1) for y in (0, 1) for z in (0, 1)]
f = [(1, 3, 4, 2), (5, 6, 8, 7), (1, 2, 6, 5), (3, 7, 8, 4), (1, 5, 7, 3), (2, 4, 8, 6)]
with open("far.obj", "w") as fh:
    fh.writelines("v %.1f %.1f %.1f\n" % p for p in v)
    fh.writelines("f %d %d %d %d\n" % q for q in f)
PY
"$VDBPACK" pack far.obj --radius 1 -o far.ply 2>far.err >/dev/null || die "far.obj: $(cat far.err)"
grep -q "warning: far.ply: PLY stores positions as 32-bit floats" far.err || die "no float warning: $(cat far.err)"
echo "  ok: $(cat far.err)"
"$VDBPACK" pack box:1,1,1 --radius 0.05 -o near.ply 2>near.err >/dev/null
[ ! -s near.err ] || die "a warning near the origin: $(cat near.err)"
echo "=== outputs that are not regular files"
# A symbolic link is followed (its file replaced, the link kept); a device
# or FIFO is written through, never replaced: before, -o /dev/null --format
# csv replaced the system's /dev/null with a 42 KB file (the write goes to a
# temporary file that is renamed onto the target).
echo old >real.csv; ln -s real.csv link.csv; ln -s later.csv dangling.csv
"$VDBPACK" pack sphere:1 --radius 0.1 -q -o link.csv || die "-o link.csv"
"$VDBPACK" pack sphere:1 --radius 0.1 -q -o dangling.csv || die "-o dangling.csv"
[ -L link.csv ] && [ -L dangling.csv ] || die "a symbolic link was replaced"
"$VDBPACK" pack sphere:1 --radius 0.1 -q -o direct.csv
cmp -s real.csv direct.csv && cmp -s later.csv direct.csv || die "the links' files do not hold the output"
echo "  ok: links kept, their files written"
mkfifo fifo.csv
cat fifo.csv >from_fifo.csv & reader=$!
"$VDBPACK" pack sphere:1 --radius 0.1 -q -o fifo.csv || die "-o fifo.csv"
wait "$reader"
[ -p fifo.csv ] || die "the FIFO was replaced"
cmp -s from_fifo.csv direct.csv || die "the FIFO's reader did not get the output"
echo "  ok: FIFO written through ($(wc -c <from_fifo.csv) bytes read from it)"
# /dev/stdout is a link into /proc to a pipe here: written through too
"$VDBPACK" pack sphere:1 --radius 0.1 -q -o /dev/stdout --format csv | cat >from_stdout.csv
cmp -s from_stdout.csv direct.csv || die "-o /dev/stdout: not the output"
[ -L /dev/stdout ] || die "/dev/stdout is no longer a link"
echo "  ok: -o /dev/stdout piped ($(wc -l <from_stdout.csv) lines)"
# without -q the summary would land in the data: it goes to stderr instead
"$VDBPACK" pack sphere:1 --radius 0.1 -o /dev/stdout --format csv 2>sum.err | cat >from_stdout2.csv
cmp -s from_stdout2.csv direct.csv || die "-o /dev/stdout without -q: the summary is in the data"
grep -q "^vdbpack: packed" sum.err || die "-o /dev/stdout: no summary on stderr: $(cat sum.err)"
# a reader that goes away: EPIPE, one line, exit 1, nothing left in TMPDIR
# (the write used to die of SIGPIPE with exit 141, its staged copy left)
set +o pipefail
"$VDBPACK" pack sphere:1 --radius 0.02 -q -o /dev/stdout --format csv 2>pipe.err | head -c 1 >/dev/null
rc=${PIPESTATUS[0]}
set -o pipefail
[ "$rc" = 1 ] && [ "$(wc -l <pipe.err)" = 1 ] && grep -q "Broken pipe" pipe.err ||
  die "-o /dev/stdout | head -c 1: exit $rc: $(cat pipe.err)"
tmp_clean "-o /dev/stdout | head -c 1"
echo "  ok: summary to stderr when -o is stdout; a closed pipe: $(cat pipe.err)"
# a job that fails after some outputs were written removes the files it
# wrote, never a link (its file goes) nor a device or FIFO
echo old >shape_target.obj; ln -s shape_target.obj shape_link.obj
rc=0; (ulimit -f 4; "$VDBPACK" pack box:1,1,1 --shape cube --radius 0.05 -q -o big.csv --shape-out shape_link.obj) 2>fsz.err || rc=$?
[ "$rc" = 1 ] && [ "$(wc -l <fsz.err)" = 1 ] || die "a main output over ulimit -f: exit $rc: $(cat fsz.err)"
[ -L shape_link.obj ] || die "the --shape-out link was removed"
[ ! -e shape_target.obj ] && [ ! -e big.csv ] || die "a failed job left its outputs"
echo "  ok: a failed job removed the file its --shape-out link names, kept the link: $(cat fsz.err)"
if mknod -m 666 null c 1 3 2>/dev/null && mknod -m 666 full c 1 7 2>/dev/null; then
  "$VDBPACK" pack sphere:1 --radius 0.1 -q -o null --format csv || die "-o null (a device)"
  [ -c null ] || die "the device null was replaced by a file"
  rc=0; "$VDBPACK" pack sphere:1 --radius 0.1 -q -o full --format vdb 2>full.err || rc=$?
  [ "$rc" = 1 ] && [ "$(wc -l <full.err)" = 1 ] && grep -q "full: cannot write output (No space left on device)" full.err ||
    die "-o full (like /dev/full): exit $rc: $(cat full.err)"
  [ -c full ] || die "the device full was replaced by a file"
  tmp_clean "-o null, -o full"
  # a failed preview after the main output went to a device, and a failed
  # main output after --shape-out went to one: the devices stay
  rc=0; (ulimit -f 4; "$VDBPACK" pack sphere:1 --radius 0.5 -q -o null --format csv --preview pv.png) 2>pv.err || rc=$?
  [ "$rc" = 1 ] && [ -c null ] && [ ! -e pv.png ] || die "-o null with a failed preview: exit $rc, null $(stat -c %F null): $(cat pv.err)"
  rc=0; "$VDBPACK" pack sphere:1 --radius 0.1 -q -o full --format csv --shape-out null 2>so.err || rc=$?
  [ "$rc" = 2 ] && grep -q "ending in .obj" so.err || die "--shape-out null: exit $rc: $(cat so.err)"
  mknod -m 666 null.obj c 1 3
  rc=0; "$VDBPACK" pack box:1,1,1 --radius 0.1 -q -o full --format csv --shape-out null.obj 2>so.err || rc=$?
  [ "$rc" = 1 ] && [ -c null.obj ] || die "--shape-out null.obj then -o full: exit $rc, null.obj $(stat -c %F null.obj): $(cat so.err)"
  tmp_clean "failed jobs with devices"
  echo "  ok: failed jobs keep the devices they wrote to"
  echo "  ok: devices written through: null, and full: $(cat full.err)"
else
  echo "  (mknod not permitted: device outputs not tested)"
fi
echo "=== a crash removes the outputs"
# libblosc (OpenVDB's compressor) dereferences a failed allocation under a
# tight ulimit -v; any crash must still leave no output. The run is
# stopped where it blocks, opening a FIFO to copy its finished output
# into, after --shape-out was written: SIGSEGV there must remove the
# shape and the staged copy, say so in one line, and still die of it.
if [ "${VP_SANITIZED:-0}" = 1 ] || [ "${VP_SANITIZED:-0}" = true ]; then
  echo "  (sanitizer build: AddressSanitizer reports crashes itself; not tested)"
else
  mkfifo crash.csv
  "$VDBPACK" pack box:1,1,1 --shape cube --radius 0.1 -q -o crash.csv --shape-out crash_shape.obj 2>crash.err &
  pid=$!
  for i in $(seq 300); do [ -n "$(ls -A "$TMPDIR")" ] && [ -e crash_shape.obj ] && break; sleep 0.1; done
  [ -e crash_shape.obj ] || die "the crash case never wrote its --shape-out"
  sleep 0.5
  kill -SEGV "$pid"
  rc=0; wait "$pid" || rc=$?
  [ "$rc" = 139 ] || die "a SIGSEGV'd pack exited $rc, not 139: $(cat crash.err)"
  [ "$(wc -l <crash.err)" = 1 ] && grep -q "^vdbpack: crashed (SIGSEGV); its outputs were removed" crash.err ||
    die "a SIGSEGV'd pack: $(cat crash.err)"
  [ ! -e crash_shape.obj ] || die "a crash left the --shape-out it had written"
  tmp_clean "a crash while writing through to a FIFO"
  [ -p crash.csv ] || die "the FIFO was replaced"
  echo "  ok: $(cut -c1-60 crash.err)..."
fi
echo "=== a .vdb whose tree would exceed --max-memory"
# 1e5 spheres of radius 1e-7: positions to 1e-3 of it need voxels of about
# 1e-3, a leaf node a sphere (about 0.6 GB); .csv is small
rc=0; "$VDBPACK" pack box:1,1,1 --method rsa --radius 1e-7 --count 100000 -q -o tiny.vdb --max-memory 300M 2>tiny.err || rc=$?
[ "$rc" = 1 ] && [ "$(wc -l <tiny.err)" = 1 ] && grep -q "leaf nodes" tiny.err && [ ! -e tiny.vdb ] ||
  die "tiny sparse spheres as .vdb under --max-memory 300M: exit $rc: $(cat tiny.err)"
"$VDBPACK" pack box:1,1,1 --method rsa --radius 1e-7 --count 100000 -q -o tiny.csv --max-memory 300M || die "the same as .csv"
"$VDBPACK" convert tiny.csv tiny2.vdb -q --max-memory 300M 2>tiny2.err && die "convert wrote the .vdb over the limit"
grep -q "leaf nodes" tiny2.err || die "convert: $(cat tiny2.err)"
# an ordinary packing under a modest limit is written
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.002 --count 100000 -q -o dense.vdb --max-memory 300M || die "1e5 dense spheres under 300M"
echo "  ok: $(cut -c1-100 tiny.err)..."
echo "PASS: sh_export"
