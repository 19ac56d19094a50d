#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# --method jam through the command line (issue 28): packings that
# `vdbpack check` passes and that an independent numpy check of every pair
# and of the wall passes too (from the CSV), the same file on 1 and 2
# threads, the report in --json and the file's metadata, and bad input
# (one line, non-zero exit, no output file).
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
PY=/usr/bin/python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }

# 1. box and sphere containers, equal and lognormal radii
for spec in "box:1,1,1 --count 600" "sphere:1 --count 500 --radius lognormal:0.05:0.01" \
            "box:1,1,1 --radius 0.06 --target-fraction 0.6"; do
  read -r cont rest <<<"$spec"
  # shellcheck disable=SC2086
  "$VDBPACK" pack "$cont" --method jam $rest -o p.csv --json >p.json 2>err.txt || die "$spec: $(cat err.txt)"
  # shellcheck disable=SC2086
  "$VDBPACK" pack "$cont" --method jam $rest -o p.vdb -q --threads 1 || die "$spec: vdb"
  "$VDBPACK" check p.vdb --container "$cont" -q || die "$spec: check failed"
  $PY - "$cont" <<'PY' || die "$spec: the independent check"
import json, sys
import numpy as np
cont = sys.argv[1]
d = json.load(open("p.json"))
a = np.loadtxt("p.csv", delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
n = len(r)
assert n == d["count"], (n, d["count"])
worst = 0.0
for i in range(n - 1):
    dist = np.linalg.norm(x[i + 1:] - x[i], axis=1)
    s = r[i + 1:] + r[i]
    worst = max(worst, float(((s - dist) / s).max()))
assert worst <= 1e-6, "pair overlap %g" % worst
if cont.startswith("box"):
    wall = (np.abs(x).max(axis=1) + r - 0.5).max()
else:
    wall = (np.linalg.norm(x, axis=1) + r - 1.0).max()
assert wall <= 1e-6, "outside by %g" % wall
frac = (4 / 3 * np.pi * r ** 3).sum() / d["container_volume"]
assert abs(frac - d["packing_fraction"]) < 1e-4, (frac, d["packing_fraction"])
assert 4.5 < d["mean_contacts"] < 6.5 and d["max_overlap"] <= 1e-6, d
print("  ok: %s: %d spheres, fraction %.4f, Z %.3f, rattlers %.3f, worst pair %.2g, wall %.2g"
      % (cont, n, frac, d["mean_contacts"], d["rattler_fraction"], worst, wall))
PY
done

# 2. the same file on 1 and 2 threads, and with the portable pair and
# list kernels (VDBPACK_NO_SIMD=1) as with the AVX2 ones; metadata
# (by VDBPACK_THREADS, in folders: the command line is in the file).
# 3001 spheres: 5 chunks of work (one per 512 spheres), so the threads
# share the chunks and their sums meet; chunks of 601 and 597 spheres, so
# the AVX2 move's groups of four leave one sphere of each to the portable
# code
mkdir -p a b s
jam3k="box:1,1,1 --method jam --count 3001 --radius lognormal:0.01:0.003"
(cd a && VDBPACK_THREADS=1 "$VDBPACK" pack $jam3k -o t.vdb -q)
(cd b && VDBPACK_THREADS=2 "$VDBPACK" pack $jam3k -o t.vdb -q)
(cd s && VDBPACK_THREADS=2 VDBPACK_NO_SIMD=1 "$VDBPACK" pack $jam3k -o t.vdb -q)
cp a/t.vdb t1.vdb
cp b/t.vdb t2.vdb
cmp t1.vdb t2.vdb || die "--threads 1 and 2 give different files"
cmp t2.vdb s/t.vdb || die "the portable and the AVX2 kernels give different files"
info=$("$VDBPACK" info t1.vdb)
for k in "method = jam" mean_contacts rattler_fraction max_overlap radius_scale; do
  case "$info" in *"$k"*) ;; *) die "metadata lacks $k";; esac
done
echo "  ok: the same file on 1 and 2 threads and without SIMD; metadata names the method and its report"

# the quench's list build copies the nine rows of cells around each row
# into plain arrays, unless they hold more than 8 192 spheres: in a long
# thin box every set of rows does, and the spheres' records are scanned
# as before. Either way the portable code's lists, so the same file.
long="box:350,1,1 --method jam --count 10000 --seed 2"
"$VDBPACK" pack $long -o long1.csv -q || die "the long box did not pack"
VDBPACK_NO_SIMD=1 "$VDBPACK" pack $long -o long2.csv -q || die "the long box did not pack (portable)"
cmp long1.csv long2.csv || die "the long box: the AVX2 and the portable code give different files"
echo "  ok: a long thin box (rows too long for the arrays) packs the same file without SIMD"

# 3. --margin and --gap: `check` holds the file to both, and to neither
# doubled; a mesh container's band reaches the margin's depth
for cont in box:1,1,1 "$VP_SRC/vdb_samples/peanut.obj"; do
  "$VDBPACK" pack "$cont" --method jam --count 800 --margin 0.04 --gap 0.003 -o mg.vdb -q \
    || die "margin/gap: pack in $cont"
  "$VDBPACK" check mg.vdb --container "$cont" --margin 0.04 --gap 0.003 -q \
    || die "margin/gap: check in $cont"
  if "$VDBPACK" check mg.vdb --container "$cont" --margin 0.08 -q >/dev/null 2>&1; then
    die "margin/gap: check passes a margin of twice the one packed ($cont)"
  fi
  if "$VDBPACK" check mg.vdb --container "$cont" --gap 0.006 -q >/dev/null 2>&1; then
    die "margin/gap: check passes a gap of twice the one packed ($cont)"
  fi
done
echo "  ok: --margin 0.04 --gap 0.003 held (box, peanut.obj), and twice them fail check"

# 4. the core of a mesh container (a narrow-band level set, whose distance
# is clamped a few voxels in): the depth map vouches for it
"$VDBPACK" pack "$VP_SRC/vdb_samples/peanut.obj" --method jam --count 20000 --voxel-size 0.01 \
  -o core.vdb -q --json >core.json || die "peanut core: pack"
$PY - <<'PY' || die "the core of peanut.obj"
import json
d = json.load(open("core.json"))
assert d["core_count"] >= 100, d["core_count"]
assert 0.58 < d["core_fraction"] < 0.70, d["core_fraction"]
print("  ok: peanut.obj, 20000 spheres: core of %d spheres at %.4f (whole %.4f)"
      % (d["core_count"], d["core_fraction"], d["packing_fraction"]))
PY

# 5. bad input: one line, non-zero exit, no output file
bad() { # DESCRIPTION ARGS...
  local what=$1; shift
  rm -f bad.vdb
  local rc=0
  "$VDBPACK" pack "$@" -o bad.vdb >out.txt 2>err.txt || rc=$?
  [ "$rc" != 0 ] || die "$what: exit 0"
  [ "$(wc -l <err.txt)" = 1 ] || die "$what: $(wc -l <err.txt) lines: $(cat err.txt)"
  [ ! -e bad.vdb ] || die "$what: bad.vdb left"
  echo "  ok: $what: exit $rc: $(cat err.txt)"
}
bad "a fraction above 0.74 of equal spheres" box:1,1,1 --method jam --radius 0.01 --target-fraction 0.75
bad "a count that cannot fit" box:1,1,1 --method jam --count 1000 --radius 0.1
bad "a zero radius" box:1,1,1 --method jam --count 10 --radius 0
bad "a negative radius" box:1,1,1 --method jam --count 10 --radius -1
bad "a container smaller than one sphere" box:1,1,1 --method jam --radius 2
bad "no count and no radius" box:1,1,1 --method jam
bad "--count and --target-fraction" box:1,1,1 --method jam --count 10 --target-fraction 0.6
bad "a solid shape" box:1,1,1 --method jam --count 10 --shape cube
bad "--count max" box:1,1,1 --method jam --count max --radius 0.1
bad "a margin past the inradius" box:1,1,1 --method jam --count 100 --margin 0.5
bad "a gap as large as the radii" box:1,1,1 --method jam --count 100 --gap 0.2
bad "a negative gap" box:1,1,1 --method jam --count 100 --gap -0.01
# (centres pushed past a level set's band, where no wall holds them, were
# squeezed to radii of 1e-18 and written with exit 0)
bad "spheres that escape a level set's band" "$VP_SRC/vdb_samples/sphere_ls.vdb" --method jam \
  --count 400 --fit center --seed 4
echo "sh_jam: all passed"
