#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""The structure of a sphere packing in a box, from vdbpack's CSV alone.

    /usr/bin/python3 scripts/packing_structure.py PACKING.csv --box SX,SY,SZ [--json]

The box is vdbpack's `box:SX,SY,SZ` (centred on the origin). Printed:

- the whole box's fraction (sphere volumes over the box's: spheres are
  inside it), and the core's: spheres whose centres lie farther than
  5 mean diameters from every wall, over that region's volume (the
  packer's report counts the core the same way);
- the fraction against the distance from a wall (exact slab volumes of
  the spheres, 0.1 mean diameters a slab, over the faces' middle parts)
  and the walls' deficit: the integral of (core - profile) over the first
  diameters, in mean diameters (the volume the walls cost per unit of
  wall area, over a diameter);
- local bond order (Steinhardt et al. 1983): q6 of each sphere over its
  neighbours within 1.2 (r_i + r_j), and the share of "solid-like"
  spheres, which have at least 8 neighbours whose normalised q6 vectors
  agree (q6(i).q6(j) > 0.7; ten Wolde, Ruiz-Montero & Frenkel 1996),
  over all spheres, those within 5 diameters of a wall and the core.
  Random close packings read a few per cent or less in the bulk; a
  lattice reads (nearly) all.

numpy only (Debian's python3-numpy). docs/jam.md quotes it.
"""
import argparse
import json
import math
import sys

import numpy as np

CORE_DIAMETERS = 5.0
SLAB = 0.1  # of the mean diameter
PROFILE_DIAMETERS = 6.0


def load(path):
    with open(path) as f:
        head = f.readline().strip().split(",")
    cols = {name: k for k, name in enumerate(head)}
    for need in ("x", "y", "z", "pscale"):
        if need not in cols:
            raise SystemExit("packing_structure: %s has no column '%s' (a vdbpack CSV?)" % (path, need))
    a = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2,
                   usecols=(cols["x"], cols["y"], cols["z"], cols["pscale"]))
    if len(a) < 2:
        raise SystemExit("packing_structure: %s holds fewer than 2 spheres" % path)
    return a[:, :3], a[:, 3]


def pairs_within(P, R, factor):
    """Index pairs i < j with |x_i - x_j| < factor (r_i + r_j), by a cell grid."""
    cut = factor * 2.0 * R.max()
    key = np.floor((P - P.min(0)) / cut).astype(np.int64)
    dims = key.max(0) + 1
    cid = (key[:, 2] * dims[1] + key[:, 1]) * dims[0] + key[:, 0]
    order = np.argsort(cid, kind="stable")
    cs = cid[order]
    n = len(P)
    I, J = [], []
    for dz in (-1, 0, 1):
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                k2 = key + np.array([dx, dy, dz])
                ok = np.all((k2 >= 0) & (k2 < dims), 1)
                c2 = (k2[:, 2] * dims[1] + k2[:, 1]) * dims[0] + k2[:, 0]
                lo = np.searchsorted(cs, c2, "left")
                hi = np.searchsorted(cs, c2, "right")
                cnt = np.where(ok, hi - lo, 0)
                ii = np.repeat(np.arange(n), cnt)
                st = np.repeat(lo, cnt) + (np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt))
                jj = order[st]
                m = ii < jj
                I.append(ii[m])
                J.append(jj[m])
    I = np.concatenate(I)
    J = np.concatenate(J)
    v = P[J] - P[I]
    r = np.linalg.norm(v, axis=1)
    m = r < factor * (R[I] + R[J])
    return I[m], J[m], v[m], r[m]


def legendre6(m, x):
    """The associated Legendre function P_6^m(x) by the standard recurrence."""
    pmm = np.ones_like(x)
    somx2 = np.sqrt(np.maximum(0.0, 1.0 - x * x))
    fact = 1.0
    for _ in range(m):
        pmm = -pmm * fact * somx2
        fact += 2.0
    if m == 6:
        return pmm
    pmmp1 = x * (2 * m + 1) * pmm
    for ll in range(m + 2, 7):
        pll = (x * (2 * ll - 1) * pmmp1 - (ll + m - 1) * pmm) / (ll - m)
        pmm, pmmp1 = pmmp1, pll
    return pmmp1


def bond_order(P, R):
    """Per sphere: q6, its neighbour count and its count of agreeing neighbours."""
    n = len(P)
    I, J, v, r = pairs_within(P, R, 1.2)
    ct = np.clip(v[:, 2] / np.maximum(r, 1e-300), -1.0, 1.0)
    ph = np.arctan2(v[:, 1], v[:, 0])
    nb = np.bincount(I, minlength=n) + np.bincount(J, minlength=n)
    q = np.zeros((n, 13), complex)
    for m in range(7):
        norm = math.sqrt(13.0 / (4.0 * math.pi) * math.factorial(6 - m) / math.factorial(6 + m))
        y = norm * legendre6(m, ct) * np.exp(1j * m * ph)
        # Y_6m(-v) = Y_6m(v) (l even): both ends of a bond add the same
        for k, (idx, yy) in enumerate(((6 + m, y), (6 - m, (-1) ** m * np.conj(y)))):
            if m == 0 and k == 1:
                continue  # Y_60 once
            add = np.bincount(I, yy.real, n) + np.bincount(J, yy.real, n)
            addi = np.bincount(I, yy.imag, n) + np.bincount(J, yy.imag, n)
            q[:, idx] += add + 1j * addi
    qn = q / np.maximum(nb, 1)[:, None]
    q6 = np.sqrt(4.0 * math.pi / 13.0 * (np.abs(qn) ** 2).sum(1))
    u = qn / np.maximum(np.linalg.norm(qn, axis=1), 1e-300)[:, None]
    agree = (u[I] * np.conj(u[J])).sum(1).real > 0.7
    na = np.bincount(I, agree, n) + np.bincount(J, agree, n)
    return q6, nb, na


def wall_profile(P, R, half, d):
    """Fraction against the distance from a wall, over the faces' middles."""
    depth = min(PROFILE_DIAMETERS * d, half.min())
    nslab = max(1, int(round(depth / (SLAB * d))))
    dt = depth / nslab
    vol = np.zeros(nslab)
    area = 0.0
    for ax in range(3):
        o = [k for k in range(3) if k != ax]
        lat = [min(depth, 0.5 * half[k]) for k in o]  # the edges' margin
        m = np.all(np.abs(P[:, o]) < np.array([half[k] - l for k, l in zip(o, lat)]), 1)
        face = 4.0 * (half[o[0]] - lat[0]) * (half[o[1]] - lat[1])
        for t in (P[m, ax] + half[ax], half[ax] - P[m, ax]):
            r = R[m]
            for b in range(nslab):
                u0 = np.clip(b * dt - t, -r, r)
                u1 = np.clip((b + 1) * dt - t, -r, r)
                vol[b] += (math.pi * ((r * r * u1 - u1 ** 3 / 3) - (r * r * u0 - u0 ** 3 / 3))).sum()
            area += face
    return vol / (area * dt), dt


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("csv")
    ap.add_argument("--box", required=True, help="SX,SY,SZ of vdbpack's box:SX,SY,SZ")
    ap.add_argument("--json", action="store_true", help="one JSON object instead of text")
    a = ap.parse_args()
    try:
        size = np.array([float(t) for t in a.box.split(",")])
    except ValueError:
        size = np.array([])
    if len(size) != 3 or not np.all(np.isfinite(size)) or not np.all(size > 0):
        raise SystemExit("packing_structure: --box wants three positive sizes, not '%s'" % a.box)
    P, R = load(a.csv)
    half = 0.5 * size
    d = 2.0 * R.mean()
    vols = 4.0 / 3.0 * math.pi * R ** 3
    whole = vols.sum() / size.prod()
    depth = (half - np.abs(P)).min(1)  # centre's distance from the nearest wall
    cd = CORE_DIAMETERS * d
    core_m = depth > cd
    core_box = np.prod(np.maximum(size - 2 * cd, 0.0))
    core = vols[core_m].sum() / core_box if core_box > 0 else float("nan")
    prof, dt = wall_profile(P, R, half, d)
    bulk = core if core_box > 0 else prof[-1]
    deficit = float((bulk - prof).sum() * dt / d)
    q6, nb, na = bond_order(P, R)
    solid = na >= 8
    wall_m = ~core_m
    out = {
        "count": int(len(R)), "mean_diameter": d, "fraction": whole,
        "core_fraction": core, "core_count": int(core_m.sum()),
        "wall_cost": core - whole if core_box > 0 else float("nan"),
        "wall_deficit_diameters": deficit,
        "mean_neighbours": float(nb.mean()), "mean_q6": float(q6.mean()),
        "solid_like": float(solid.mean()),
        "solid_like_wall": float(solid[wall_m].mean()) if wall_m.any() else float("nan"),
        "solid_like_core": float(solid[core_m].mean()) if core_m.any() else float("nan"),
        "profile": [round(float(p), 4) for p in prof],
        "profile_slab_diameters": dt / d,
    }
    if a.json:
        print(json.dumps(out))
        return
    print("%s: %d spheres, mean diameter %.6g" % (a.csv, out["count"], d))
    print("fraction %.4f, core (centres > %g d from the walls, %d spheres) %.4f" %
          (whole, CORE_DIAMETERS, out["core_count"], core))
    print("walls: deficit %.4f d (the whole below the core by %.4f)" % (deficit, out["wall_cost"]))
    print("fraction at the distance from a wall (d):")
    step = max(1, int(round(0.2 * d / dt)))
    for b in range(0, len(prof), step):
        print("  %4.1f-%4.1f  %.3f" % (b * dt / d, min(len(prof), b + step) * dt / d,
                                      prof[b:b + step].mean()))
    print("q6: mean %.4f over %.2f neighbours; solid-like %.4f (within %g d of a wall %.4f, core %.4f)" %
          (out["mean_q6"], out["mean_neighbours"], out["solid_like"], CORE_DIAMETERS,
           out["solid_like_wall"], out["solid_like_core"]))


if __name__ == "__main__":
    sys.exit(main())
