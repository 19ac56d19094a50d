#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Independent checks of a random (rsa/relax) sphere packing, from PLY files
that OpenVDB's vdb_tool extracted after vdb_ax rewrote P (no vdbpack code):
  x.ply: P = (x, id, 0)   y.ply: P = (y, id, 0)   z.ply: P = (z, id, 0)
  a.ply: P = (pscale, id, group)   (group = 1-based pass index, 0 = none)
Joins them on id and checks: every id once, overlaps between every pair of
spheres (exact pairwise, numpy), every sphere inside the container (fit
inside), the count per group, and the packing fraction against the summary.
Positions come through float32 PLY, so overlaps are bounded at 1e-5 of
r_i + r_j here; vdbpack check verifies the 1e-6 bound from the file itself.
Usage: random_check.py DIR N CONTAINER FIT GROUPCOUNTS SUMMARY.json
  GROUPCOUNTS: comma list of expected counts per group, or '-' to skip."""
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from vp_check import read_ply  # noqa: E402  (the PLY reader, not vdbpack's)


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def by_id(path, n):
    P = read_ply(path)
    if len(P) != n:
        fail("%s has %d points, expected %d" % (path, len(P), n))
    ids = np.rint(P[:, 1]).astype(np.int64)
    if not np.array_equal(np.sort(ids), np.arange(n)):
        fail("%s: ids are not exactly 0..%d once each" % (path, n - 1))
    out = np.empty((n, 2))
    out[ids] = P[:, [0, 2]]
    return out


def main():
    d, n, cont, fit, groups, summary = sys.argv[1:7]
    n = int(n)
    x = by_id(os.path.join(d, "x.ply"), n)[:, 0]
    y = by_id(os.path.join(d, "y.ply"), n)[:, 0]
    z = by_id(os.path.join(d, "z.ply"), n)[:, 0]
    a = by_id(os.path.join(d, "a.ply"), n)
    P = np.stack([x, y, z], axis=1)
    r, g = a[:, 0], np.rint(a[:, 1]).astype(int)
    if not np.all(r > 0):
        fail("a pscale is not positive")
    # overlaps: exact pairwise in chunks
    worst, pairs = 0.0, 0
    for s in range(0, n, 512):
        D = np.linalg.norm(P[s:s + 512, None, :] - P[None, :, :], axis=2)
        S = r[s:s + 512, None] + r[None, :]
        ov = (S - D) / S
        idx = np.arange(s, min(s + 512, n))
        ov[np.arange(len(idx)), idx] = -1.0  # self
        worst = max(worst, float(ov.max()))
        pairs += int(np.count_nonzero(ov > 1e-5))
    if pairs:
        fail("%d overlapping pairs beyond 1e-5 of r_i + r_j (worst %.3g)" % (pairs // 2, worst))
    print("  ok: no two of %d spheres overlap (largest overlap %.2g of r_i + r_j, float32 "
          "positions)" % (n, max(worst, 0.0)))
    # inside the container
    kind, dims = cont.split(":")
    if kind == "box":
        half = np.array([float(v) for v in dims.split(",")]) / 2
        dist = np.max(np.abs(P) - half, axis=1)  # exact for points near a face; >= 0 outside
    else:
        dist = np.linalg.norm(P, axis=1) - float(dims)
    need = dist + (r if fit == "inside" else 0) if True else None
    tol = 1e-5 * max(abs(float(v)) for v in dims.split(","))
    bad = int(np.count_nonzero(need > tol))
    if bad:
        fail("%d spheres cross the wall of %s (fit %s; worst by %.3g)" % (bad, cont, fit,
                                                                           float(need.max())))
    print("  ok: every sphere inside %s (fit %s)" % (cont, fit))
    if groups != "-":
        want = [int(v) for v in groups.split(",")]
        got = [int(np.count_nonzero(g == k + 1)) for k in range(len(want))]
        if got != want or int(np.count_nonzero(g == 0)):
            fail("points per group %s (and %d in none), expected %s" %
                 (got, int(np.count_nonzero(g == 0)), want))
        print("  ok: points per group %s" % got)
    S = json.load(open(summary))
    vol = np.prod([float(v) for v in dims.split(",")]) if kind == "box" else \
        4.0 / 3.0 * np.pi * float(dims) ** 3
    frac = float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / vol)
    if abs(frac - S["packing_fraction"]) > 1e-4 * frac:
        fail("packing fraction from the file %.6f, summary says %.6f" % (frac,
                                                                          S["packing_fraction"]))
    print("  ok: packing fraction %.4f matches the summary" % frac)


main()
