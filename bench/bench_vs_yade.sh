#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# vdbpack's random packers against Yade (Debian package `yade`), the one peer
# issue 3 names that Debian ships, timed in the same run on the same problem:
#  1. RSA, one radius, unit box: N = 1e6 x SCALE spheres asked for, radius
#     0.0043 / cbrt(SCALE) (fraction 0.333 if all are placed). Yade:
#     SpherePack.makeCloud (its own limit: 1000 tries per sphere); vdbpack:
#     `pack box:1,1,1 --method rsa --pass count=N,radius=R` (default retries).
#  2. Dense packing in a sphere container of radius 20 r. Yade:
#     pack.randomDensePack(inSphere, radius=r, spheresInCell=2000) (a periodic
#     compression of 2000 spheres of radius r, tiled, then the spheres wholly
#     inside the predicate); vdbpack: `--method relax --count 4960
#     --target-fraction 0.62` in sphere:20 at radius 1. With --triaxial also
#     Yade's default, non-periodic route (spheresInCell=0: a triaxial test whose
#     internal compaction grows the radii, so its r is not the r asked).
#  3. Dense packing of N spheres in the unit box (issue 3's
#     relax case at SCALE 0.1): vdbpack `--method relax --count N
#     --target-fraction 0.62`; Yade: randomDensePack(inAlignedBox, radius =
#     the radius relax starts from, spheresInCell=2000), as in case 2.
# Yade's figures are what it returns: its spheres are read back from the
# SpherePack (count, radii, the farthest reach from the container's centre
# or outside the box), and its time is its call alone, without Yade's start.
# vdbpack's time is the whole CLI run, writing the .vdb included.
# Each vdbpack output is checked by `vdbpack check` (overlaps, outside).
# Usage: bash bench/bench_vs_yade.sh [SCALE] [--no-dense] [--triaxial]
#   SCALE defaults to 0.1: Yade's makeCloud time grows about as N^2 here
#   (1e4 in 0.54 s, 1e5 in 47 s), so SCALE 1 would take it hours.
#   Cases 2 and 3 take about a minute (4 more with --triaxial); --no-dense
#   skips them.
# If yade is missing and this runs as root, it is installed with apt-get.
# No pass/fail: figures and ratios are printed for the notes.
set -euo pipefail
cd "$(dirname "$0")/.."
VDBPACK=${VDBPACK:-build/vdbpack}
SCALE=0.1
DENSE=1
TRIAXIAL=0
for a in "$@"; do
  case "$a" in
    --no-dense) DENSE=0 ;;
    --triaxial) TRIAXIAL=1 ;;
    *) SCALE=$a ;;
  esac
done
if ! [[ "$SCALE" =~ ^[0-9]*\.?[0-9]+([eE][-+]?[0-9]+)?$ ]] || ! python3 -c "assert float('$SCALE') > 0" 2>/dev/null; then
  echo "bench_vs_yade: SCALE must be a positive number, not '$SCALE'" >&2; exit 2
fi
[ -x "$VDBPACK" ] || { echo "bench_vs_yade: $VDBPACK not built (bash scripts/setup.sh)" >&2; exit 1; }
if ! command -v yade >/dev/null; then
  if [ "$(id -u)" = 0 ]; then
    echo "bench_vs_yade: installing yade (apt-get, about 130 MB)"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -q yade >/dev/null
  else
    echo "bench_vs_yade: yade not found (apt-get install yade)" >&2; exit 1
  fi
fi
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT

read -r N R < <(python3 -c "
s = float('$SCALE')
print(int(round(1e6 * s)), repr(0.0043 / s ** (1 / 3)))")

# Yade's side: one script, the case in argv; prints one JSON line.
cat > "$tmp/yade_case.py" <<'EOF'
import json, math, sys, time
from yade import pack
case = sys.argv[1]
if case == "cloud":
    n, r = int(sys.argv[2]), float(sys.argv[3])
    sp = pack.SpherePack()
    t = time.time()
    sp.makeCloud((0, 0, 0), (1, 1, 1), rMean=r, rRelFuzz=0, num=n, seed=1)
    dt = time.time() - t
    vol, out = 1.0, 0.0
    for c, rr in sp:
        for k in range(3):
            out = max(out, rr - c[k], c[k] + rr - 1.0)
elif case == "box":
    r = float(sys.argv[2])
    t = time.time()
    sp = pack.randomDensePack(pack.inAlignedBox((-0.5, -0.5, -0.5), (0.5, 0.5, 0.5)), radius=r,
                              rRelFuzz=0, spheresInCell=2000, returnSpherePack=True, seed=1)
    dt = time.time() - t
    vol, out = 1.0, 0.0
    for c, rr in sp:
        for k in range(3):
            out = max(out, abs(c[k]) + rr - 0.5)
else:
    R, r = 20.0, 1.0
    t = time.time()
    sp = pack.randomDensePack(pack.inSphere((0, 0, 0), R), radius=r, rRelFuzz=0,
                              spheresInCell=2000 if case == "dense" else 0,
                              returnSpherePack=True, seed=1)
    dt = time.time() - t
    vol = 4.0 / 3.0 * math.pi * R ** 3
    out = max(0.0, max(c.norm() + rr - R for c, rr in sp))
radii = [rr for c, rr in sp]
# overlapping pairs, by the rule `vdbpack check` uses (deeper than 1e-6 of r_i + r_j)
import numpy as np
from scipy.spatial import cKDTree
P = np.array([[c[0], c[1], c[2]] for c, rr in sp]); Rr = np.array(radii)
pairs = cKDTree(P).query_pairs(2.0 * Rr.max(), output_type="ndarray")
d = np.linalg.norm(P[pairs[:, 0]] - P[pairs[:, 1]], axis=1)
s = Rr[pairs[:, 0]] + Rr[pairs[:, 1]]
overl = int(np.count_nonzero(s - d > 1e-6 * s))
worst = float(max(0.0, ((s - d) / s).max())) if len(d) else 0.0
solid = sum(4.0 / 3.0 * math.pi * rr ** 3 for rr in radii)
print("RESULT " + json.dumps({"count": len(radii), "fraction": solid / vol, "seconds": dt,
                              "mean_radius": sum(radii) / len(radii), "outside_by": out,
                              "overlapping_pairs": overl, "max_overlap": worst}))
EOF

yade_run() { # case args... -> JSON on stdout
  yade -n -x "$tmp/yade_case.py" "$@" > "$tmp/yade.log" 2>&1 || { echo "yade failed:" >&2; tail -5 "$tmp/yade.log" >&2; exit 1; }
  grep '^RESULT ' "$tmp/yade.log" | sed 's/^RESULT //'
}
vdbpack_run() { # container, args... -> JSON (pack's, with wall seconds and check's verdict)
  local cont=$1; shift
  local t0 t1
  t0=$(date +%s.%N)
  "$VDBPACK" pack "$cont" "$@" --seed 1 -o "$tmp/v.vdb" --json > "$tmp/v.json"
  t1=$(date +%s.%N)
  "$VDBPACK" check "$tmp/v.vdb" --container "$cont" --json > "$tmp/c.json" || {
    echo "vdbpack check failed:" >&2; cat "$tmp/c.json" >&2; exit 1; }
  python3 -c "
import json
p = json.load(open('$tmp/v.json')); c = json.load(open('$tmp/c.json'))
p['wall'] = $t1 - $t0; p['check'] = c
print(json.dumps(p))"
}
report() { # label, vdbpack JSON, yade JSON
  python3 - "$1" "$2" "$3" <<'EOF'
import json, sys
label, v, y = sys.argv[1], json.loads(sys.argv[2]), json.loads(sys.argv[3])
c = v["check"]
print("%s" % label)
print("  %-8s %9s %9s %9s %12s  %s" % ("", "placed", "fraction", "seconds", "placed/s", "notes"))
print("  %-8s %9d %9.4f %9.2f %12.0f  overlapping pairs %d (largest %.2g of r_i + r_j), outside %d (vdbpack check)" % (
    "vdbpack", v["count"], v["packing_fraction"], v["wall"], v["count"] / v["wall"],
    c["overlapping_pairs"], c["max_overlap"], c["outside"]))
print("  %-8s %9d %9.4f %9.2f %12.0f  overlapping pairs %d (largest %.2g of r_i + r_j), mean radius %.6g, farthest outside %.3g" % (
    "yade", y["count"], y["fraction"], y["seconds"], y["count"] / y["seconds"],
    y["overlapping_pairs"], y["max_overlap"], y["mean_radius"], y["outside_by"]))
print("  fraction: vdbpack - yade = %+.4f; time: vdbpack / yade = %.3f" % (
    v["packing_fraction"] - y["fraction"], v["wall"] / y["seconds"]))
EOF
}

echo "bench_vs_yade: SCALE $SCALE (N = $N, r = $R), $(yade --version 2>/dev/null | head -1)"
v=$(vdbpack_run box:1,1,1 --method rsa --pass "count=$N,radius=$R")
y=$(yade_run cloud "$N" "$R")
report "1. RSA, one radius, unit box: $N asked at r = $R" "$v" "$y"
if [ "$DENSE" = 1 ]; then
  v=$(vdbpack_run sphere:20 --method relax --radius 1 --count 4960 --target-fraction 0.62)
  y=$(yade_run dense)
  report "2. dense, sphere container of radius 20 (r = 1 asked; vdbpack's relax shrinks radii a little)" "$v" "$y"
  if [ "$TRIAXIAL" = 1 ]; then
    y=$(yade_run triaxial)
    report "2b. the same, Yade's non-periodic route (its compaction grows the radii)" "$v" "$y"
  fi
  read -r NB RB < <(python3 -c "
import math
n = int(round(1e6 * float('$SCALE')))
print(n, repr((0.62 / (n * 4.0 / 3.0 * math.pi)) ** (1 / 3)))")
  v=$(vdbpack_run box:1,1,1 --method relax --radius 1 --count "$NB" --target-fraction 0.62)
  y=$(yade_run box "$RB")
  report "3. dense, unit box: vdbpack relax $NB at target 0.62 (r = $RB before relaxing)" "$v" "$y"
fi
