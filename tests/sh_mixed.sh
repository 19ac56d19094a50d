#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Several shapes in one packing through the command line (--pass ...,shape=):
# a ternary packing of cubes, a concave mesh shape and grown spheres is
# checked by `vdbpack check`, its shape attribute and metadata are read
# back with OpenVDB's own tools (tests/dump_points on OpenVDB's API,
# vdb_print, vdb_ax) and compared in numpy with the CSV export, the sphere
# pairs are checked here by distance; PLY and CSV round trips keep the
# shapes; render, --shape-out and OBJ export handle the set; bad pass
# shapes give one line, a non-zero exit and no file.
set -euo pipefail
: "${VDBPACK:?}" "${VP_DUMP_POINTS:?}"
VP_SRC=${VP_SRC:-$(cd "$(dirname "$0")/.." && pwd)}
PY=/usr/bin/python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
PEANUT=$VP_SRC/vdb_samples/peanut.obj

echo "=== ternary: cubes, peanut.obj (concave), grown spheres"
"$VDBPACK" pack box:1,1,1 --method rsa --seed 4 -o m.vdb --json --shape-out shapes.obj \
  --pass count=60,radius=0.1,shape=cube,name=cubes \
  --pass count=250,radius=0.06,shape="$PEANUT",name=peanuts \
  --pass count=max,radius=0.025,retries=3000,grow,name=grains >m.json
"$PY" - <<'PY'
import json
j = json.load(open("m.json"))
assert j["shape"] == "mixed", j["shape"]
names = [s["shape"] for s in j["shapes"]]
assert names == ["cube", "mesh:peanut.obj", "sphere"], names
assert sum(s["count"] for s in j["shapes"]) == j["count"], j["shapes"]
assert [p["shape"] for p in j["passes"]] == names, [p["shape"] for p in j["passes"]]
assert [s["count"] for s in j["shapes"]][:2] == [60, 250], j["shapes"]
print("  ok: %d particles: %s" % (j["count"], ", ".join("%d %s" % (s["count"], s["shape"]) for s in j["shapes"])))
PY
"$VDBPACK" check m.vdb --container box:1,1,1 --shape "$PEANUT" --json >c.json || die "check: $(cat c.json)"
"$PY" -c "
import json; j = json.load(open('c.json'))
assert j['overlapping_pairs'] == 0 and j['outside'] == 0 and j['shape'] == 'mixed', j
assert j['mean_contacts'] > 0.3, j
print('  ok: check: no overlap, none outside, mean contacts %.2f' % j['mean_contacts'])"

echo "=== the file as OpenVDB reads it"
vdb_print -m m.vdb >m.meta 2>&1
grep -q "shape: mixed" m.meta || die "no shape: mixed in $(cat m.meta)"
grep -q "shapes: cube;mesh:peanut.obj;sphere" m.meta || die "no shapes list in $(cat m.meta)"
"$VP_DUMP_POINTS" m.vdb >m.txt
"$VDBPACK" convert m.vdb m.csv -q
"$PY" - <<'PY'
import numpy as np
rows = [l.split() for l in open("m.txt")]
assert all(len(r) == 11 for r in rows), "id P pscale orient groups shape on every line"
ids = np.array([int(r[0]) for r in rows])
shape = np.array([int(r[10]) for r in rows])[np.argsort(ids)]
group = np.array([r[9] for r in rows])[np.argsort(ids)]
P = np.array([[float(x) for x in r[1:4]] for r in rows])[np.argsort(ids)]
R = np.array([float(r[4]) for r in rows])[np.argsort(ids)]
# the attribute against the passes' groups and the CSV's names
want = {"cubes": 0, "peanuts": 1, "grains": 2}
assert all(shape[i] == want[g] for i, g in enumerate(group)), "shape index != pass"
csv = open("m.csv").read().splitlines()
assert csv[0].endswith(",group,shape"), csv[0]
names = [l.rsplit(",", 1)[1] for l in csv[1:]]
order = ["cube", "mesh:peanut.obj", "sphere"]
assert [order[k] for k in shape] == names, "CSV shape names differ from the attribute"
# sphere pairs by distance (positions are stored full precision)
s = np.where(shape == 2)[0]
d = np.linalg.norm(P[s, None, :] - P[None, s, :], axis=-1)
e = R[s, None] + R[None, s]
np.fill_diagonal(d, np.inf)
worst = ((d - e) / e).min()
assert worst > -1e-6, worst
print("  ok: %d points: shape attribute = pass = CSV name; %d spheres, least gap %.2g of r_i + r_j"
      % (len(ids), len(s), worst))
PY
# vdb_ax (OpenVDB's AX) sees the attribute: delete every point whose shape
# is not 1 and count what is left
if command -v vdb_ax >/dev/null && command -v vdb_tool >/dev/null; then
  env OPENVDB_DISABLE_DELAYED_LOAD=1 vdb_ax -i m.vdb -s 'if (i@shape != 1) deletepoint();' \
    -o ax.vdb >ax.out 2>&1 || die "vdb_ax: $(cat ax.out)"
  vdb_tool -quiet -read ax.vdb -vdb2points -write ax.ply >/dev/null 2>&1 || die "vdb_tool"
  n=$("$PY" -c "
import re; h = open('ax.ply','rb').read(2000).decode('latin1')
print(re.search(r'element vertex (\d+)', h).group(1))")
  [ "$n" = 250 ] || die "vdb_ax kept $n points of shape 1, not 250"
  echo "  ok: vdb_ax i@shape: 250 points of shape 1"
fi

echo "=== PLY and CSV round trips, render, shape-out, OBJ"
"$VDBPACK" convert m.vdb m.ply -q
"$VDBPACK" convert m.ply back_ply.vdb -q
"$VDBPACK" convert m.csv back_csv.vdb -q
for f in back_ply.vdb back_csv.vdb; do
  "$VDBPACK" check "$f" --container box:1,1,1 --shape "$PEANUT" -q || die "check of $f"
  vdb_print -m "$f" >"$f.meta" 2>&1 # (not piped into grep -q: SIGPIPE under pipefail)
  grep -q "shape: mixed" "$f.meta" || die "$f lost the shapes"
done
grep -aq "comment shapes cube;mesh:peanut.obj;sphere" m.ply || die "PLY shapes comment"
echo "  ok: PLY and CSV read back, checked"
"$VDBPACK" render m.vdb -o m.png --size 160x90 --shape "$PEANUT" -q || die "render"
[ -s m.png ] || die "no image"
[ "$(grep -c '^g shape' shapes.obj)" = 3 ] || die "shape-out groups: $(grep '^g' shapes.obj)"
"$VDBPACK" convert m.vdb m.obj -q 2>/dev/null && die "OBJ of a set with a mesh shape and no mesh"
"$VDBPACK" pack box:1,1,1 --method rsa --seed 1 -o two.obj -q \
  --pass count=5,radius=0.1,shape=cube --pass count=7,radius=0.05 || die "OBJ export"
"$PY" -c "
lines = open('two.obj').read().splitlines()
v = sum(l.startswith('v ') for l in lines)
assert v == 5 * 8 + 7 * (10 * 2 * 2 + 2), v   # 8 corners a cube, icospheres of n = 2
print('  ok: OBJ of 5 cubes and 7 spheres: %d vertices' % v)"

echo "=== bad input: one line, non-zero exit, no file"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n' >open.obj
bad() { # EXIT-STATUS WHAT ARGS...
  local want=$1 what=$2; shift 2
  rm -f out.vdb
  set +e; "$@" >out.txt 2>err.txt; local rc=$?; set -e
  [ "$rc" = "$want" ] || die "$what: exit $rc, not $want ($(cat err.txt))"
  [ "$(wc -l <err.txt)" = 1 ] || die "$what: not one line: $(cat err.txt)"
  [ ! -e out.vdb ] || die "$what: left out.vdb"
  echo "  ok: $what: $(cat err.txt)"
}
P=("$VDBPACK" pack box:1,1,1 --method rsa -o out.vdb --pass count=10,radius=0.05)
bad 2 "superball:0.3" "${P[@]}" --pass count=5,radius=0.05,shape=superball:0.3
bad 2 "superball:nan" "${P[@]}" --pass count=5,radius=0.05,shape=superball:nan
bad 2 "unknown solid" "${P[@]}" --pass count=5,radius=0.05,shape=dodecahedrone
bad 1 "open mesh shape" "${P[@]}" --pass count=5,radius=0.05,shape=open.obj
bad 2 "empty shape" "${P[@]}" --pass count=5,radius=0.05,shape=
bad 2 "gap with a mesh pass" "${P[@]}" --pass count=5,radius=0.05,shape="$PEANUT" --gap 0.01
bad 2 "bbox with a pass shape" "${P[@]}" --pass count=5,radius=0.05,shape=cube --overlap bbox \
  --orient fixed
bad 2 "lattice" "$VDBPACK" pack box:1,1,1 -o out.vdb --pass count=5,radius=0.05,shape=cube
many=(); for i in $(seq 1 17); do many+=(--pass "count=1,radius=0.01,shape=superball:$((i + 1))"); done
bad 1 "17 shapes" "$VDBPACK" pack box:1,1,1 --method rsa -o out.vdb "${many[@]}"
bad 2 "check without the mesh" "$VDBPACK" check m.vdb --container box:1,1,1
bad 2 "check with two meshes for one" "$VDBPACK" check m.vdb --container box:1,1,1 \
  --shape "$PEANUT" --shape "$PEANUT"
echo "PASS"
