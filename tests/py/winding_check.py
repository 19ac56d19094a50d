#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Particles of a packing against the generalized winding number of a
mesh, computed here with numpy alone (no vdbpack code): for tests/sh_inside.sh.

    winding_check.py MESH.obj PACKING.csv [--probe F] [--min W] [--sample N]

Reads the OBJ (v lines, taken as float as Assimp does; f lines of any
size, triangulated as vdbpack does; v/vt/vn indices, negative indices) and the CSV that vdbpack writes (x, y, z,
pscale). For each particle (or N of them, evenly spread) it sums the exact
solid angles of every triangle (Van Oosterom & Strackee) at the centre and
at 6 points at F times the radius along the axes (F = 0.9 by default: a
particle touching the wall keeps those points inside), and requires every
winding number to be at least W (default 0.5). Prints one summary line;
exits 1 with the worst particle named when any point is below W.
"""
import sys

import numpy as np


def cross2(a, b, c):
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])


def triangulate(pos, idx):
    """A polygon's triangles as vdbpack makes them (src/mesh/mesh.c,
    triangulate_polygon): ear clipping in the plane of the Newell normal,
    the first ear from corner 0 on, a fan for what cannot be clipped. A
    non-planar polygon's surface depends on the diagonals, so the test
    must cut it the same way."""
    n = len(idx)
    if n == 3:
        return [list(idx)]
    nn = np.zeros(3)
    for k in range(n):
        a, b = pos[idx[k]], pos[idx[(k + 1) % n]]
        nn += [(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]),
               (a[0] - b[0]) * (a[1] + b[1])]
    ax = int(np.argmax(np.abs(nn)))
    if not abs(nn[ax]) > 0 or n > 1024:
        return [[idx[0], idx[k], idx[k + 1]] for k in range(1, n - 1)]
    u, v = (ax + 1) % 3, (ax + 2) % 3
    if nn[ax] < 0:
        u, v = v, u
    xy = [(pos[i][u], pos[i][v]) for i in idx]
    ring = list(range(n))
    out = []
    start = 0
    while len(ring) > 3:
        m = len(ring)
        clipped = False
        for t in range(m):
            i = (start + t) % m
            ip, ic, inx = ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m]
            a, b, c = xy[ip], xy[ic], xy[inx]
            if not cross2(a, b, c) > 0:
                continue
            ear = True
            for q in ring:
                if q in (ip, ic, inx):
                    continue
                p = xy[q]
                if p == a or p == b or p == c:
                    continue
                if cross2(a, b, p) >= 0 and cross2(b, c, p) >= 0 and cross2(c, a, p) >= 0:
                    ear = False
                    break
            if not ear:
                continue
            out.append([idx[ip], idx[ic], idx[inx]])
            del ring[i]
            start = i % len(ring)
            clipped = True
            break
        if not clipped:
            break
    for k in range(1, len(ring) - 1):
        out.append([idx[ring[0]], idx[ring[k]], idx[ring[k + 1]]])
    return out


def read_obj(path):
    verts, faces = [], []
    with open(path, encoding="utf-8", errors="replace") as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f":
                idx = []
                for p in parts[1:]:
                    i = int(p.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                faces.append(idx)
    # as vdbpack reads them: float coordinates (Assimp's), in double
    pos = np.array(verts, dtype=np.float32).astype(np.float64)
    tris = []
    for idx in faces:
        if len(idx) >= 3 and all(0 <= i < len(pos) for i in idx):
            tris.extend(triangulate(pos, idx))
    return pos, np.array(tris, dtype=np.int64)


def winding(verts, tris, points, chunk=200000):
    """Winding numbers of points (P x 3) with respect to the triangles."""
    A, B, C = verts[tris[:, 0]], verts[tris[:, 1]], verts[tris[:, 2]]
    out = np.zeros(len(points))
    step = max(1, chunk // max(1, len(tris)))
    for s in range(0, len(points), step):
        q = points[s:s + step, None, :]
        a, b, c = A[None] - q, B[None] - q, C[None] - q
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        det = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ijk,ijk->ij", a, b) * lc +
               np.einsum("ijk,ijk->ij", a, c) * lb + np.einsum("ijk,ijk->ij", b, c) * la)
        out[s:s + step] = (2.0 * np.arctan2(det, den)).sum(axis=1) / (4.0 * np.pi)
    return out


def main(argv):
    args = argv[1:]
    probe, wmin, sample = 0.9, 0.5, 0
    while len(args) > 2:
        opt, val = args[-2], args[-1]
        args = args[:-2]
        if opt == "--probe":
            probe = float(val)
        elif opt == "--min":
            wmin = float(val)
        elif opt == "--sample":
            sample = int(val)
        else:
            sys.exit("winding_check: unknown option " + opt)
    mesh, packing = args
    verts, tris = read_obj(mesh)
    data = np.loadtxt(packing, delimiter=",", skiprows=1, usecols=(1, 2, 3, 4), ndmin=2)
    if sample and len(data) > sample:
        data = data[np.linspace(0, len(data) - 1, sample).astype(int)]
    pos, rad = data[:, :3], data[:, 3]
    offsets = np.array([[0, 0, 0], [1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1],
                        [0, 0, -1]], dtype=np.float64)
    pts = (pos[:, None, :] + probe * rad[:, None, None] * offsets[None]).reshape(-1, 3)
    w = winding(verts, tris, pts).reshape(len(pos), len(offsets))
    worst = w.min(axis=1)
    bad = np.nonzero(worst < wmin)[0]
    print("winding_check: %d particles of %s against %s (%d triangles): lowest winding "
          "number %.4f at centres, %.4f at %.2f r" % (len(pos), packing, mesh, len(tris),
                                                     w[:, 0].min(), worst.min(), probe))
    if len(bad):
        i = bad[np.argmin(worst[bad])]
        print("FAIL: %d particles below %.2f; worst at (%g, %g, %g) r %g: %.4f" %
              (len(bad), wmin, pos[i][0], pos[i][1], pos[i][2], rad[i], worst[i]))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
