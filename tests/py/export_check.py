#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Independent checks of vdbpack's PLY, CSV and OBJ exports (tests/sh_export.sh).

Parses the binary PLY header and data itself (struct/numpy), the CSV with
numpy, and compares both with a dump of the .vdb made by tests/dump_points
(OpenVDB's API, no vdbpack code) and with positions OpenVDB's vdb_tool
extracted. Every check prints "ok: ..." or exits 1 with "FAIL: ...".

  export_check.py compare DUMP.txt FILE.ply FILE.csv [VDBTOOL.ply]
  export_check.py roundtrip DUMP_A.txt DUMP_B.txt    (B: A through ply, csv, vdb)
  export_check.py obj FILE.obj FILE.csv sphere N | UNIT.obj
"""
import sys

import numpy as np


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


def ok(msg):
    print("  ok: " + msg)


def read_dump(path):
    """id x y z pscale [qx qy qz qw] groups, one line per point, sorted by id."""
    rows = [l.split() for l in open(path) if l.strip()]
    if not rows:
        fail("%s: no points" % path)
    has_q = len(rows[0]) == 10
    ids = np.array([int(r[0]) for r in rows])
    order = np.argsort(ids)
    d = {
        "id": ids[order],
        "P": np.array([[float(v) for v in r[1:4]] for r in rows])[order],
        "pscale": np.array([float(r[4]) for r in rows], dtype=np.float32)[order],
        "group": np.array([r[-1].split(",")[0] for r in rows])[order],
    }
    if has_q:
        d["q"] = np.array([[float(v) for v in r[5:9]] for r in rows], dtype=np.float32)[order]
    return d


def read_ply(path):
    """vdbpack's binary PLY, parsed here: header checked line by line."""
    data = open(path, "rb").read()
    end = data.find(b"end_header\n")
    if end < 0:
        fail("%s: no end_header" % path)
    body = end + len(b"end_header\n")
    lines = data[:body].decode("ascii").split("\n")[:-1]
    if lines[0] != "ply" or lines[1] != "format binary_little_endian 1.0":
        fail("%s: header starts %r" % (path, lines[:2]))
    types = {"float": "<f4", "double": "<f8", "int": "<i4", "uchar": "u1", "ushort": "<u2"}
    n, props, names, shape = None, [], {}, None
    for l in lines[2:-1]:
        w = l.split()
        if w[0] == "comment" and len(w) >= 4 and w[1] == "group":
            names[int(w[2])] = w[3]
        elif w[0] == "comment" and len(w) >= 3 and w[1] == "shape":
            shape = w[2]
        elif w[0] == "element":
            if w[1] != "vertex" or n is not None:
                fail("%s: unexpected element line %r" % (path, l))
            n = int(w[2])
        elif w[0] == "property":
            props.append((w[2], types[w[1]]))
        elif w[0] != "comment":
            fail("%s: unexpected header line %r" % (path, l))
    want = ["x", "y", "z", "pscale", "id"]
    got = [p[0] for p in props]
    if got[:5] != want or got[-1] != "group" or got[5:-1] not in ([], ["orient_x", "orient_y", "orient_z", "orient_w"]):
        fail("%s: properties %s" % (path, got))
    dt = np.dtype(props)
    if len(data) - body != n * dt.itemsize:
        fail("%s: %d data bytes for %d vertices of %d" % (path, len(data) - body, n, dt.itemsize))
    rec = np.frombuffer(data, dtype=dt, count=n, offset=body)
    return rec, names, shape


def read_csv(path):
    a = np.genfromtxt(path, delimiter=",", names=True, dtype=None, encoding="ascii")
    return np.atleast_1d(a)


def by_id(ids, n, what):
    ids = np.asarray(ids).astype(np.int64)
    if len(ids) != n or not np.array_equal(np.sort(ids), np.arange(n)):
        fail("%s: ids are not 0..%d once each" % (what, n - 1))
    return np.argsort(ids)


def cmd_compare(dump, ply, csv, vdbtool=None):
    d = read_dump(dump)
    n = len(d["id"])
    by_id(d["id"], n, dump)
    rec, names, shape = read_ply(ply)
    c = read_csv(csv)
    if len(rec) != n or len(c) != n:
        fail("counts: dump %d, ply %d, csv %d" % (n, len(rec), len(c)))
    ok("%d particles in the dump, the PLY and the CSV" % n)
    r = rec[by_id(rec["id"], n, ply)]
    c = c[by_id(c["id"], n, csv)]
    ok("ids 0..%d once each in PLY and CSV" % (n - 1))
    P = np.stack([c["x"], c["y"], c["z"]], axis=1)
    if not np.array_equal(P, d["P"]):
        fail("CSV positions differ from OpenVDB's (largest %.3g)" % np.abs(P - d["P"]).max())
    ok("CSV positions (%.17g) equal the doubles OpenVDB computes, bit for bit")
    Pf = np.stack([r["x"], r["y"], r["z"]], axis=1)
    if not np.array_equal(Pf, d["P"].astype(np.float32)):
        fail("PLY positions are not the float32 of OpenVDB's (largest %.3g)"
             % np.abs(Pf - d["P"]).max())
    ok("PLY positions equal float32(OpenVDB's positions) exactly")
    if not (np.array_equal(r["pscale"], d["pscale"]) and
            np.array_equal(c["pscale"].astype(np.float32), d["pscale"])):
        fail("pscale differs")
    ok("pscale equal in PLY, CSV and the .vdb (float32)")
    if "q" in d:
        qp = np.stack([r["orient_" + k] for k in "xyzw"], axis=1)
        qc = np.stack([c["q" + k] for k in "xyzw"], axis=1).astype(np.float32)
        if not (np.array_equal(qp, d["q"]) and np.array_equal(qc, d["q"])):
            fail("orient differs (largest %.3g)" % np.abs(qp - d["q"]).max())
        ok("orient (x,y,z,w) equal in PLY, CSV and the .vdb (float32)")
    elif "orient_x" in rec.dtype.names:
        fail("PLY has orient but the .vdb does not")
    gp = np.array([names[int(g)] for g in r["group"]])
    if not (np.array_equal(gp, d["group"]) and np.array_equal(c["group"].astype(str), d["group"])):
        fail("groups differ")
    ok("groups equal (%s)" % ", ".join(sorted(set(d["group"]))))
    if vdbtool:
        # OpenVDB's vdb_tool writes P as float32 in its own order: same set
        v = read_ply_plain(vdbtool).astype(np.float32)
        a = v[np.lexsort(v.T[::-1])]
        b = Pf[np.lexsort(Pf.T[::-1])]
        if a.shape != b.shape or not np.array_equal(a, b):
            fail("vdb_tool's positions differ from the PLY's")
        ok("vdb_tool -vdb2points gives the same %d float32 positions exactly" % n)


def read_ply_plain(path):
    import os
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from vp_check import read_ply as rp
    return rp(path)


def cmd_roundtrip(a, b):
    A, B = read_dump(a), read_dump(b)
    n = len(A["id"])
    if len(B["id"]) != n or not np.array_equal(A["id"], B["id"]):
        fail("count or ids changed: %d -> %d" % (n, len(B["id"])))
    ok("count %d and ids kept" % n)
    if not np.array_equal(A["group"], B["group"]):
        fail("groups changed")
    ok("groups kept")
    err = np.abs(A["P"].astype(np.float32).astype(np.float64) - B["P"]).max()
    scale = max(1.0, np.abs(A["P"]).max())
    if err > 1e-6 * scale:
        fail("positions moved by %.3g (> float precision)" % err)
    ok("positions kept to float precision (largest change %.3g)" % err)
    if not np.array_equal(A["pscale"], B["pscale"]):
        fail("pscale changed")
    if ("q" in A) != ("q" in B) or ("q" in A and not np.array_equal(A["q"], B["q"])):
        fail("orient changed")
    ok("pscale and orient kept exactly")


def cmd_pack_vs_convert(pply, pcsv, cply, ccsv):
    """pack -o writes the packer's doubles, convert the .vdb's: the same but
    for positions, which differ by at most the .vdb's float storage."""
    a, b = read_csv(pcsv), read_csv(ccsv)
    (ra, na, sa), (rb, nb, sb) = read_ply(pply), read_ply(cply)
    if len(a) != len(b) or len(ra) != len(rb) or len(a) != len(ra):
        fail("counts differ")
    for f in a.dtype.names:
        if f not in "xyz" and not np.array_equal(a[f], b[f]):
            fail("CSV column %s differs between pack -o and convert" % f)
    for f in ra.dtype.names:
        if f not in "xyz" and not np.array_equal(ra[f], rb[f]):
            fail("PLY property %s differs between pack -o and convert" % f)
    if na != nb or sa != sb:
        fail("PLY group names or shape differ")
    e = max(np.abs(a[c] - b[c]).max() for c in "xyz")
    ef = max(np.abs(ra[c].astype(float) - rb[c]).max() for c in "xyz")
    if e > 1e-6 or ef > 1e-6:
        fail("positions differ by %.3g (CSV), %.3g (PLY)" % (e, ef))
    ok("pack -o and convert agree (positions within %.2g: the .vdb stores floats)" % max(e, ef))


def quat_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def read_obj(path):
    V, F, objs = [], 0, []
    for l in open(path):
        if l.startswith("v "):
            V.append([float(t) for t in l.split()[1:4]])
        elif l.startswith("f "):
            F += 1
        elif l.startswith("o "):
            objs.append(l.split()[1])
    return np.array(V), F, objs


def cmd_obj(obj, csv, kind, arg=None):
    c = read_csv(csv)
    n = len(c)
    V, F, objs = read_obj(obj)
    if kind == "sphere":
        k = int(arg)
        nv, nf, U = 10 * k * k + 2, 20 * k * k, None
    else:
        U, nf, _ = read_obj(kind)
        nv = len(U)
    if len(V) != n * nv or F != n * nf:
        fail("%s: %d vertices and %d faces, expected %d x (%d, %d)" % (obj, len(V), F, n, nv, nf))
    ok("%d vertices and %d faces = %d particles x (%d, %d)" % (len(V), F, n, nv, nf))
    # particles in group order (first appearance), id order within
    groups = list(dict.fromkeys(c["group"].astype(str)))
    if objs != groups:
        fail("objects %s, groups %s" % (objs, groups))
    order = sorted(range(n), key=lambda i: (groups.index(str(c["group"][i])), int(c["id"][i])))
    worst = 0.0
    for j, i in enumerate(order):
        ctr = np.array([c["x"][i], c["y"][i], c["z"][i]])
        s = float(c["pscale"][i])
        vs = V[j * nv:(j + 1) * nv]
        if U is None:
            e = np.abs(np.linalg.norm(vs - ctr, axis=1) - s).max()
        else:
            R = quat_matrix([c["q" + a][i] for a in "xyzw"])
            e = np.abs(vs - (ctr + s * U @ R.T)).max()
        worst = max(worst, e)
    tol = 1e-6 * max(1.0, np.abs(V).max())
    if worst > tol:
        fail("a vertex is %.3g off its place (tolerance %.3g)" % (worst, tol))
    ok("every vertex %s (largest error %.2g)" % (
        "at distance pscale from its centre" if U is None else
        "= centre + pscale * R(orient) * unit vertex", worst))


if __name__ == "__main__":
    cmd = sys.argv[1]
    if cmd == "compare":
        cmd_compare(*sys.argv[2:])
    elif cmd == "packvsconvert":
        cmd_pack_vs_convert(*sys.argv[2:])
    elif cmd == "roundtrip":
        cmd_roundtrip(*sys.argv[2:])
    elif cmd == "obj":
        cmd_obj(*sys.argv[2:])
    else:
        fail("unknown subcommand " + cmd)
