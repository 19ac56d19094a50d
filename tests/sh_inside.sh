#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Issue 26 through the command line: production meshes as containers.
#  1. the open meshes of ../shared/containers (bunny with holes, teapot of
#     unwelded, interpenetrating patches, suzanne with open eyes, the 3dfier
#     city model) pack with lattice, rsa and relax; every packing passes
#     `vdbpack check` against the mesh, and its particles are checked
#     against the winding number computed by tests/py/winding_check.py
#     (numpy alone, no vdbpack code) at their centres and 0.9 radii out;
#  2. a .vdb level set of a hollow ball whose cavity holds positive values
#     (made here with pyopenvdb) keeps its cavity: no particle in it, the
#     volume of the shell, check passes;
#  3. a fog grid with --iso (Gaffer's smoke), its check from the file's
#     metadata, and the refusals around --iso;
#  4. check uses the same inside: a full box's packing against a hollow
#     box's mesh fails;
#  5. the summary's and --json's inside and volume estimate, the warning
#     when the level set loses volume (a sword at a coarse voxel);
#  6. bad input: a mesh with no inside (a plane, a row of degenerate
#     triangles), --inside unknown, --allow-open (removed): one line,
#     non-zero exit, no output file.
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
PY=/usr/bin/python3
$PY -c 'import numpy' 2>/dev/null || { echo "SKIP: numpy not installed"; exit 77; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
WC="$PY $VP_SRC/tests/py/winding_check.py"
S=${VP_SHARED:-$VP_SRC/../shared/containers}

# --- 1. the open meshes of ../shared/containers
if [ -d "$S" ] && [ -f "$S/stanford-bunny.obj" ]; then
  for m in stanford-bunny teapot suzanne 3dfier_testarea; do
    f=$S/$m.obj
    [ -f "$f" ] || die "$f is missing from $S"
    # a radius of 1/60 of the bounding box's diagonal; 3dfier (524 m wide,
    # its inside a thin ground slab) at a coarse voxel, or it takes minutes
    r=$($PY -c "
import sys; sys.path.insert(0, '$VP_SRC/tests/py'); import winding_check as w
v, t = w.read_obj('$f'); import numpy as np
print('%.6g' % (np.linalg.norm(v.max(0) - v.min(0)) / 60))")
    extra=""
    [ "$m" = 3dfier_testarea ] && { r=2.5; extra="--voxel-size 2"; }
    for meth in lattice rsa relax; do
      case $meth in
        lattice) a="--radius $r";;
        rsa) a="--method rsa --radius $r --count max";;
        relax) a="--method relax --radius $r --count 800 --target-fraction 0.5";;
      esac
      [ "$m" = 3dfier_testarea ] && [ "$meth" = relax ] && a="--method relax --radius $r --count 100"
      # shellcheck disable=SC2086
      "$VDBPACK" pack "$f" $a $extra --seed 3 -o "$m-$meth.vdb" --json >"$m-$meth.json" 2>err.txt ||
        die "$m $meth: $(cat err.txt)"
      n=$($PY -c "import json; d = json.load(open('$m-$meth.json')); assert d['inside'] == 'winding', d['inside']; print(d['count'])")
      [ "$n" -gt 20 ] || die "$m $meth: only $n particles"
      # (3dfier takes about 8 s a load: its own check for one method; the
      # winding numbers for all three)
      if [ "$m" != 3dfier_testarea ] || [ "$meth" = rsa ]; then
        # shellcheck disable=SC2086
        "$VDBPACK" check "$m-$meth.vdb" --container "$f" $extra -q || die "$m $meth: check failed"
      fi
      "$VDBPACK" convert "$m-$meth.vdb" "$m-$meth.csv" -q
      $WC "$f" "$m-$meth.csv" --sample 60 || die "$m $meth: a particle outside the winding number"
    done
    echo "ok: $m packs by lattice, rsa and relax, inside its winding number"
  done
else
  echo "skip: ../shared/containers is absent (the shared meshes)"
fi

# --- 2. a hollow ball whose cavity holds positive values
if $PY -c 'import pyopenvdb' 2>/dev/null; then
  $PY - <<'PY'
import numpy as np, pyopenvdb as vdb
h, n = 0.02, 61
ax = np.arange(-n, n + 1) * h
X, Y, Z = np.meshgrid(ax, ax, ax, indexing="ij")
R = np.sqrt(X * X + Y * Y + Z * Z)
bg = 3 * h
sdf = np.clip(np.maximum(R - 1.0, 0.5 - R), -bg, bg).astype(np.float32)
g = vdb.FloatGrid(background=bg)
g.copyFromArray(sdf, ijk=(-n, -n, -n), tolerance=0)
for it in g.iterOnValues():  # a narrow band: only the band's voxels are active
    if abs(it.value) >= 0.999 * bg:
        it.active = False
g.prune()
g.transform = vdb.createLinearTransform(voxelSize=h)
g.gridClass = vdb.GridClass.LEVEL_SET
g.name = "hollow"
vdb.write("hollow.vdb", grids=[g])
PY
  "$VDBPACK" pack hollow.vdb --method rsa --radius 0.05 --count max -o hollow_p.csv --json >h.json ||
    die "hollow ball: pack failed"
  "$VDBPACK" pack hollow.vdb --method rsa --radius 0.05 --count 400 -o hollow_p.vdb -q
  "$VDBPACK" check hollow_p.vdb --container hollow.vdb -q || die "hollow ball: check failed"
  $PY - h.json hollow_p.csv <<'PY' || exit 1
import json, math, sys
import numpy as np
d = json.load(open(sys.argv[1]))
shell = 4.0 / 3.0 * math.pi * (1 - 0.125)
assert abs(d["container_volume"] - shell) < 0.03 * shell, ("volume", d["container_volume"], shell)
a = np.loadtxt(sys.argv[2], delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
l = np.linalg.norm(a[:, :3], axis=1)
inner = (l - a[:, 3]).min()
assert inner > 0.5 - 0.01, ("a particle in the cavity", inner)
assert (l + a[:, 3]).max() < 1.0 + 0.01
print("ok: hollow ball .vdb: volume %.4f (shell %.4f), %d particles, none in the cavity "
      "(nearest %.4f from the centre, inner wall 0.5)" % (d["container_volume"], shell, len(a), inner))
PY
else
  echo "skip: pyopenvdb (python3-openvdb) is not installed (the hollow ball .vdb)"
fi

# --- 3. a fog grid with --iso
FOG=$S/gaffer_smoke_fog.vdb
if [ -f "$FOG" ]; then
  out=$("$VDBPACK" pack "$FOG" --radius 0.5 -o fog.vdb 2>&1) && die "fog without --iso packed"
  case "$out" in *"--iso V"*) ;; *) die "fog without --iso: the message does not name --iso: $out";; esac
  [ ! -e fog.vdb ] || die "fog without --iso left fog.vdb"
  "$VDBPACK" pack "$FOG" --iso 0.5 --method rsa --radius 0.5 --count 3000 -o fog.vdb --json >fog.json ||
    die "fog --iso 0.5 failed"
  $PY -c "import json; d = json.load(open('fog.json')); assert d['iso'] == 0.5 and d['count'] > 1000 and 5000 < d['container_volume'] < 15000, d"
  "$VDBPACK" check fog.vdb --container "$FOG" -q || die "check of the fog packing (iso from the file) failed"
  out=$("$VDBPACK" pack "$FOG" --iso 100 --radius 0.5 -o bad.vdb 2>&1) && die "--iso 100 packed"
  case "$out" in *"not inside the values"*) ;; *) die "--iso 100: $out";; esac
  echo "ok: fog grid packs with --iso 0.5 and checks; no --iso and --iso out of range refused"
else
  echo "skip: $FOG is absent"
fi
# a fog ball whose outside is inactive (as sdfToFogVolume and Houdini make
# them; the sweep then had no outside to start from and every voxel
# "leaked"), at a voxel of 1 and of 1000 (OpenVDB's sweep took values of
# 1000 and more for unknown): the same volume, 4/3 pi 30^3 voxels, at both
if $PY -c 'import pyopenvdb' 2>/dev/null; then
  for vs in 1 1000; do
    $PY - "$vs" <<'PY'
import sys, numpy as np, pyopenvdb as vdb
vs = float(sys.argv[1]); n = 40
i = np.indices((2 * n,) * 3) - n + 0.5
a = np.clip(30.5 - np.sqrt((i ** 2).sum(0)), 0, 1).astype(np.float32)
g = vdb.FloatGrid(0.0); g.copyFromArray(a, (-n, -n, -n))
g.transform = vdb.createLinearTransform(vs); g.gridClass = vdb.GridClass.FOG_VOLUME; g.name = "density"
vdb.write("ball%g.vdb" % vs, [g])
PY
    "$VDBPACK" pack "ball$vs.vdb" --iso 0.5 --method rsa --radius "$((3 * vs))" --count max \
      -o "ballp$vs.vdb" --json >"ball$vs.json" 2>err.txt || die "fog ball at voxel $vs: $(cat err.txt)"
    "$VDBPACK" check "ballp$vs.vdb" --container "ball$vs.vdb" -q || die "check of the fog ball at voxel $vs"
  done
  $PY - <<'PY' || die "fog balls"
import json, math
a, b = (json.load(open("ball%s.json" % v)) for v in ("1", "1000"))
want = 4 / 3 * math.pi * 30 ** 3
for d, vs in ((a, 1), (b, 1000)):
    v = d["container_volume"] / vs ** 3
    assert abs(v / want - 1) < 0.01, "voxel %d: volume %g voxels, want %g" % (vs, v, want)
assert abs(a["count"] - b["count"]) <= 0.02 * a["count"], (a["count"], b["count"])
print("ok: fog ball with an inactive outside: volume %.0f voxels at voxel 1, %.0f at voxel 1000 "
      "(want %.0f); %d and %d spheres" % (a["container_volume"], b["container_volume"] / 1e9, want,
                                          a["count"], b["count"]))
PY
fi
out=$("$VDBPACK" pack "$VP_SRC/vdb_samples/sphere_ls.vdb" --iso 0 --radius 0.1 -o bad.vdb 2>&1) &&
  die "--iso on a level set packed"
case "$out" in *"--iso takes a fog"*|*"is a level set"*) ;; *) die "--iso on a level set: $out";; esac
out=$("$VDBPACK" pack "$VP_SRC/vdb_samples/box.obj" --iso 0.5 --radius 0.1 -o bad.vdb 2>&1) &&
  die "--iso on a mesh packed"
case "$out" in *"not a mesh"*) ;; *) die "--iso on a mesh: $out";; esac
[ ! -e bad.vdb ] || die "a refused --iso left bad.vdb"

# --- 4. check uses the same inside: a hollow box's mesh fails a full box's packing
$PY - <<'PY'
def box(f, s, flip, base):
    v = [(x * s, y * s, z * s) for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]
    for p in v:
        f.write("v %g %g %g\n" % p)
    # faces of the cube with vertices (x, y, z) = bits of the index, outward
    q = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    for a, b, c, d in q:
        t = [(a, b, c), (a, c, d)]
        for i, j, k in t:
            if flip:
                j, k = k, j
            f.write("f %d %d %d\n" % (base + i + 1, base + j + 1, base + k + 1))
with open("full.obj", "w") as f:
    box(f, 0.5, False, 0)
with open("hollow.obj", "w") as f:
    box(f, 0.5, False, 0)
    box(f, 0.25, True, 8)
PY
"$VDBPACK" pack full.obj --radius 0.05 -o full.vdb -q
"$VDBPACK" pack hollow.obj --radius 0.05 -o hbox.vdb --json >hbox.json
$PY -c "import json; d = json.load(open('hbox.json')); assert d['inside'] == 'winding' and d['cavities'] == 1, d"
rc=0; "$VDBPACK" check full.vdb --container hollow.obj >chk.txt 2>&1 || rc=$?
[ "$rc" = 3 ] || die "a full box's packing against the hollow box: exit $rc, not 3: $(cat chk.txt)"
grep -q "outside the container: [1-9]" chk.txt || die "check did not count the particles in the cavity: $(cat chk.txt)"
"$VDBPACK" check hbox.vdb --container hollow.obj -q || die "the hollow box's own packing fails check"
echo "ok: check takes the hollow box's cavity as outside ($(grep -o 'outside the container: [0-9]*' chk.txt))"

# --- 5. the summary, --json and the volume warning
"$VDBPACK" pack full.obj --radius 0.05 -o s.vdb >sum.txt
grep -q "inside: closed surface" sum.txt || die "summary: $(cat sum.txt)"
grep -q "volume estimate 1 (the mesh's signed volume)" sum.txt || die "summary estimate: $(cat sum.txt)"
"$VDBPACK" pack full.obj --radius 0.05 --inside winding -o s.vdb >sum.txt
grep -q "inside: by winding number" sum.txt || die "--inside winding: $(cat sum.txt)"
rm -f s.vdb
if [ -f "$S/sword.obj" ]; then
  # the blade is 0.004 to 0.008 thick: a voxel of 0.01 loses it
  "$VDBPACK" pack "$S/sword.obj" --radius 0.002 --voxel-size 0.01 -o sw.vdb --json >sw.json 2>sw.err || true
  grep -q "warning: the container's inside" sw.err || die "no volume warning for the sword: $(cat sw.err)"
  [ "$(grep -c . sw.err)" = 1 ] || die "the warning is not one line: $(cat sw.err)"
  if [ -s sw.json ]; then
    $PY -c "import json; d = json.load(open('sw.json')); assert d['volume_mismatch'] is True and d['volume_estimate_kind'] == 'mesh_volume', d"
  fi
  echo "ok: the sword at a coarse voxel warns: $(cut -c1-100 sw.err)..."
fi

# --- 6. bad input
printf 'v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n' >plane.obj
printf 'v 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 0 0\nf 1 2 3\nf 2 3 4\n' >line.obj
bad() { # NAME STATUS PATTERN ARGS...
  local name=$1 want=$2 pat=$3; shift 3
  local rc=0
  "$VDBPACK" "$@" >o.txt 2>e.txt || rc=$?
  [ "$rc" = "$want" ] || die "$name: exit $rc, not $want: $(cat e.txt)"
  [ "$(grep -c . e.txt)" = 1 ] || die "$name: not one line on stderr: $(cat e.txt)"
  grep -q -- "$pat" e.txt || die "$name: stderr lacks '$pat': $(cat e.txt)"
  [ ! -e out.vdb ] || die "$name: left out.vdb"
  echo "ok: $name: exit $rc: $(cat e.txt)"
}
bad "plane" 1 "has no inside" pack plane.obj --radius 0.1 -o out.vdb
bad "line of degenerate triangles" 1 "vdbpack: line.obj" pack line.obj --radius 0.1 -o out.vdb
bad "--inside unknown" 2 "unknown --inside 'open'" pack full.obj --inside open --radius 0.1 -o out.vdb
bad "--allow-open removed" 2 "was removed" pack full.obj --allow-open --radius 0.1 -o out.vdb
bad "check --allow-open removed" 2 "was removed" check full.vdb --container full.obj --allow-open
bad "--inside closed on an open mesh" 1 "use --inside auto or winding" pack plane.obj --inside closed --radius 0.1 -o out.vdb
bad "--inside on an analytic container" 2 "need a mesh or .vdb" pack box:1,1,1 --inside winding --radius 0.1 -o out.vdb
echo "all ok"
