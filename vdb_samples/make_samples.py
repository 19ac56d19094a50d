#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Generates vdbpack's own sample containers (see README.md in this folder).

Meshes need only python3 + numpy; the level sets need pyopenvdb
(Debian: python3-openvdb). The OBJ files are deterministic (running it again
gives byte-identical files); the .vdb files differ only in the random file
UUID that OpenVDB writes into every file header.

    python3 vdb_samples/make_samples.py            # everything, into vdb_samples/
    python3 vdb_samples/make_samples.py --meshes   # only the OBJ files
    python3 vdb_samples/make_samples.py --out DIR

Every mesh is closed, manifold and consistently oriented with outward
normals; each vertex is written once and shared by index, so the meshes
are watertight with or without welding.
"""
import argparse
import os
import sys

import numpy as np


# --------------------------------------------------------------------------
# Mesh construction

def icosphere(subdivisions):
    """Unit icosphere: points (n,3) float64 on the unit sphere, triangles
    (m,3) int, counter-clockwise seen from outside."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    pts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0),
           (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
           (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    pts = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in pts]
    tris = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11),
            (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6), (7, 1, 8),
            (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9),
            (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(subdivisions):
        cache = {}

        def midpoint(a, b):
            key = (a, b) if a < b else (b, a)
            if key not in cache:
                m = pts[a] + pts[b]
                pts.append(m / np.linalg.norm(m))
                cache[key] = len(pts) - 1
            return cache[key]

        new = []
        for a, b, c in tris:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        tris = new
    return np.array(pts), np.array(tris, dtype=np.int64)


def torus(R, r, nu, nv):
    """Torus around the z axis: nu segments around the hole, nv around the
    tube; quads (i,j),(i+1,j),(i+1,j+1),(i,j+1) face outward."""
    u = 2.0 * np.pi * np.arange(nu) / nu
    v = 2.0 * np.pi * np.arange(nv) / nv
    uu, vv = np.meshgrid(u, v, indexing="ij")
    rho = R + r * np.cos(vv)
    pts = np.stack([rho * np.cos(uu), rho * np.sin(uu), r * np.sin(vv)], axis=-1)
    pts = pts.reshape(-1, 3)
    quads = []
    for i in range(nu):
        for j in range(nv):
            i1, j1 = (i + 1) % nu, (j + 1) % nv
            quads.append((i * nv + j, i1 * nv + j, i1 * nv + j1, i * nv + j1))
    return pts, np.array(quads, dtype=np.int64)


def peanut(subdivisions):
    """Concave, genus-0 closed surface: the unit icosphere pushed out
    radially to r(d) = 0.55 + 0.6 * d_x^2 (d = unit direction). Two lobes
    along x joined by a waist (radius 0.55) whose surface curves inward
    (r^2 + 2 r'^2 - r r'' < 0 there), so it is not convex. The radial map
    of a star-shaped surface cannot self-intersect."""
    pts, tris = icosphere(subdivisions)
    r = 0.55 + 0.6 * pts[:, 0] ** 2
    return pts * r[:, None], tris


def box(sx, sy, sz):
    """Axis-aligned box centred at the origin, 6 outward quads."""
    hx, hy, hz = sx / 2.0, sy / 2.0, sz / 2.0
    pts = np.array([(-hx, -hy, -hz), (hx, -hy, -hz), (hx, hy, -hz), (-hx, hy, -hz),
                    (-hx, -hy, hz), (hx, -hy, hz), (hx, hy, hz), (-hx, hy, hz)])
    quads = np.array([(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4),
                      (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)], dtype=np.int64)
    return pts, quads


# --------------------------------------------------------------------------
# Checks (the same counts vdbpack computes, done independently here)

def check_closed(name, pts, faces):
    """Asserts every edge is used by exactly two faces with opposite
    directions (closed, manifold, consistently oriented) and returns the
    signed volume (> 0: outward normals)."""
    directed = {}
    for f in faces:
        n = len(f)
        for k in range(n):
            e = (int(f[k]), int(f[(k + 1) % n]))
            if e in directed:
                raise SystemExit("%s: directed edge %s used twice" % (name, e))
            directed[e] = 1
    for (a, b) in directed:
        if (b, a) not in directed:
            raise SystemExit("%s: edge %s has no opposite: not closed" % (name, (a, b)))
    if len(np.unique(np.round(pts, 12), axis=0)) != len(pts):
        raise SystemExit("%s: two vertices at the same position" % name)
    c = 0.5 * (pts.min(axis=0) + pts.max(axis=0))
    vol = 0.0
    for f in faces:
        p = pts[np.asarray(f)] - c
        for k in range(1, len(f) - 1):  # fan: exact for planar polygons
            vol += np.dot(p[0], np.cross(p[k], p[k + 1]))
    vol /= 6.0
    if vol <= 0:
        raise SystemExit("%s: signed volume %g is not positive" % (name, vol))
    return vol


def write_obj(path, pts, faces, comment):
    lines = ["# %s\n" % line for line in comment.strip().splitlines()]
    lines.append("o %s\n" % os.path.splitext(os.path.basename(path))[0])
    for p in pts:
        lines.append("v %s %s %s\n" % tuple(_fmt(x) for x in p))
    for f in faces:
        lines.append("f " + " ".join(str(int(i) + 1) for i in f) + "\n")
    with open(path, "w", newline="\n") as fh:
        fh.writelines(lines)


def _fmt(x):
    s = "%.9g" % x
    return "0" if s == "-0" else s


def read_back(path):
    """Points as written (rounded to 9 digits): level sets are built from
    exactly what the OBJ holds."""
    pts, faces = [], []
    with open(path) as fh:
        for line in fh:
            t = line.split()
            if t and t[0] == "v":
                pts.append([float(x) for x in t[1:4]])
            elif t and t[0] == "f":
                faces.append([int(x) - 1 for x in t[1:]])
    return np.array(pts), faces


# --------------------------------------------------------------------------

def make_meshes(out):
    made = {}
    specs = [
        ("sphere.obj", icosphere(3),
         "Icosphere, radius 1, centred at the origin: icosahedron subdivided 3 times\n"
         "(midpoints projected onto the sphere). Convex. 642 vertices, 1280 triangles."),
        ("torus.obj", torus(1.0, 0.4, 64, 32),
         "Torus around the z axis: major radius R = 1, tube radius r = 0.4,\n"
         "64 x 32 planar quads (genus 1: a hole through it)."),
        ("peanut.obj", peanut(4),
         "Peanut: unit icosphere (4 subdivisions) pushed out radially to\n"
         "r(d) = 0.55 + 0.6 d_x^2. Two lobes along x joined by a concave waist.\n"
         "Closed, genus 0. 2562 vertices, 5120 triangles."),
        ("box.obj", box(2.0, 1.0, 1.0),
         "Box 2 x 1 x 1 centred at the origin, 6 quads."),
    ]
    for name, (pts, faces), comment in specs:
        path = os.path.join(out, name)
        write_obj(path, pts, faces,
                  comment + "\nMade by vdb_samples/make_samples.py (vdbpack).")
        rp, rf = read_back(path)
        vol = check_closed(name, rp, rf)
        made[name] = vol
        print("%-12s %6d verts %6d faces  volume %.6f  bbox %s..%s  %d bytes" % (
            name, len(rp), len(rf), vol, np.round(rp.min(0), 4), np.round(rp.max(0), 4),
            os.path.getsize(path)))
    return made


def make_level_sets(out, voxel, torus_voxel):
    import pyopenvdb as vdb

    sphere = vdb.createLevelSetSphere(radius=1.0, center=(0.0, 0.0, 0.0),
                                      voxelSize=voxel, halfWidth=3.0)
    sphere.name = "sphere"
    _tag(sphere, "createLevelSetSphere(radius=1, center=0, voxelSize=%g, halfWidth=3)" % voxel)
    vdb.write(os.path.join(out, "sphere_ls.vdb"), grids=[sphere])

    pts, faces = read_back(os.path.join(out, "torus.obj"))
    quads = np.array(faces, dtype=np.int32)
    xform = vdb.createLinearTransform(voxelSize=torus_voxel)
    torus_ls = vdb.FloatGrid.createLevelSetFromPolygons(
        pts.astype(np.float32), quads=quads, transform=xform, halfWidth=3.0)
    torus_ls.name = "torus"
    _tag(torus_ls, "FloatGrid.createLevelSetFromPolygons(torus.obj quads, "
         "voxelSize=%g, halfWidth=3)" % torus_voxel)
    vdb.write(os.path.join(out, "torus_ls.vdb"), grids=[torus_ls])

    for name in ("sphere_ls.vdb", "torus_ls.vdb"):
        path = os.path.join(out, name)
        g = vdb.read(path, name.split("_")[0])
        print("%-14s class %s  %d active voxels  bbox %s  %d bytes" % (
            name, g.gridClass, g.activeVoxelCount(), g.evalActiveVoxelBoundingBox(),
            os.path.getsize(path)))


def _tag(grid, how):
    grid["creator"] = "vdbpack vdb_samples/make_samples.py"
    grid["vdbpack_made_with"] = "pyopenvdb " + how


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=here, help="output folder (default: this one)")
    ap.add_argument("--meshes", action="store_true", help="only the OBJ meshes")
    ap.add_argument("--voxel", type=float, default=0.02, help="sphere_ls.vdb voxel size")
    ap.add_argument("--torus-voxel", type=float, default=0.025,
                    help="torus_ls.vdb voxel size (0.02 would make a 1.1 MB file)")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    make_meshes(a.out)
    if not a.meshes:
        make_level_sets(a.out, a.voxel, a.torus_voxel)
    return 0


if __name__ == "__main__":
    sys.exit(main())
