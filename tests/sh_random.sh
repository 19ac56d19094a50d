#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# The random packers through the CLI (--method rsa, --method relax), read back
# with OpenVDB's own tools only (vdb_ax rewrites P, vdb_tool extracts it,
# numpy checks: tests/py/random_check.py), then with `vdbpack check`; and
# issue 3's bad input: one line on stderr, non-zero exit, no output file.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
for t in vdb_ax vdb_tool; do command -v $t >/dev/null || { echo "SKIP: $t not installed"; exit 77; }; done
PY=""
for p in /usr/bin/python3 python3; do
  if command -v "$p" >/dev/null && "$p" -c 'import numpy' 2>/dev/null; then PY=$p; break; fi
done
[ -n "$PY" ] || { echo "SKIP: no python3 with numpy"; exit 77; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
AX=(env OPENVDB_DISABLE_DELAYED_LOAD=1 vdb_ax)
jget() { "$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }

extract() { # VDB N NGROUPS -> x.ply y.ply z.ply a.ply in ./ex
  local in=$1 n=$2 ng=$3 gcode="float gi = 0.0f;"
  for k in $(seq 1 "$ng"); do gcode="$gcode if (ingroup(\"pass$k\")) gi = float($k);"; done
  rm -rf ex; mkdir ex
  for c in x y z; do
    "${AX[@]}" -i "$in" -s "@P = {@P.$c, float(i@id), 0.0f};" -o ex/$c.vdb >ax.out 2>&1 || die "vdb_ax ($c): $(cat ax.out)"
    vdb_tool -quiet -read ex/$c.vdb -vdb2points -write ex/$c.ply >/dev/null 2>&1 || die "vdb_tool ($c)"
  done
  "${AX[@]}" -i "$in" -s "$gcode @P = {f@pscale, float(i@id), gi};" -o ex/a.vdb >ax.out 2>&1 || die "vdb_ax (a): $(cat ax.out)"
  vdb_tool -quiet -read ex/a.vdb -vdb2points -write ex/a.ply >/dev/null 2>&1 || die "vdb_tool (a)"
}

case_ok() { # NAME CONTAINER FIT GROUPCOUNTS(or -) NGROUPS pack-args...
  local name=$1 cont=$2 fit=$3 groups=$4 ng=$5; shift 5
  echo "=== $name: pack $cont --fit $fit $*"
  "$VDBPACK" pack "$cont" --fit "$fit" -o "$name.vdb" --json "$@" >"$name.json" 2>"$name.err" ||
    die "pack failed: $(cat "$name.err")"
  local n; n=$(jget "$name.json" count)
  [ "$n" -gt 0 ] || die "no particles"
  echo "  $n particles, fraction $(jget "$name.json" packing_fraction)"
  extract "$name.vdb" "$n" "$ng"
  "$PY" "$VP_SRC/tests/py/random_check.py" ex "$n" "$cont" "$fit" "$groups" "$name.json" || exit 1
  "$VDBPACK" check "$name.vdb" --container "$cont" --fit "$fit" --json >"$name.check" 2>&1 ||
    die "vdbpack check found a violation or failed: $(cat "$name.check")"
  [ "$(jget "$name.check" overlapping_pairs)" = 0 ] || die "check: overlapping pairs"
  echo "  ok: vdbpack check: no violation, mean contacts $(jget "$name.check" mean_contacts)"
}

# binary RSA with grow: group sizes exact when every particle is placed
case_ok binary box:1,1,1 inside 60,1500 2 --method rsa --seed 3 \
  --pass count=60,radius=0.06,grow --pass count=1500,radius=0.015
[ "$(jget binary.json packing_fraction)" != 0 ] || die "binary: zero fraction"
"$PY" - binary.json <<'PY' || exit 1
import json, sys
d = json.load(open(sys.argv[1]))
p = d["passes"]
assert [q["placed"] for q in p] == [60, 1500], p
assert p[0]["grow"] and p[0]["grow_mean"] > 1.0, "pass 1 grew by %s" % p[0]["grow_mean"]
assert [q["stop"] for q in p] == ["count", "count"], p
print("  ok: JSON passes: placed 60 and 1500, pass 1 grown x%.3f" % p[0]["grow_mean"])
PY
# a distribution, centre fit, sphere container
case_ok lognormal sphere:1 center 800 1 --method rsa --seed 9 --radius lognormal:0.04:0.01 --count 800
# ternary, one pass maximal
case_ok ternary box:1,1,1 inside - 3 --method rsa --seed 4 --pass count=20,radius=0.1 \
  --pass count=200,radius=0.04 --pass count=max,radius=0.03
# relaxation with a target fraction
case_ok relax sphere:1 inside 600 1 --method relax --seed 2 --radius 1 --count 600 --target-fraction 0.5
"$PY" -c "
import json; d = json.load(open('relax.json'))
assert d['max_overlap'] <= 1e-6, d['max_overlap']
assert 0 < d['radius_scale'] <= 1, d['radius_scale']
print('  ok: relax: largest overlap %.2g <= 1e-6, radii scaled by %.4f' % (d['max_overlap'], d['radius_scale']))" || die relax-json
# retry limit: more than fit (20 spheres of radius 0.2 are 0.67 of the box,
# under the 0.7405 that would refuse them, but far over what RSA reaches),
# stops by retries
# (issue 31: packed, but short: exit status 4, one warning line, the file
# written)
set +e; "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.2 --count 20 --retries 200 -o full.vdb --json >full.json 2>full.err; st=$?; set -e
[ "$st" = 4 ] && [ -s full.vdb ] && [ "$(wc -l <full.err)" = 1 ] && grep -q "packed, but short" full.err ||
  die "a count over what fits must still pack what fits, exit 4: exit $st, $(cat full.err)"
"$PY" -c "
import json; p = json.load(open('full.json'))['passes'][0]
assert p['stop'] == 'retries' and 0 < p['placed'] < 20, p
print('  ok: count 20 of radius 0.2 in a unit box: placed %d, stopped by retries' % p['placed'])" || die retries
# same seed, same file; another seed, another file
# (the command line is file metadata: same command in t1/ and t2/, threads
# from the environment)
same_cmd() { # DIR THREADS METHOD-ARGS...
  local d=$1 t=$2; shift 2
  mkdir -p "$d"; (cd "$d" && VDBPACK_THREADS=$t "$VDBPACK" pack "$@" -o d.vdb -q) || die "pack in $d"
}
for m in "box:1,1,1 --method rsa --radius 0.03 --count 2000 --seed 7" \
         "box:1,1,1 --method rsa --pass count=30,radius=0.08,grow --pass count=max,radius=0.03 --seed 7" \
         "sphere:1 --method relax --radius uniform:0.5:1 --count 3000 --target-fraction 0.55 --seed 7"; do
  # shellcheck disable=SC2086
  same_cmd t1 1 $m; same_cmd t2 2 $m
  # shellcheck disable=SC2086
  same_cmd t3 2 ${m/--seed 7/--seed 8}
  cmp -s t1/d.vdb t2/d.vdb || die "'$m': 1 and 2 threads give different files"
  cmp -s t1/d.vdb t3/d.vdb && die "'$m': seeds 7 and 8 give the same file"
  echo "  ok: identical for 1 and 2 threads, different for another seed: $m"
done

# bad input: one line on stderr, exit status, no output file
bad() { # EXPECTED_STATUS WORD args...
  local want=$1 word=$2; shift 2
  rm -f bad.vdb
  set +e; "$VDBPACK" pack "$@" -o bad.vdb >bad.out 2>bad.err; local st=$?; set -e
  [ "$st" = "$want" ] || die "'$*' exited $st, expected $want: $(cat bad.err)"
  [ "$(wc -l <bad.err)" = 1 ] || die "'$*' printed $(wc -l <bad.err) lines on stderr: $(cat bad.err)"
  grep -qi -- "$word" bad.err || die "'$*': message lacks '$word': $(cat bad.err)"
  [ ! -e bad.vdb ] || die "'$*' left an output file"
  echo "  ok: $(cat bad.err)"
}
echo "=== bad input"
bad 2 "unknown field" box:1,1,1 --method rsa --pass count=10,radius=0.1,colour=red
bad 2 "count" box:1,1,1 --method rsa --pass radius=0.1
bad 2 "count" box:1,1,1 --method rsa --pass count=ten,radius=0.1
bad 2 "unknown distribution" box:1,1,1 --method rsa --pass count=10,radius=gamma:1:2
bad 2 "> 0" box:1,1,1 --method rsa --pass count=10,radius=-0.1
bad 2 "> 0" box:1,1,1 --method rsa --pass count=10,radius=0
bad 2 "A <= B" box:1,1,1 --method rsa --pass count=10,radius=uniform:0.2:0.1
bad 2 "retries" box:1,1,1 --method rsa --pass count=10,radius=0.1,retries=0
bad 2 "retries" box:1,1,1 --method rsa --radius 0.1 --count 10 --retries 0
# (count=max with a distribution, refused before issue 31, fills until no
# room is left for its smallest radius: tests/sh_options.sh,
# tests/test_rsa_maximal_sizes.c)
bad 2 "target-fraction" box:1,1,1 --method relax --radius 0.1 --count 10 --target-fraction 1
bad 2 "target-fraction" box:1,1,1 --method relax --radius 0.1 --count 10 --target-fraction 1.5
bad 2 "count" box:1,1,1 --method relax --radius 0.1
bad 2 "spheres" box:1,1,1 --method relax --shape cube --radius 0.1 --count 10
bad 2 "fixed" box:1,1,1 --method rsa --shape cube --overlap bbox --orient random --radius 0.1 --count 10
bad 2 "shape" box:1,1,1 --method rsa --orient fixed --radius 0.1 --count 10
bad 2 "orient" box:1,1,1 --method rsa --shape cube --orient sideways --radius 0.1 --count 10
bad 1 "radius" box:1,1,1 --method rsa --radius 2 --count 10
bad 1 "" box:1,1,1 --method relax --radius 0.3 --count 500
# malformed pass strings that strtok would have let through
bad 2 "empty field" box:1,1,1 --method rsa --pass count=10,radius=0.1,
bad 2 "empty field" box:1,1,1 --method rsa --pass count=10,,radius=0.1
bad 2 "count is given twice" box:1,1,1 --method rsa --pass count=10,radius=0.1,count=5
bad 2 "grow is given twice" box:1,1,1 --method rsa --pass count=10,radius=0.1,grow,grow
# one group name for two passes (pack wrote .csv with the groups merged and
# refused .vdb after packing); OpenVDB's own names start with __
bad 2 "passes 1 and 2 would both be group 'pass2'" box:1,1,1 --method rsa --pass count=5,radius=0.1,name=pass2 --pass count=5,radius=0.05
bad 2 "passes 1 and 2 would both be group 'big'" box:1,1,1 --method rsa --pass count=5,radius=0.1,name=big --pass count=5,radius=0.05,name=big
bad 2 "not starting with __" box:1,1,1 --method rsa --pass count=5,radius=0.1,name=__group
# radii are stored as float: below its smallest normal value they would be 0
bad 2 "1.2e-38" box:1,1,1 --method rsa --pass count=10,radius=1e-46
bad 2 "1.2e-38" box:1,1,1 --method rsa --pass count=10,radius=1e-300
bad 2 "3.4e38" box:1,1,1 --method rsa --pass count=10,radius=1e39
bad 2 "1.2e-38" box:1,1,1 --method relax --radius 1e-46 --count 10
bad 2 "reach below" box:1,1,1 --method rsa --pass count=10,radius=uniform:1e-40:0.1
# counts that no packing can hold (rsa; relax refuses them above)
bad 1 "105 times the container's volume" box:1,1,1 --method rsa --pass count=200000,radius=0.05
bad 1 "1.25 times the container's volume" sphere:1 --method rsa --pass count=10000,radius=0.05
bad 1 "0.7405" box:1,1,1 --method rsa --pass count=1500,radius=0.05
bad 1 "0.7405" box:1,1,1 --method rsa --pass count=1000,radius=0.05 --pass count=800,radius=0.05
bad 1 "cannot fit" box:1,1,1 --method rsa --pass count=1000,radius=0.05 --pass count=1000,radius=0.06
bad 1 "grown by the largest radius" box:1,1,1 --fit center --method rsa --pass count=15000,radius=0.05
# Kepler's bound holds in a box, not in a container shaped to its spheres:
# one sphere filling 0.857 of a sphere is packed
"$VDBPACK" pack sphere:1 --method rsa --pass count=1,radius=0.95 -o one.vdb -q || die "one sphere of 0.95 in sphere:1"
# a sphere wider than the box is thin, though its volume would fit
bad 1 "leaves no room" box:1,1,0.5 --method rsa --pass count=1,radius=0.3
# an analytic container beyond what float positions hold
bad 2 "1e18" sphere:1e300 --method rsa --pass count=10,radius=0.05
# a first particle drawn large that never finds room: the message names it
bad 1 "tries in a row failed for the first particle" box:1,1,1 --method rsa --pass count=20,radius=uniform:0.01:0.49
# the container named as the output: refused before anything is read or written
cp "$VP_SRC/vdb_samples/torus_ls.vdb" own.vdb
set +e; "$VDBPACK" pack own.vdb --method rsa --pass count=10,radius=0.05 -o own.vdb >bad.out 2>bad.err; st=$?; set -e
[ "$st" = 2 ] && grep -q "container itself" bad.err || die "-o naming the container: exit $st, $(cat bad.err)"
cmp -s own.vdb "$VP_SRC/vdb_samples/torus_ls.vdb" || die "-o naming the container changed it"
echo "  ok: $(cat bad.err)"
bad 2 "same file" box:1,1,1 --radius 0.1 --save-container bad.vdb
# a count pass that runs out of room (under the 0.7405 bound, over what
# RSA reaches) says why it stopped
"$VDBPACK" pack box:1,1,1 --method rsa --pass count=1400,radius=0.05 -o short.vdb --allow-short >short.out
grep -q "placed [0-9]* of 1400 (stopped: no room left for another)" short.out ||
  die "short count pass: $(cat short.out)"
echo "  ok: $(grep pass1 short.out)"
# with fit center particles may reach out of the container: a fraction over 1
# says why
"$VDBPACK" pack box:1,1,0.01 --fit center --method rsa --pass count=50,radius=0.05 -o flat.vdb >flat.out
grep -q "packing fraction [1-9][0-9.]* (over 1: with --fit center" flat.out || die "fraction over 1: $(cat flat.out)"
echo "  ok: $(grep fraction flat.out)"
# solids (issue 5): random orientations in a level-set container, grown
mesh="$VP_SRC/vdb_samples/peanut.obj"
echo "=== solids: octahedra, random orientations, grow, in $mesh"
"$VDBPACK" pack "$mesh" --method rsa --shape octahedron --radius 0.07 --count 600 --grow \
  -o solids.vdb --json >solids.json 2>solids.err || die "solids: $(cat solids.err)"
"$PY" - solids.json <<'PY' || exit 1
import json, sys
d = json.load(open(sys.argv[1]))
assert d["shape"] == "octahedron" and d["orient"] == "random" and d["overlap"] == "exact", d
p = d["passes"][0]
assert p["placed"] == 600 and p["grow_mean"] > 1.0, p
print("  ok: 600 octahedra, grown x%.3f, fraction %.4f" % (p["grow_mean"], d["packing_fraction"]))
PY
"$VDBPACK" check solids.vdb --container "$mesh" --json >solids.check 2>&1 ||
  die "solids: vdbpack check found a violation: $(cat solids.check)"
[ "$(jget solids.check overlapping_pairs)" = 0 ] && [ "$(jget solids.check outside)" = 0 ] ||
  die "solids: check: $(cat solids.check)"
[ "$(jget solids.check shape)" = octahedron ] || die "solids: check read shape $(jget solids.check shape)"
"${AX[@]}" -i solids.vdb -s 'vec4f q = vec4f@orient; if (q[0] > 2.0f) deletepoint();' >orient.txt 2>&1 || true
grep -q 'Attribute "orient" on grid "points" exists of type "quats"' orient.txt ||
  die "solids: vdb_ax does not see orient as quats: $(cat orient.txt)"
echo "  ok: vdbpack check clean; orient stored as quats"
# mesh shapes (issue 5): a concave shipped mesh (its centroid lies in the
# hole), the unit shape written for instancing, check with --shape
shp="$VP_SRC/vdb_samples/torus.obj"
echo "=== mesh shapes: torus.obj particles in a box"
"$VDBPACK" pack box:1,1,1 --method rsa --shape "$shp" --radius 0.1 --count 100 \
  -o tori.vdb --shape-out unit_torus.obj --json >tori.json 2>tori.err || die "tori: $(cat tori.err)"
"$PY" - tori.json unit_torus.obj "$shp" <<'PY' || exit 1
import json, math, sys
d = json.load(open(sys.argv[1]))
assert d["shape"] == "mesh" and d["shape_file"] == "torus.obj" and d["orient"] == "random", d
assert d["passes"][0]["placed"] == 100, d["passes"][0]
# the unit shape: as many vertices and faces as the source, bounding radius 1
def load(path):
    v, f = [], 0
    for line in open(path):
        t = line.split()
        if t and t[0] == "v": v.append(tuple(map(float, t[1:4])))
        if t and t[0] == "f": f += 1
    return v, f
uv, uf = load(sys.argv[2])
sv, sf = load(sys.argv[3])
r = max(math.sqrt(x * x + y * y + z * z) for x, y, z in uv)
assert abs(r - 1) < 1e-12, r
assert len(uv) == len(sv) and uf >= sf, (len(uv), len(sv), uf, sf)
print("  ok: 100 tori, fraction %.4f; unit shape %d vertices, radius %.15f" % (d["packing_fraction"], len(uv), r))
PY
"$VDBPACK" check tori.vdb --container box:1,1,1 --shape "$shp" --json >tori.check 2>&1 ||
  die "tori: vdbpack check found a violation: $(cat tori.check)"
[ "$(jget tori.check overlapping_pairs)" = 0 ] && [ "$(jget tori.check outside)" = 0 ] &&
  [ "$(jget tori.check shape)" = mesh ] || die "tori: check: $(cat tori.check)"
# a check that could fail: the same file against a smaller box
set +e; "$VDBPACK" check tori.vdb --container box:0.8,0.8,0.8 --shape "$shp" -q 2>/dev/null; st=$?; set -e
[ "$st" = 3 ] || die "tori: check against a smaller box exited $st, expected 3"
set +e; "$VDBPACK" check tori.vdb --container box:1,1,1 >chk.out 2>chk.err; st=$?; set -e
[ "$st" = 2 ] && [ "$(wc -l <chk.err)" = 1 ] && grep -q "torus.obj" chk.err ||
  die "tori: check without --shape: exit $st: $(cat chk.err)"
"${AX[@]}" -i tori.vdb -s 'vec4f q = vec4f@orient; if (q[0] > 2.0f) deletepoint();' >orient.txt 2>&1 || true
grep -q 'Attribute "orient" on grid "points" exists of type "quats"' orient.txt ||
  die "tori: vdb_ax does not see orient as quats: $(cat orient.txt)"
echo "  ok: check clean with --shape, refuses without it ($(cat chk.err))"
# the full geometry as OBJ: every particle is the normalised mesh, moved
"$VDBPACK" pack box:1,1,1 --method rsa --shape "$shp" --radius 0.1 --count 5 -o tori.obj -q ||
  die "tori: OBJ export failed"
nv=$(grep -c '^v ' tori.obj); nf=$(grep -c '^f ' tori.obj)
[ "$nv" = $((5 * $(grep -c '^v ' unit_torus.obj))) ] && [ "$nf" = $((5 * $(grep -c '^f ' unit_torus.obj))) ] ||
  die "tori.obj: $nv vertices, $nf faces for 5 tori"
set +e; "$VDBPACK" render tori.vdb -o tori.png >/dev/null 2>rend.err; st=$?; set -e
[ "$st" = 2 ] && [ "$(wc -l <rend.err)" = 1 ] && [ ! -e tori.png ] || die "render of mesh shapes without --shape: exit $st: $(cat rend.err)"
# another mesh than the one recorded (shape_file): a warning, not silence
set +e; "$VDBPACK" check tori.vdb --container box:1,1,1 --shape "$VP_SRC/vdb_samples/peanut.obj" -q \
  >/dev/null 2>wrong.err; set -e
grep -q "^vdbpack: warning: tori.vdb was packed with the mesh shape 'torus.obj', not 'peanut.obj'$" wrong.err ||
  die "check with another mesh: no warning: $(cat wrong.err)"
"$VDBPACK" check tori.vdb --container box:1,1,1 --shape "$shp" -q 2>right.err || die "check tori: $(cat right.err)"
[ ! -s right.err ] || die "a warning with the recorded mesh: $(cat right.err)"
echo "  ok: $(cat wrong.err | head -1)"
# rendered: one torus seen from the front through its hole, the hole shows
# the background (a sphere of the same bounding radius would cover it)
"$VDBPACK" pack box:1,1,1 --method rsa --shape "$shp" --orient fixed --radius 0.4 --count 1 -o one.vdb -q &&
  "$VDBPACK" render one.vdb --shape "$shp" -o one.png --view front --size 201x201 --ao 0 -q ||
  die "render of one torus failed"
"$PY" - one.png "$VP_SRC/tests/py" <<'PY' || exit 1
import sys
sys.path.insert(0, sys.argv[2])
from png_read import read
w, h, rows = read(sys.argv[1])
alpha = lambda x, y: rows[y][x * 4 + 3]
cx = cy = w // 2
covered = sum(1 for y in range(h) for x in range(w) if alpha(x, y))
assert alpha(cx, cy) == 0, "the torus's hole is covered"
assert covered > 2000, covered
ring = [alpha(cx + dx, cy) for dx in range(1, w // 2)]
assert any(ring), "no torus around the hole"
print("  ok: one torus rendered, %d pixels covered, its hole clear" % covered)
PY
echo "  ok: OBJ export $nv vertices, $nf faces; render needs --shape, then draws the mesh"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n' >open_shape.obj
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n' >flat_shape.obj
bad 2 "unknown --shape" box:1,1,1 --method rsa --shape cubes --radius 0.1 --count 10
bad 1 "not closed" box:1,1,1 --method rsa --shape open_shape.obj --radius 0.1 --count 10
bad 1 "no volume" box:1,1,1 --method rsa --shape flat_shape.obj --radius 0.1 --count 10
bad 1 "nothere.obj" box:1,1,1 --method rsa --shape nothere.obj --radius 0.1 --count 10
bad 2 "method rsa" box:1,1,1 --method lattice --shape "$shp" --radius 0.1
bad 2 "fixed" box:1,1,1 --method rsa --shape "$shp" --overlap bbox --orient random --radius 0.1 --count 10
if [ -f "$VP_SHARED/spot.obj" ]; then
  echo "=== mesh shapes: grown cows (spot.obj) in peanut.obj"
  "$VDBPACK" pack "$mesh" --method rsa --shape "$VP_SHARED/spot.obj" --radius 0.12 --count 120 --grow \
    -o cows.vdb --json >cows.json 2>cows.err || die "cows: $(cat cows.err)"
  "$VDBPACK" check cows.vdb --container "$mesh" --shape "$VP_SHARED/spot.obj" --json >cows.check 2>&1 ||
    die "cows: vdbpack check found a violation: $(cat cows.check)"
  echo "  ok: $(jget cows.json count) cows grown, fraction $(jget cows.json packing_fraction), check clean"
else
  echo "=== skipped: ../shared/containers/spot.obj not present"
fi
echo "PASS: sh_random"
