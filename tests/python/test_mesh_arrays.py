# SPDX-License-Identifier: Apache-2.0
"""Containers from numpy arrays (Container.from_mesh), checked against the
geometry of the same arrays computed here: every particle inside the
polyhedron by at least its radius (within the level set's voxel), no two
closer than the sum of their radii."""
import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, overlapping_pairs


def icosphere(subdivisions=2, radius=1.0):
    t = (1 + 5 ** 0.5) / 2
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t),
         (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    v = [np.array(x, float) / np.linalg.norm(x) for x in v]
    for _ in range(subdivisions):
        mid = {}

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = v[a] + v[b]
                v.append(p / np.linalg.norm(p))
                mid[key] = len(v) - 1
            return mid[key]
        f = [t for a, b, c in f for t in ((a, m(a, b), m(c, a)), (b, m(b, c), m(a, b)),
                                          (c, m(c, a), m(b, c)), (m(a, b), m(b, c), m(c, a)))]
    return np.array(v) * radius, np.array(f, np.int64)


def box_mesh(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    v = np.array([[lo[0] if i & 1 == 0 else hi[0], lo[1] if i & 2 == 0 else hi[1],
                   lo[2] if i & 4 == 0 else hi[2]] for i in range(8)])
    quads = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    t = [(a, b, c) for a, b, c, d in quads] + [(a, c, d) for a, b, c, d in quads]
    return v, np.array(t)


def face_planes(v, t):
    """Outward unit normals n and offsets d of a convex mesh's faces (n.x <= d inside)."""
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    n = np.cross(b - a, c - a)
    n /= np.linalg.norm(n, axis=1)[:, None]
    d = np.einsum("ij,ij->i", n, a)
    centre = v.mean(axis=0)
    assert np.all(n @ centre < d), "the test mesh must be convex and outward-facing"
    return n, d


def assert_inside(p, v, t, tol):
    n, d = face_planes(v, t)
    # signed distance of each centre to each face plane; inside by r means <= -r
    depth = (p.positions @ n.T - d[None, :]).max(axis=1) + p.radii
    assert depth.max() <= tol, "particle %d crosses the mesh by %g (tolerance %g)" % (
        int(depth.argmax()), depth.max(), tol)


def test_icosphere_from_numpy_lattice():
    v, t = icosphere(2)
    # the particle radius sizes the level set's interior band (as pack()
    # does itself for a container given as a path)
    c = vdbpack.Container.from_mesh(v, t, name="icosphere", particle_radius=0.08)
    info = c.info
    assert info["kind"] == "mesh" and info["mesh_triangles"] == len(t) == 320
    assert info["mesh_vertices"] == len(v) and info["boundary_edges"] == 0
    # the polyhedron's volume, summed here over its faces' tetrahedra
    vol = np.einsum("ij,ij->i", v[t[:, 0]], np.cross(v[t[:, 1]], v[t[:, 2]])).sum() / 6
    assert abs(info["mesh_volume"] - vol) < 1e-9 * vol
    assert abs(c.volume - vol) < 0.03 * vol
    p = vdbpack.pack(c, radius=0.08)
    assert len(p) > 500
    assert_inside(p, v, t, tol=info["voxel_size"])
    assert overlapping_pairs(p.positions, p.radii, tol=1e-6) == []
    assert p.metadata["container"] == "icosphere" and p.metadata["inside"] == "auto"


def test_box_from_float32_and_int16_arrays_rsa():
    lo, hi = (0.5, 0.25, -0.5), (2.5, 1.25, 0.5)
    v, t = box_mesh(lo, hi)
    c = vdbpack.Container.from_mesh(v.astype(np.float32), t.astype(np.int16), voxel_size=0.02,
                                    particle_radius=0.1)
    assert c.info["voxel_size"] == pytest.approx(0.02)
    assert abs(c.volume - 2.0) < 0.02
    p = vdbpack.pack(c, method="rsa", radius=0.06, count=400, grow=True, seed=5)
    assert len(p) == 400
    lo, hi = np.array(lo), np.array(hi)
    r = p.radii[:, None]
    tol = c.info["voxel_size"]
    assert np.all(p.positions - r >= lo - tol) and np.all(p.positions + r <= hi + tol)
    assert overlapping_pairs(p.positions, p.radii, tol=1e-6) == []
    # grown until touching: some particles larger than they started
    assert p.radii.max() > 0.06 * 1.05


def test_lists_and_unsigned_indices_are_accepted():
    v, t = box_mesh((0, 0, 0), (1, 1, 1))
    c1 = vdbpack.Container.from_mesh(v.tolist(), t.astype(np.uint64), voxel_size=0.05)
    c2 = vdbpack.Container.from_mesh(v.astype(int), t.tolist(), voxel_size=0.05)
    pts = np.random.default_rng(1).uniform(-0.2, 1.2, (200, 3))
    np.testing.assert_array_equal(c1.distance(pts), c2.distance(pts))


def test_same_level_set_as_the_mesh_file():
    """The numpy box equals vdb_samples/box.obj (2 x 1 x 1 about the
    origin): the same distances from both containers at the same voxel."""
    v, t = box_mesh((-1, -0.5, -0.5), (1, 0.5, 0.5))
    a = vdbpack.Container.from_mesh(v, t, voxel_size=0.04)
    b = vdbpack.Container.from_file(SAMPLES + "/box.obj", voxel_size=0.04)
    assert a.info["mesh_triangles"] == b.info["mesh_triangles"] == 12
    pts = np.random.default_rng(2).uniform(-1.2, 1.2, (500, 3))
    np.testing.assert_allclose(a.distance(pts), b.distance(pts), rtol=0, atol=1e-6)
    # inside the band the distance is the box's own, to a fraction of a voxel
    inner = np.random.default_rng(3).uniform([-1, -0.5, -0.5], [1, 0.5, 0.5], (300, 3))
    exact = -np.min(np.stack([1 - np.abs(inner[:, 0]), 0.5 - np.abs(inner[:, 1]),
                              0.5 - np.abs(inner[:, 2])]), axis=0)
    near = exact > -0.1
    assert near.sum() > 50
    assert np.abs(a.distance(inner)[near] - exact[near]).max() < 0.04


def test_analytic_distances_are_exact():
    s = vdbpack.Container.sphere((1, 2, 3), 0.5)
    pts = np.random.default_rng(4).normal(size=(100, 3)) + [1, 2, 3]
    np.testing.assert_allclose(s.distance(pts), np.linalg.norm(pts - [1, 2, 3], axis=1) - 0.5,
                               rtol=0, atol=1e-12)
    assert s.distance((1, 2, 3)) == -0.5
    assert s.distance(np.zeros((0, 3))).shape == (0,)
    b = vdbpack.Container.box((0, 0, 0), (2, 1, 1))
    assert b.info["kind"] == "analytic" and b.volume == pytest.approx(2.0)
    assert b.distance((1, 0.5, 0.5)) == pytest.approx(-0.5)


def test_packing_in_analytic_box_checked_in_numpy():
    p = vdbpack.pack(vdbpack.Container.box((-1, -1, -1), (1, 1, 1)), method="relax",
                     radius="uniform:0.05:0.08", count=300, target_fraction=0.45)
    assert len(p) == 300
    assert np.all(np.abs(p.positions) + p.radii[:, None] <= 1 + 1e-9)
    # relax ends with overlaps of at most 1e-6 of r_i + r_j
    assert overlapping_pairs(p.positions, p.radii, tol=1.01e-6) == []
    assert p.fraction == pytest.approx((4 / 3 * np.pi * p.radii ** 3).sum() / 8, rel=1e-12)


def test_mesh_shape_from_numpy_octahedron():
    v = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], float)
    t = np.array([(0, 2, 4), (2, 1, 4), (1, 3, 4), (3, 0, 4), (2, 0, 5), (1, 2, 5), (3, 1, 5),
                  (0, 3, 5)])
    s = vdbpack.MeshShape.from_mesh(v, t, name="octa")
    assert s.name == "octa" and s.triangles == 8
    assert s.volume == pytest.approx(4 / 3, rel=1e-9)       # octahedron of circumradius 1
    assert s.inradius == pytest.approx(1 / 3 ** 0.5, rel=1e-9)
    p = vdbpack.pack("box:1,1,1", method="rsa", shape=s, radius=0.1, count=100)
    assert p.shape == "mesh" and p.metadata["shape_file"] == "octa"
    assert len(p) == 100 and p.orient.shape == (100, 4)
    np.testing.assert_allclose(np.linalg.norm(p.orient, axis=1), 1, atol=1e-6)
    # the check of the library agrees: no overlaps, nothing outside
    assert p.check("box:1,1,1").ok
