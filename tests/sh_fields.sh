#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Fields and masks through the command line (issue 31, section 4; docs/fields.md):
# a radius field that halves the radius across a box gives radii whose
# fitted line matches the field's within 1 % (scale and absolute modes),
# with no overlap (an independent numpy check of every pair) and `vdbpack
# check` passing; a density field's counts in two halves follow its ratio;
# a mask sphere (a .vdb level set, and analytic) is empty after rsa and
# lattice packing (the distance from the sphere's centre, measured here)
# while particles surround it; and bad fields (missing, corrupt, not float,
# NaN, radii <= 0, not covering the container, ...) are refused with one
# line, a non-zero exit and no output file. The fields are written by
# OpenVDB's Python module (tests/make_fields.py).
set -euo pipefail
: "${VDBPACK:?}" "${VP_SRC:?}"
PY=/usr/bin/python3
$PY -c "import pyopenvdb, numpy" 2>/dev/null || { echo "SKIP: python3-openvdb or numpy missing"; exit 77; }
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }
$PY "$VP_SRC/tests/make_fields.py" . || die "make_fields.py"

# 1. radius field: x 1 at x = -0.5 down to x 0.5 at x = 0.5
fit_radii() { # CSV, expected intercept at x = -0.5, expected value at x = 0.5
  $PY - "$@" <<'PY'
import os
import sys
import numpy as np
a = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
want_lo, want_hi = float(sys.argv[2]), float(sys.argv[3])
tol = float(os.environ.get("FIT_TOL", "0.01"))
n = len(r)
assert n > 500, n
slope, icpt = np.polyfit(x[:, 0], r, 1)
lo, hi = icpt - 0.5 * slope, icpt + 0.5 * slope
for got, want in ((lo, want_lo), (hi, want_hi)):
    assert abs(got - want) <= tol * want, ("fitted radius", got, "expected", want)
# no pair overlaps (every pair, independently of vdbpack)
worst = 0.0
for i in range(n - 1):
    d = np.linalg.norm(x[i + 1:] - x[i], axis=1)
    s = r[i + 1:] + r[i]
    worst = max(worst, float(((s - d) / s).max()))
assert worst <= 1e-6, ("overlap", worst)
wall = float((np.abs(x).max(axis=1) + r - 0.5).max())
assert wall <= 1e-6, ("outside", wall)
print("n=%d radius at x=-0.5 %.6f (want %.6f), at x=0.5 %.6f (want %.6f), worst overlap %.2g"
      % (n, lo, want_lo, hi, want_hi, worst))
PY
}
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 1500 --radius-field halve.vdb \
  -o h.csv -q || die "radius field (scale)"
fit_radii h.csv 0.03 0.015 || die "radius field (scale): radii do not follow the field"
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 1500 --radius-field halve.vdb \
  -o h.vdb -q || die "radius field (scale), .vdb"
"$VDBPACK" check h.vdb --container box:1,1,1 -q || die "check of the radius-field packing"
"$VDBPACK" pack box:1,1,1 --method rsa --count 1500 --radius-field halve_abs.vdb:radius \
  --radius-field-mode absolute -o a.csv -q || die "radius field (absolute)"
fit_radii a.csv 0.03 0.015 || die "radius field (absolute): radii do not follow the field"
# with --margin and --gap: measured here, and by check (from the metadata)
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 800 --radius-field halve.vdb \
  --margin 0.05 --gap 0.01 -o mg.csv -q || die "radius field with margin and gap"
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 800 --radius-field halve.vdb \
  --margin 0.05 --gap 0.01 -o mg.vdb -q
"$VDBPACK" check mg.vdb --container box:1,1,1 -q || die "check: radius field with margin and gap"
$PY - <<'PY' || die "radius field: margin or gap not kept"
import numpy as np
a = np.loadtxt("mg.csv", delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
wall = (0.5 - (np.abs(x).max(axis=1) + r)).min()
gap = min((np.linalg.norm(x[i + 1:] - x[i], axis=1) - r[i + 1:] - r[i]).min()
          for i in range(len(r) - 1))
print("margin 0.05: nearest wall %.6f; gap 0.01: nearest pair %.6f" % (wall, gap))
assert len(r) == 800 and wall >= 0.05 - 1e-7 and gap >= 0.01 - 1e-7
PY
# a named grid of two
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 1500 --radius-field two.vdb:second \
  -o t.csv -q || die "radius field, named grid"
fit_radii t.csv 0.03 0.015 || die "the named grid was not the one used"
# the same seed, the same file; any thread count
mkdir -p t1 && cp halve.vdb t1/ && (cd t1 && "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 \
  --count 1500 --radius-field halve.vdb -o h.vdb -q --threads 1)
cmp h.vdb t1/h.vdb || die "radius field: not deterministic across thread counts"
"$VDBPACK" info h.vdb | grep -q "radius_field_mode.*scale" || die "metadata: radius_field_mode"

# relax: radii from the field at the starting centres (then shrunk one by
# one where they still overlap): the line within 2 %
"$VDBPACK" pack box:1,1,1 --method relax --radius 0.04 --count 800 --radius-field halve.vdb \
  -o r.csv -q || die "relax radius field (scale)"
FIT_TOL=0.02 fit_radii r.csv 0.04 0.02 || die "relax radius field (scale)"
"$VDBPACK" pack box:1,1,1 --method relax --count 800 --radius-field halve_abs.vdb \
  --radius-field-mode absolute -o r.vdb -q || die "relax radius field (absolute)"
"$VDBPACK" check r.vdb --container box:1,1,1 -q || die "check of the relax radius-field packing"
"$VDBPACK" convert r.vdb r.csv -q
FIT_TOL=0.02 fit_radii r.csv 0.03 0.015 || die "relax radius field (absolute)"
# jam: radii from the field at the starting centres, then scaled together:
# their ratios stay the field's (its values over the box span 0.5 .. 1);
# the spheres move while they jam, so the line only leans the field's way
"$VDBPACK" pack box:1,1,1 --method jam --count 800 --radius-field halve.vdb -o j.vdb -q \
  || die "jam radius field"
"$VDBPACK" check j.vdb --container box:1,1,1 -q || die "check of the jam radius-field packing"
"$VDBPACK" pack box:1,1,1 --method jam --count 200 --radius-field halve.vdb -o j2.csv --json \
  | grep -q '"radius_field":"halve.vdb","radius_field_mode":"scale"' || die "jam --json: the field"
"$VDBPACK" convert j.vdb j.csv -q
$PY - <<'PY' || die "jam radius field: the radii do not keep the field's ratios"
import numpy as np
a = np.loadtxt("j.csv", delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
ratio = r.max() / r.min()
slope, icpt = np.polyfit(x[:, 0], r, 1)
ends = (icpt + 0.5 * slope) / (icpt - 0.5 * slope)
print("jam: %d spheres, largest / smallest radius %.4f (field: at most 2), fitted r(0.5) / "
      "r(-0.5) %.3f (field 0.5)" % (len(r), ratio, ends))
assert 1.7 < ratio <= 2.0 * (1 + 1e-6), ratio
assert 0.4 < ends < 0.75, ends
PY

# 2. density field 1 .. 3 along x: 3/8 of the particles left of x = 0
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.004 --count 4000 --density-field density.vdb \
  -o d.csv -q || die "density field"
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.004 --count 4000 -o u.csv -q
$PY - <<'PY' || die "density field: the halves do not follow the field"
import numpy as np
for name, p_left in (("d.csv", 0.75 / 2.0), ("u.csv", 0.5)):
    x = np.loadtxt(name, delimiter=",", skiprows=1, usecols=(1,))
    n, left = len(x), int((x < 0).sum())
    sd = (n * p_left * (1 - p_left)) ** 0.5
    print("%s: %d of %d left of x = 0, expected %.0f +- %.0f" % (name, left, n, n * p_left, sd))
    assert n == 4000 and abs(left - n * p_left) < 4 * sd, (name, left)
PY

# 3. a mask sphere of radius 0.25 at the centre: empty, and surrounded
mask_check() { # CSV, tolerance on the sphere's radius, fit (inside|center)
  $PY - "$@" <<'PY'
import os
import sys
import numpy as np
a = np.loadtxt(sys.argv[1], delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
tol, fit = float(sys.argv[2]), sys.argv[3]
d = np.linalg.norm(x, axis=1) - (r if fit == "inside" else 0.0)
assert len(r) > 100, len(r)
assert d.min() >= 0.25 - tol, ("a particle inside the mask", d.min())
near = int((d < 0.25 + 0.1).sum())
assert near > 20, ("nothing around the mask", near)
print("%s: %d particles, nearest to the mask's centre %.5f (sphere 0.25), %d within 0.1 of it"
      % (sys.argv[1], len(r), d.min(), near))
PY
}
for mask in ball.vdb ball.vdb:ball sphere:0.25; do
  tol=0.002; [ "$mask" = sphere:0.25 ] && tol=1e-9
  "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.02 --count max --mask "$mask" -o m.csv -q \
    || die "rsa --mask $mask"
  mask_check m.csv "$tol" inside || die "rsa --mask $mask"
  "$VDBPACK" pack box:1,1,1 --radius 0.03 --mask "$mask" -o l.csv -q || die "lattice --mask $mask"
  mask_check l.csv "$tol" inside || die "lattice --mask $mask"
  "$VDBPACK" pack box:1,1,1 --radius 0.03 --mask "$mask" --fit center -o c.csv -q \
    || die "lattice --fit center --mask $mask"
  mask_check c.csv "$tol" center || die "lattice --fit center --mask $mask"
done
# relax and jam honour it too (an analytic mask: exact)
"$VDBPACK" pack box:1,1,1 --method relax --radius 0.03 --count 800 --mask sphere:0.25 -o x.csv -q \
  || die "relax --mask"
mask_check x.csv 1e-9 inside || die "relax --mask"
"$VDBPACK" pack box:1,1,1 --method jam --count 800 --mask sphere:0.25 -o x.csv -q || die "jam --mask"
mask_check x.csv 1e-9 inside || die "jam --mask"
# a mesh mask (a cube of side 0.4, OBJ text): its level set's zero
# crossing, within a few thousandths at its edges
printf 'v %s\n' "-0.2 -0.2 -0.2" "0.2 -0.2 -0.2" "0.2 0.2 -0.2" "-0.2 0.2 -0.2" \
  "-0.2 -0.2 0.2" "0.2 -0.2 0.2" "0.2 0.2 0.2" "-0.2 0.2 0.2" >cube.obj
printf 'f %s\n' "1 4 3 2" "5 6 7 8" "1 2 6 5" "3 4 8 7" "2 3 7 6" "1 5 8 4" >>cube.obj
for m in "rsa --radius 0.02 --count max" "lattice --radius 0.03"; do
  # shellcheck disable=SC2086
  "$VDBPACK" pack box:1,1,1 --method $m --mask cube.obj -o x.csv -q || die "$m --mask cube.obj"
  $PY - <<'PY' || die "$m --mask cube.obj: a particle in the cube"
import numpy as np
a = np.loadtxt("x.csv", delimiter=",", skiprows=1, usecols=(1, 2, 3, 4))
x, r = a[:, :3], a[:, 3]
d = np.linalg.norm(np.maximum(np.abs(x) - 0.2, 0.0), axis=1) - r  # exact distance to the cube
print("cube mask: %d particles, least clearance %.5f, %d within 0.1" % (len(r), d.min(),
                                                                      (d < 0.1).sum()))
assert d.min() >= -0.002 and (d < 0.1).sum() > 20
PY
done
# vdbpack check applies the mask the file records (mesh: at its voxel)
for mask in cube.obj ball.vdb sphere:0.25; do
  "$VDBPACK" pack box:1,1,1 --method rsa --radius 0.02 --count max --mask "$mask" -o mk.vdb -q
  "$VDBPACK" check mk.vdb --container box:1,1,1 -q || die "check of a packing with --mask $mask"
  "$VDBPACK" check mk.vdb --container box:1,1,1 --json | grep -q "\"mask\":\"$mask\"" \
    || die "check --json does not name the mask $mask"
done
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.02 --count max -o nm.vdb -q
set +e
"$VDBPACK" check nm.vdb --container box:1,1,1 --mask sphere:0.25 -q 2>/dev/null; st=$?
set -e
[ "$st" -eq 3 ] || die "check --mask passed a packing that fills the mask (status $st)"
"$VDBPACK" check mk.vdb --container box:1,1,1 --mask none -q || die "check --mask none"
# the packing fraction counts the container less the mask
"$VDBPACK" pack box:1,1,1 --radius 0.03 --mask sphere:0.25 -o l.vdb --json >l.json
$PY - <<'PY' || die "the masked container's volume"
import json, math
v = json.load(open("l.json"))["container_volume"]
want = 1 - 4 / 3 * math.pi * 0.25 ** 3
assert abs(v - want) < 0.01 * want, (v, want)
PY
"$VDBPACK" info l.vdb | grep -q "mask.*sphere:0.25" || die "metadata: mask"

# 4. bad input: one line on stderr, exit status 1 or 2, no output file
refuse() { # expected text, then the pack arguments
  local want=$1; shift
  rm -f out.vdb
  if "$VDBPACK" pack box:1,1,1 -o out.vdb "$@" 2>err.txt >/dev/null; then
    die "accepted: $*"
  fi
  [ "$(wc -l <err.txt)" -eq 1 ] || die "not one line: $* -> $(cat err.txt)"
  grep -q -- "$want" err.txt || die "$*: expected '$want', got: $(cat err.txt)"
  [ ! -e out.vdb ] || die "$*: an output file was left"
  echo "refused: $* -> $(cat err.txt)"
}
RSA=(--method rsa --radius 0.03 --count 100)
refuse "cannot open file" "${RSA[@]}" --radius-field missing.vdb
refuse "not a readable .vdb" "${RSA[@]}" --radius-field corrupt.vdb
refuse "no float grid" "${RSA[@]}" --radius-field vec3.vdb
refuse "holds vec3s values, not float" "${RSA[@]}" --radius-field vec3.vdb:velocity
refuse "no grid named 'nope'" "${RSA[@]}" --radius-field halve.vdb:nope
refuse "NaN value" "${RSA[@]}" --radius-field nan.vdb
refuse "radii must be positive" "${RSA[@]}" --radius-field negative.vdb
refuse "radii must be positive" "${RSA[@]}" --radius-field zero.vdb
refuse "smaller than the smallest radius the field gives" "${RSA[@]}" --radius-field halve.vdb \
  --gap 0.02
refuse "does not cover the container" "${RSA[@]}" --radius-field small.vdb
refuse "does not cover the container" "${RSA[@]}" --density-field small.vdb
refuse "must not be negative" "${RSA[@]}" --density-field neg_density.vdb
refuse "goes with --radius-field" "${RSA[@]}" --radius-field-mode absolute
refuse "unknown --radius-field-mode" "${RSA[@]}" --radius-field halve.vdb --radius-field-mode x
refuse "leave out --radius" "${RSA[@]}" --radius-field halve_abs.vdb --radius-field-mode absolute
refuse "goes with --method rsa, relax and jam" --radius 0.05 --radius-field halve.vdb
refuse "goes with --method rsa, not jam" --method jam --count 100 --density-field density.vdb
refuse "leave out --radius" --method relax --radius 0.03 --count 100 --radius-field halve_abs.vdb \
  --radius-field-mode absolute
refuse "does not cover the container" --method jam --count 100 --radius-field small.vdb
refuse "radii must be positive" --method relax --radius 0.03 --count 100 --radius-field zero.vdb
refuse "pack spheres" "${RSA[@]}" --shape cube --radius-field halve.vdb
refuse "cannot open file" "${RSA[@]}" --mask missing.obj
refuse "covers the whole container" "${RSA[@]}" --mask box:2,2,2
refuse "holds distances only" --method jam --count 800 --mask ball.vdb
# an output that is a field or mask file would replace it (exit 2, the file kept)
cp halve.vdb keep.vdb
set +e
"$VDBPACK" pack box:1,1,1 --method rsa --radius 0.03 --count 10 --radius-field keep.vdb \
  -o ./keep.vdb 2>err.txt; st=$?
set -e
[ "$st" -eq 2 ] && grep -q "is the --radius-field itself" err.txt && cmp -s keep.vdb halve.vdb \
  || die "an output naming the radius field: status $st, $(cat err.txt)"
# a points grid (a packing) is not a field
"$VDBPACK" pack box:1,1,1 --radius 0.1 -o pts.vdb -q
refuse "holds points values, not float" "${RSA[@]}" --radius-field pts.vdb:points
echo "PASS"
