#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Independent checks of vdbpack output for the tests/sh_*.sh scripts.

Reads only files produced by OpenVDB's own tools (PLY from `vdb_tool
-vdb2points`) and JSON text; every expected value is computed here from
geometry, never taken from vdbpack.  Each subcommand prints what it checks and
exits non-zero with a "FAIL:" line on the first violated property.

  vp_check.py plycount FILE.ply
  vp_check.py json FILE.json KEY            print a top-level JSON value
  vp_check.py geom --ply F --summary S.json --container sphere:R|box:X,Y,Z
                   --shape sphere|cube|... --lattice sc|bcc|fcc|hcp|densest
                   --fit inside|center --radius r
  vp_check.py ids --ply F --n N --radius r  (P was set to (id, pscale, 0) by vdb_ax)
  vp_check.py info --info INFO.json --summary S.json
  vp_check.py fraction --summary S.json --container ... --shape S --lattice L
"""
import argparse
import json
import math
import sys

import numpy as np

SQ2, SQ3 = math.sqrt(2.0), math.sqrt(3.0)
PHI = (1 + math.sqrt(5.0)) / 2

# inradius / circumradius of each shape (circumradius = pscale)
IN_OVER_CIRC = {
    "sphere": 1.0,
    "tetrahedron": 1.0 / 3.0,
    "cube": 1.0 / SQ3,
    "octahedron": 1.0 / SQ3,
    "dodecahedron": 0.7946544722917661,
    "icosahedron": 0.7946544722917661,
}
# volume of the shape with circumradius 1
UNIT_VOLUME = {
    "sphere": 4.0 / 3.0 * math.pi,
    "tetrahedron": 8.0 / (9.0 * SQ3),
    "cube": (2.0 / SQ3) ** 3,
    "octahedron": 4.0 / 3.0,
    # edge a = 4/(sqrt3 (1+sqrt5)) for R=1; V = (15+7 sqrt5)/4 a^3
    "dodecahedron": (15 + 7 * math.sqrt(5.0)) / 4 * (4.0 / (SQ3 * (1 + math.sqrt(5.0)))) ** 3,
    # edge a = R / sin(2pi/5); V = 5(3+sqrt5)/12 a^3
    "icosahedron": 5 * (3 + math.sqrt(5.0)) / 12 * (1.0 / math.sin(2 * math.pi / 5)) ** 3,
}
# infinite-lattice packing fractions (literature values)
LATTICE_FRACTION = {
    ("sphere", "sc"): math.pi / 6,
    ("sphere", "bcc"): math.pi * SQ3 / 8,
    ("sphere", "fcc"): math.pi / (3 * SQ2),
    ("sphere", "hcp"): math.pi / (3 * SQ2),
    ("cube", "densest"): 1.0,
    ("octahedron", "densest"): 18.0 / 19.0,
    ("tetrahedron", "densest"): 18.0 / 49.0,
    ("dodecahedron", "densest"): (2 + PHI) / 4,
    ("icosahedron", "densest"): 0.8363574,
}
# neighbour shells, in units of the sphere radius r (touching distance 2r):
# list of (distance limit, expected number of neighbours within it)
SHELLS = {
    ("sphere", "sc"): [(2.1, 6), (2.9, 18)],
    ("sphere", "bcc"): [(2.1, 8), (2.5, 14)],
    ("sphere", "fcc"): [(2.1, 12), (3.35, 18)],  # 12 @2, 6 @2.83, 24 @3.46
    ("sphere", "hcp"): [(2.1, 12), (3.35, 20)],  # 12 @2, 6 @2.83, 2 @3.27
    # cube of circumradius r: simple cubic of edge a = 2r/sqrt3 = 1.1547 r
    ("cube", "densest"): [(1.2, 6), (1.7, 18)],
}

failures = []


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def ok(msg):
    print("  ok: " + msg)


def read_ply(path):
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if end < 0:
        fail("%s: no PLY header" % path)
    nl = data.index(b"\n", end) + 1
    header = data[:nl].decode("ascii", "replace").splitlines()
    fmt, n, props, in_vertex = None, None, [], False
    for line in header:
        w = line.split()
        if not w:
            continue
        if w[0] == "format":
            fmt = w[1]
        elif w[0] == "element":
            in_vertex = w[1] == "vertex"
            if in_vertex:
                n = int(w[2])
        elif w[0] == "property" and in_vertex:
            if w[1] == "list":
                fail("%s: list property in vertex element" % path)
            props.append((w[2], w[1]))
    if n is None:
        fail("%s: no vertex element" % path)
    types = {"float": "f4", "float32": "f4", "double": "f8", "float64": "f8", "int": "i4",
             "int32": "i4", "uint": "u4", "uint32": "u4", "uchar": "u1", "uint8": "u1",
             "char": "i1", "int8": "i1", "short": "i2", "int16": "i2", "ushort": "u2",
             "uint16": "u2"}
    if fmt == "ascii":
        rows = data[nl:].decode("ascii").split("\n")[:n]
        arr = np.array([[float(v) for v in r.split()[:len(props)]] for r in rows], dtype=np.float64)
        cols = {name: arr[:, i] for i, (name, _) in enumerate(props)}
    else:
        endian = "<" if fmt == "binary_little_endian" else ">"
        dt = np.dtype([(name, endian + types[t]) for name, t in props])
        rec = np.frombuffer(data, dtype=dt, count=n, offset=nl)
        cols = {name: rec[name].astype(np.float64) for name, _ in props}
    for c in "xyz":
        if c not in cols:
            fail("%s: vertex has no %s" % (path, c))
    return np.stack([cols["x"], cols["y"], cols["z"]], axis=1)


def parse_container(spec):
    kind, _, rest = spec.partition(":")
    vals = [float(v) for v in rest.split(",")]
    if kind == "sphere" and len(vals) == 1:
        return ("sphere", vals[0])
    if kind == "box" and len(vals) == 3:
        return ("box", np.array(vals))
    fail("bad container spec %s" % spec)


def container_volume(c):
    return 4.0 / 3.0 * math.pi * c[1] ** 3 if c[0] == "sphere" else float(np.prod(c[1]))


def boundary_distance(P, c):
    """Distance from each point to the container surface (positive inside)."""
    if c[0] == "sphere":
        return c[1] - np.linalg.norm(P, axis=1)
    half = c[1] / 2
    return np.min(half[None, :] - np.abs(P), axis=1)


def neighbour_counts(P, idx, limits, chunk=512):
    """For points P[idx], number of other points within each limit."""
    out = np.zeros((len(idx), len(limits)), dtype=np.int64)
    lim2 = np.array(limits) ** 2
    for s in range(0, len(idx), chunk):
        sub = P[idx[s:s + chunk]]
        d2 = ((sub[:, None, :] - P[None, :, :]) ** 2).sum(axis=2)
        for k, l2 in enumerate(lim2):
            out[s:s + chunk, k] = (d2 <= l2).sum(axis=1) - 1  # minus itself
    return out


def min_distance(P, chunk=512):
    best = np.inf
    n = len(P)
    for s in range(0, n, chunk):
        sub = P[s:s + chunk]
        d2 = ((sub[:, None, :] - P[None, :, :]) ** 2).sum(axis=2)
        rows = np.arange(sub.shape[0])
        d2[rows, rows + s] = np.inf
        best = min(best, float(d2.min()))
    return math.sqrt(best)


def cmd_geom(a):
    P = read_ply(a.ply)
    S = json.load(open(a.summary))
    c = parse_container(a.container)
    r = a.radius
    n = len(P)
    print("geom: %d points from %s (%s, %s, %s, fit %s, r=%g)" %
          (n, a.ply, a.container, a.shape, a.lattice, a.fit, r))
    if n != S["count"]:
        fail("vdb_tool extracted %d points, JSON summary says count %d" % (n, S["count"]))
    ok("point count %d == JSON count" % n)
    if n == 0:
        fail("no points")
    if not np.all(np.isfinite(P)):
        fail("non-finite positions")
    tol = 1e-3 * r
    dist = boundary_distance(P, c)
    if a.fit == "inside":
        need = r if a.shape == "sphere" else r * IN_OVER_CIRC[a.shape]
        what = "r" if a.shape == "sphere" else "inradius"
    else:
        need, what = 0.0, "0"
    worst = float(dist.min())
    if worst < need - tol:
        i = int(np.argmin(dist))
        fail("point %d at %s is %.6g from the container surface, need >= %s = %.6g" %
             (i, P[i].tolist(), worst, what, need))
    ok("every point inside %s with clearance >= %s (min clearance %.6g, need %.6g)" %
       (a.container, what, worst, need))
    dmin = min_distance(P)
    need_d = 2 * r * IN_OVER_CIRC[a.shape]
    if dmin < need_d * (1 - 1e-3):
        fail("minimum centre distance %.6g < %.6g (2 x %s)" %
             (dmin, need_d, "r" if a.shape == "sphere" else "inradius"))
    ok("minimum centre distance %.6g >= %.6g" % (dmin, need_d))
    shells = SHELLS.get((a.shape, a.lattice))
    if shells and a.fit == "inside":
        reach = max(l for l, _ in shells) * r
        interior = np.nonzero(dist >= need + reach + 2 * tol)[0]
        if len(interior) < 5:
            fail("only %d interior points to check neighbour shells; use a larger container" %
                 len(interior))
        counts = neighbour_counts(P, interior, [l * r for l, _ in shells])
        for k, (l, want) in enumerate(shells):
            bad = np.nonzero(counts[:, k] != want)[0]
            if len(bad):
                i = interior[bad[0]]
                fail("%s: interior point %d at %s has %d neighbours within %.3g r, expected %d "
                     "(%d of %d interior points wrong)" % (a.lattice, i, P[i].tolist(),
                                                           counts[bad[0], k], l, want, len(bad),
                                                           len(interior)))
            ok("%d interior points each have %d neighbours within %.3g r (%s)" %
               (len(interior), want, l, a.lattice))


def cmd_fraction(a):
    S = json.load(open(a.summary))
    c = parse_container(a.container)
    vol = container_volume(c)
    r = S["radius"]
    print("fraction: analytic volume %.10g, %d x %s of radius %g" % (vol, S["count"], a.shape, r))
    if abs(S["container_volume"] - vol) > 1e-9 * vol:
        fail("JSON container_volume %.12g != analytic %.12g" % (S["container_volume"], vol))
    ok("container_volume %.12g == analytic" % vol)
    frac = S["count"] * UNIT_VOLUME[a.shape] * r ** 3 / vol
    if abs(S["packing_fraction"] - frac) > 1e-9 * frac:
        fail("JSON packing_fraction %.12g != count*V(particle)/V(container) = %.12g" %
             (S["packing_fraction"], frac))
    ok("packing_fraction %.9g == count * particle volume / container volume" % frac)
    lf = LATTICE_FRACTION.get((a.shape, a.lattice))
    if lf is not None:
        if abs(S["lattice_fraction"] - lf) > 1e-5:
            fail("JSON lattice_fraction %.9g != %s/%s literature value %.9g" %
                 (S["lattice_fraction"], a.shape, a.lattice, lf))
        ok("lattice_fraction %.9g == literature value for %s/%s" % (lf, a.shape, a.lattice))
        if S.get("fit") == "inside" and frac > lf + 1e-9:
            fail("packing fraction %.6g exceeds the infinite-lattice fraction %.6g" % (frac, lf))


def cmd_ids(a):
    P = read_ply(a.ply)
    n = a.n
    print("ids: %d points whose P was set to (id, pscale, 0) by vdb_ax" % len(P))
    if len(P) != n:
        fail("%d points after vdb_ax, expected %d" % (len(P), n))
    ids = np.rint(P[:, 0]).astype(np.int64)
    if np.max(np.abs(P[:, 0] - ids)) > 0.05:
        fail("id values not integral after round trip (max error %g)" %
             np.max(np.abs(P[:, 0] - ids)))
    srt = np.sort(ids)
    if not np.array_equal(srt, np.arange(n)):
        dup = srt[1:][srt[1:] == srt[:-1]]
        fail("ids are not a permutation of 0..%d (min %d, max %d, %d duplicates e.g. %s)" %
             (n - 1, srt[0], srt[-1], len(dup), dup[:5].tolist()))
    ok("ids are exactly 0..%d, each once" % (n - 1))
    err = float(np.max(np.abs(P[:, 1] - a.radius)))
    # pscale carried through a 16-bit fixed-point P: tolerance = quantisation
    if err > 1e-3 * a.radius + 1e-4 * max(1.0, n / 1000.0):
        fail("pscale differs from radius %g by up to %g" % (a.radius, err))
    ok("pscale == %g for every point (max deviation %.3g after the P round trip)" % (a.radius, err))


def cmd_info(a):
    I = json.load(open(a.info))
    S = json.load(open(a.summary))
    print("info: %s vs summary %s" % (a.info, a.summary))
    md = I.get("metadata", {})
    for key, skey in (("packing_fraction", "packing_fraction"), ("particle_count", "count"),
                      ("radius", "radius"), ("container_volume", "container_volume")):
        if key not in md:
            fail("info --json metadata has no %s" % key)
        v, w = md[key], S[skey]
        if not isinstance(v, (int, float)):
            fail("metadata %s is %r, not a number" % (key, v))
        if abs(v - w) > 1e-5 * max(abs(w), 1e-30):
            fail("metadata %s = %r but summary %s = %r" % (key, v, skey, w))
        exact = "exact" if abs(v - w) <= 1e-12 * max(abs(w), 1e-30) else \
            "NOTE: only to %d significant digits" % len(repr(v).replace(".", "").lstrip("0"))
        ok("metadata %s = %r matches summary %r (%s)" % (key, v, w, exact))
    for key in ("creator", "command_line", "seed", "method", "shape", "lattice", "fit",
                "container", "voxel_size"):
        if key not in md:
            fail("info --json metadata lacks %s" % key)
    ok("metadata has creator, command_line, seed, method, shape, lattice, fit, container, "
       "voxel_size")
    grids = I.get("grids", [])
    pts = [g for g in grids if g.get("name") == "points"]
    if len(pts) != 1:
        fail("expected one grid 'points', got %s" % [g.get("name") for g in grids])
    g = pts[0]
    if g.get("points") != S["count"]:
        fail("info says %r points, summary %r" % (g.get("points"), S["count"]))
    attrs = {x["name"]: x["type"] for x in g.get("attributes", [])}
    for name, typ in (("P", "vec3s"), ("pscale", "float"), ("id", "int32")):
        if attrs.get(name) != typ:
            fail("attribute %s has type %r, expected %s" % (name, attrs.get(name), typ))
    if S["shape"] != "sphere" and attrs.get("orient") != "quats":
        fail("orient attribute type %r, expected quats" % attrs.get("orient"))
    if S["shape"] == "sphere" and "orient" in attrs:
        fail("spheres should not carry orient")
    groups = {x["name"]: x["count"] for x in g.get("groups", [])}
    if groups.get("pass1") != S["count"]:
        fail("group pass1 has %r points, expected all %d" % (groups.get("pass1"), S["count"]))
    ok("grid points: %d points, attributes %s, group pass1 holds all" % (S["count"], attrs))


def main():
    ap = argparse.ArgumentParser()
    sub = ap.add_subparsers(dest="cmd", required=True)
    p = sub.add_parser("plycount")
    p.add_argument("ply")
    p = sub.add_parser("json")
    p.add_argument("file")
    p.add_argument("key")
    p = sub.add_parser("geom")
    for k in ("ply", "summary", "container", "shape", "lattice", "fit"):
        p.add_argument("--" + k, required=True)
    p.add_argument("--radius", type=float, required=True)
    p = sub.add_parser("fraction")
    for k in ("summary", "container", "shape", "lattice"):
        p.add_argument("--" + k, required=True)
    p = sub.add_parser("ids")
    p.add_argument("--ply", required=True)
    p.add_argument("--n", type=int, required=True)
    p.add_argument("--radius", type=float, required=True)
    p = sub.add_parser("info")
    p.add_argument("--info", required=True)
    p.add_argument("--summary", required=True)
    a = ap.parse_args()
    if a.cmd == "plycount":
        print(len(read_ply(a.ply)))
    elif a.cmd == "json":
        try:
            v = json.load(open(a.file))[a.key]
        except (ValueError, KeyError) as e:
            fail("%s: cannot get %s (%s)" % (a.file, a.key, e))
        print(json.dumps(v) if not isinstance(v, str) else v)
    else:
        {"geom": cmd_geom, "fraction": cmd_fraction, "ids": cmd_ids, "info": cmd_info}[a.cmd](a)


if __name__ == "__main__":
    main()
