#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Superballs through the command line: a lattice packing (C1 at P = 2) read
# back with OpenVDB's own API (tests/dump_points) and checked pair by pair
# here in numpy by the gauge of the centres' differences (a lattice packs
# a centrally symmetric K iff no difference lies inside 2K); an RSA packing
# passes `vdbpack check`; the shape survives in the file's metadata
# (vdb_print), in render, --shape-out and OBJ export; bad exponents give
# one line, exit 2 and no file.
set -euo pipefail
: "${VDBPACK:?}" "${VP_DUMP_POINTS:?}"
PY=/usr/bin/python3
W=$(mktemp -d); trap 'rm -rf "$W"' EXIT; cd "$W"
die() { echo "FAIL: $*"; exit 1; }

echo "=== lattice, P = 2: the file as OpenVDB reads it, pairs by the gauge"
"$VDBPACK" pack box:1,1,1 -o l.vdb -q --shape superball:2 --radius 0.1 --json >l.json
"$VP_DUMP_POINTS" l.vdb >l.txt
"$PY" - <<'PY'
import json, numpy as np
d = np.loadtxt("l.txt", usecols=(1, 2, 3, 4, 5, 6, 7, 8))
P, r, q = d[:, :3], d[:, 3], d[:, 4:8]
p = 2.0
R = 3 ** (0.5 - 0.5 / p)                 # bounding radius of the unit p-ball
assert np.allclose(q, [0, 0, 0, 1]), "a lattice of one orientation"
diff = (P[:, None, :] - P[None, :, :]) / (2 * r[0] / R)
g = (np.abs(diff) ** (2 * p)).sum(-1) ** (1 / (2 * p))
np.fill_diagonal(g, np.inf)
least = g.min()
contacts = (np.abs(g - 1) < 1e-3).sum(1)
assert least > 1 - 1e-4, least           # 16-bit positions: 1e-4 of the radius
vol = r[0] ** 3 * len(r) * 2 / p**2       # closed form, eq. 5 of Jiao et al.
from math import gamma
B = lambda a, b: gamma(a) * gamma(b) / gamma(a + b)
vsb = 2 / p**2 * B(1 / (2 * p), (2 * p + 1) / (2 * p)) * B(1 / (2 * p), (p + 1) / p) / R**3
frac = vsb * (r ** 3).sum()
j = json.load(open("l.json"))
assert abs(j["packing_fraction"] - frac) < 1e-6, (j["packing_fraction"], frac)
assert abs(j["lattice_fraction"] - 0.869889) < 1e-6, j["lattice_fraction"]
assert contacts.max() == 12, contacts.max()
print("  ok: %d superballs, least gauge %.6f, at most %d contacts, fraction %.4f (lattice %.6f)"
      % (len(r), least, contacts.max(), frac, j["lattice_fraction"]))
PY
vdb_print -m l.vdb >l.meta 2>&1; grep -q "shape: superball:2" l.meta || die "no shape metadata"
"$VDBPACK" check l.vdb --container box:1,1,1 -q || die "check of the lattice"

echo "=== rsa, P = 0.7, grown: check, render, shape-out, OBJ"
"$VDBPACK" pack box:1,1,1 -o r.vdb -q --method rsa --shape superball:0.7 \
  --pass count=300,radius=0.07,grow --shape-out sb.obj
"$VDBPACK" check r.vdb --container box:1,1,1 --json >r.json || die "check: $(cat r.json)"
"$PY" -c "
import json; j = json.load(open('r.json'))
assert j['overlapping_pairs'] == 0 and j['outside'] == 0 and j['shape'] == 'superball', j
assert j['mean_contacts'] > 0.5, j
print('  ok: %d superballs, fraction %.4f, mean contacts %.2f' % (j['count'], j['packing_fraction'], j['mean_contacts']))"
"$VDBPACK" render r.vdb -o r.png --size 160x90 -q || die "render"
[ -s r.png ] || die "no image"
head -1 sb.obj | grep -q "superball:0.7" || die "shape-out: $(head -1 sb.obj)"
"$PY" -c "
import numpy as np
v = np.array([l.split()[1:] for l in open('sb.obj') if l.startswith('v ')], float)
g = ((np.abs(v) ** 1.4).sum(1)) ** (1 / 1.4)   # bounding radius 1 at P <= 1
assert abs(g.max() - 1) < 1e-9 and abs(g.min() - 1) < 1e-9, (g.min(), g.max())
print('  ok: shape-out has %d vertices on the surface' % len(v))"
"$VDBPACK" convert r.vdb r.ply -q && "$VDBPACK" convert r.ply r2.vdb -q
vdb_print -m r2.vdb >r2.meta 2>&1; grep -q "shape: superball:0.7" r2.meta || die "PLY round trip lost the shape"

echo "=== bad input: one line, exit 2, no output"
for s in superball:0.3 superball:nan superball:-1 superball: superball:2x truncated_cubee; do
  set +e; "$VDBPACK" pack box:1,1,1 -o bad.vdb --shape "$s" --radius 0.1 2>err; rc=$?; set -e
  [ "$rc" = 2 ] || die "$s: exit $rc"
  [ "$(wc -l <err)" = 1 ] || die "$s: $(cat err)"
  [ ! -e bad.vdb ] || die "$s: wrote a file"
  echo "  ok: $s: $(cat err)"
done
echo "all superball CLI tests passed"
