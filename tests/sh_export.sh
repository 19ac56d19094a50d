#!/usr/bin/env bash
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
echo "PASS: sh_export"
