# SPDX-License-Identifier: Apache-2.0
"""Headless tests of the Blender add-on (blender/vdbpack_blender), run inside
Blender by tests/blender/run.sh:

    blender -b --factory-startup --python-exit-code 1 --python test_addon.py -- SECTION

Each section is one CTest test (blender_SECTION). The expected particles
come from the vdbpack Python module given the same mesh as a file, and the
geometry checks (instances, overlaps, containment) are computed here with
numpy from Blender's evaluated data, not with the add-on's code."""
import atexit
import csv
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import addon_utils
import bpy
import numpy as np

SRC = os.environ["VP_SRC"]
sys.path.insert(0, os.path.join(SRC, "blender"))
import vdbpack  # noqa: E402  (PYTHONPATH: the build's module)

TMP = tempfile.mkdtemp(prefix="vp-blender-")
atexit.register(shutil.rmtree, TMP, True)  # Blender finalizes Python when it quits
FAILS = []
CHECKS = [0]


def check(cond, what):
    CHECKS[0] += 1
    if not cond:
        FAILS.append(what)
        print("FAIL:", what)
    return cond


def fresh():
    """An empty scene with the add-on enabled and default settings."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    addon_utils.enable("vdbpack_blender", default_set=True)
    assert hasattr(bpy.context.scene, "vdbpack"), "the add-on did not register"
    return bpy.context.scene.vdbpack


def activate(obj):
    for o in bpy.context.view_layer.objects:
        o.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj


def results(source):
    return [o for o in bpy.data.objects if o.get("vdbpack_source") == source]


def world_obj(obj, path):
    """The evaluated mesh of obj in world space as an OBJ file, computed
    here (float64 sums of Blender's float32 matrix and vertices)."""
    ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    me.calc_loop_triangles()
    m = [[float(obj.matrix_world[i][j]) for j in range(4)] for i in range(3)]
    with open(path, "w") as f:
        for v in me.vertices:
            x, y, z = (float(c) for c in v.co)
            w = [m[i][0] * x + m[i][1] * y + m[i][2] * z + m[i][3] for i in range(3)]
            f.write("v %r %r %r\n" % tuple(w))
        for t in me.loop_triangles:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t.vertices))
    ev.to_mesh_clear()
    return path


def attrs(obj):
    """Positions, pscale, orient (or None), group of a particle object."""
    me = obj.data
    n = len(me.vertices)
    co = np.empty(3 * n, np.float32)
    me.vertices.foreach_get("co", co)
    out = {"P": co.reshape(-1, 3)}
    for name, width, field, dt in (("pscale", 1, "value", np.float32), ("id", 1, "value", np.int32),
                                   ("group", 1, "value", np.int32),
                                   ("orient", 4, "color", np.float32),
                                   ("rotation", 3, "vector", np.float32)):
        if name in me.attributes:
            a = np.empty(width * n, dt)
            me.attributes[name].data.foreach_get(field, a)
            out[name] = a.reshape(-1, width) if width > 1 else a
    return out


def same_particles(obj, expected, what):
    """The particle object holds `expected` (a vdbpack.Packing) exactly, at
    the float32 precision of Blender's attributes."""
    a = attrs(obj)
    ok = check(len(a["P"]) == len(expected), "%s: %d particles, expected %d"
               % (what, len(a["P"]), len(expected)))
    if not ok or not len(expected):
        return
    check(np.array_equal(a["P"], expected.positions.astype(np.float32)),
          "%s: positions differ (max %g)" % (what, np.abs(a["P"] - expected.positions).max()))
    check(np.array_equal(a["pscale"], expected.radii.astype(np.float32)), what + ": pscale differ")
    check(np.array_equal(a["id"], expected.ids), what + ": ids differ")
    check(np.array_equal(a["group"], expected.groups), what + ": groups differ")
    if expected.orient is not None:
        check("orient" in a and np.array_equal(a["orient"], expected.orient.astype(np.float32)),
              what + ": orient differ")
    names = obj.get("vdbpack_groups", "").split(",")
    check(names == list(expected.group_names), "%s: groups %s, expected %s"
          % (what, names, expected.group_names))
    for g, name in enumerate(expected.group_names):
        b = np.empty(len(expected), bool)
        obj.data.attributes[name].data.foreach_get("value", b)
        check(np.array_equal(b, expected.groups == g), "%s: boolean attribute %s" % (what, name))


def fill(expect_ok=True):
    """bpy.ops.vdbpack.fill(); returns (result set, error text or None)."""
    try:
        return bpy.ops.vdbpack.fill(), None
    except RuntimeError as e:  # an ERROR report raised by bpy.ops in a script
        if expect_ok:
            check(False, "fill failed: %s" % e)
        return {'CANCELLED'}, str(e)


def set_passes(s, passes):
    s.passes.clear()
    for p in passes:
        q = s.passes.add()
        for k, v in p.items():
            setattr(q, k, v)


def test_cube(location=(0.0, 0.0, 0.0), scale=2.0):
    """A cube with a level-2 Subdivision Surface modifier, scaled by a power
    of two: its world-space vertices are then exact in float32, so its OBJ
    (which Assimp reads as float32) is the very mesh the add-on hands over."""
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=location)
    obj = bpy.context.active_object
    obj.name = "Container"
    obj.scale = (scale, scale, scale)
    mod = obj.modifiers.new("subsurf", 'SUBSURF')
    mod.levels = 2
    activate(obj)
    return obj


def test_bar():
    """A moved and scaled box (vertices +-0.5, not Blender's primitive,
    whose coordinates are a little off) with an Array modifier that adds a
    second box beside it: every world-space coordinate is a short dyadic
    number, exact in float32, so its OBJ is the very mesh the add-on hands
    over. (Subdivision modifiers compute in float32 and round.)"""
    me = bpy.data.meshes.new("Bar")
    me.from_pydata([(x, y, z) for x in (-0.5, 0.5) for y in (-0.5, 0.5) for z in (-0.5, 0.5)],
                   [], [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4),
                        (1, 5, 7, 3)])
    obj = bpy.data.objects.new("Bar", me)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = (4.0, -2.0, 1.5)
    obj.scale = (1.5, 1.0, 2.0)
    mod = obj.modifiers.new("array", 'ARRAY')  # a second box, 0.5 (local) beside the first
    mod.use_relative_offset = False
    mod.use_constant_offset = True
    mod.constant_offset_displace = (1.5, 0.0, 0.0)
    obj.modifiers.new("triangulate", 'TRIANGULATE')
    activate(obj)
    return obj


# ---------------------------------------------------------------------------


def section_fill():
    """Every method (and the mesh-object shape) against vdbpack.pack on the
    same mesh as a file, with the same settings and seed."""
    s = fresh()
    obj = test_cube()
    path = world_obj(obj, os.path.join(TMP, "container.obj"))
    cases = [
        ("lattice spheres", dict(method="lattice", shape="sphere", size_by="RADIUS", radius=0.09,
                                 lattice="bcc", seed=3),
         dict(method="lattice", radius=0.09, lattice="bcc", seed=3)),
        ("lattice octahedra by count", dict(method="lattice", shape="octahedron", size_by="COUNT",
                                            count=300, lattice="default", seed=1),
         dict(method="lattice", shape="octahedron", count=300, seed=1)),
        ("rsa cubes, passes", dict(method="rsa", shape="cube", seed=11, fit="inside"),
         dict(method="rsa", shape="cube", seed=11,
              passes=[{"count": 40, "radius": 0.15, "name": "large", "grow": True},
                      {"count": 400, "radius": "uniform:0.04:0.06", "retries": 2000}])),
        ("relax spheres", dict(method="relax", shape="sphere", radius=0.05, count=800,
                               distribution="lognormal:0.05:0.01", use_target_fraction=True,
                               target_fraction=0.5, seed=5),
         dict(method="relax", radius="lognormal:0.05:0.01", count=800, target_fraction=0.5,
              seed=5)),
        ("rsa spheres, centre fit, max pass", dict(method="rsa", shape="sphere", fit="center",
                                                   seed=2),
         dict(method="rsa", fit="center", seed=2,
              passes=[{"count": 20, "radius": 0.2}, {"count": "max", "radius": 0.1}])),
    ]
    passes_of = {"rsa cubes, passes": [
        dict(count=40, radius=0.15, name="large", grow=True),
        dict(count=400, distribution="uniform:0.04:0.06", retries=2000)],
        "rsa spheres, centre fit, max pass": [dict(count=20, radius=0.2),
                                              dict(maximal=True, radius=0.1)]}
    if "jam" in vdbpack.METHODS:
        cases.append(("jam spheres", dict(method="jam", shape="sphere", radius=0.05, count=500,
                                          seed=4),
                      dict(method="jam", radius=0.05, count=500, seed=4)))
    else:
        print("NOTE: this vdbpack has no jam method; its case is not run")
    for what, panel, kwargs in cases:
        s.passes.clear()
        s.distribution = ""
        s.use_target_fraction = False
        s.fit = "inside"
        for k, v in panel.items():
            setattr(s, k, v)
        set_passes(s, passes_of.get(what, []))
        activate(obj)
        t0 = time.perf_counter()
        r, err = fill()
        t_addon = time.perf_counter() - t0
        if not check(r == {'FINISHED'}, "%s: fill gave %s %s" % (what, r, err)):
            continue
        t0 = time.perf_counter()
        expected = vdbpack.pack(path, **kwargs)
        t_module = time.perf_counter() - t0
        res = results("Container")
        check(len(res) == 1, "%s: %d result objects" % (what, len(res)))
        same_particles(res[0], expected, what)
        check(res[0]["vdbpack_shape"] == expected.shape, what + ": vdbpack_shape")
        check(("%d particles" % len(expected)) in s.report and s.report_ok,
              "%s: report %r" % (what, s.report))
        print("%-36s %6d particles, add-on %.2f s, module from file %.2f s"
              % (what, len(expected), t_addon, t_module))

    # moved, scaled, modifiers applied: world space as the module sees the file
    bar = test_bar()
    bar_path = world_obj(bar, os.path.join(TMP, "bar.obj"))
    s.method, s.shape, s.seed, s.fit = "rsa", "dodecahedron", 12, "inside"
    s.distribution = ""
    set_passes(s, [dict(count=300, radius=0.1, grow=True)])
    activate(bar)
    r, err = fill()
    if check(r == {'FINISHED'}, "bar: %s %s" % (r, err)):
        expected = vdbpack.pack(bar_path, method="rsa", shape="dodecahedron", seed=12,
                                passes=[{"count": 300, "radius": 0.1, "grow": True}])
        same_particles(results("Bar")[0], expected, "moved boxes (array modifier)")
        a = attrs(results("Bar")[0])
        # the two boxes in world space: x in [3.25, 4.75] and [5.5, 7], y, z
        lo, hi = np.array([3.25, -2.5, 0.5]), np.array([7.0, -1.5, 2.5])
        x = a["P"][:, 0]
        # a dodecahedron's inradius is 0.7947 of its circumradius (pscale)
        gap = np.minimum(np.minimum(a["P"] - lo, hi - a["P"]).min(axis=1),
                         np.where(x < 5.125, 4.75 - x, x - 5.5)) - 0.79 * a["pscale"]
        check(gap.min() > -1e-5, "bar: a particle's inscribed sphere leaves the moved boxes by %g"
              % -gap.min())
        check((x < 4.75).sum() > 50 and (x > 5.5).sum() > 50,
              "bar: %d and %d particles in the two boxes" % ((x < 4.75).sum(), (x > 5.5).sum()))
        check(len(bpy.data.objects["Bar"].data.polygons) == 6, "bar: its mesh was changed")
        print("%-36s %6d particles in world space, %d triangles handed over"
              % ("moved boxes (array modifier)", len(expected),
                 sum(1 for l in open(bar_path) if l.startswith("f "))))

    # a mesh object of the scene as the particle: a cone, in its own space
    bpy.ops.mesh.primitive_cone_add(vertices=8, radius1=1.0, depth=2.0, location=(9, 9, 9))
    cone = bpy.context.active_object
    cone.name = "Rock"
    cone.rotation_euler = (0.3, 0.2, 0.1)  # not part of the shape: its object space is
    ev = cone.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    ev.calc_loop_triangles()
    shape_path = os.path.join(TMP, "Rock.obj")
    with open(shape_path, "w") as f:
        for v in ev.vertices:
            f.write("v %r %r %r\n" % tuple(float(c) for c in v.co))
        for t in ev.loop_triangles:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t.vertices))
    s.method, s.shape, s.shape_object, s.seed = "rsa", "OBJECT", cone, 6
    set_passes(s, [dict(count=150, radius=0.12)])
    activate(obj)
    r, err = fill()
    if check(r == {'FINISHED'}, "mesh shape: %s %s" % (r, err)):
        expected = vdbpack.pack(path, method="rsa", shape=vdbpack.MeshShape.from_file(shape_path),
                                seed=6, passes=[{"count": 150, "radius": 0.12}])
        same_particles(results("Container")[0], expected, "rsa, mesh object shape")

    # peanut.obj imported with Blender's OBJ importer, axes unchanged
    s = fresh()
    bpy.ops.wm.obj_import(filepath=os.path.join(SRC, "vdb_samples", "peanut.obj"),
                          forward_axis='Y', up_axis='Z')
    peanut = bpy.context.selected_objects[0]
    activate(peanut)
    for what, panel, kwargs in (
            ("peanut rsa", dict(method="rsa", shape="icosahedron", seed=8),
             dict(method="rsa", shape="icosahedron", seed=8,
                  passes=[{"count": 300, "radius": 0.05, "grow": True}])),
            ("peanut lattice", dict(method="lattice", shape="sphere", size_by="COUNT", count=2000),
             dict(method="lattice", count=2000))):
        for k, v in panel.items():
            setattr(s, k, v)
        set_passes(s, [dict(count=300, radius=0.05, grow=True)] if panel["method"] == "rsa"
                   else [])
        r, err = fill()
        if check(r == {'FINISHED'}, "%s: %s %s" % (what, r, err)):
            expected = vdbpack.pack(os.path.join(SRC, "vdb_samples", "peanut.obj"), **kwargs)
            same_particles(results(peanut.name)[0], expected, what + " (vdb_samples/peanut.obj)")


def quat_matrix(q):
    """Rotation matrices (N, 3, 3) of unit quaternions (x, y, z, w)."""
    x, y, z, w = (q[:, i].astype(np.float64) for i in range(4))
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)], 1),
        np.stack([2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)], 1),
        np.stack([2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1)], 1)


def realized(obj):
    """The evaluated vertices of obj with a Realize Instances node added
    before its modifier's output (the test's own change)."""
    ng = obj.modifiers["vdbpack instances"].node_group
    out = [n for n in ng.nodes if n.type == 'GROUP_OUTPUT'][0]
    link = out.inputs[0].links[0]
    real = ng.nodes.new('GeometryNodeRealizeInstances')
    ng.links.new(link.from_socket, real.inputs[0])
    ng.links.new(real.outputs[0], out.inputs[0])
    ev = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    v = np.empty(3 * len(me.vertices), np.float32)
    me.vertices.foreach_get("co", v)
    polys = [tuple(p.vertices) for p in me.polygons]
    ev.to_mesh_clear()
    return v.reshape(-1, 3).astype(np.float64), polys


def read_obj(path):
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(v), f


def sat_overlaps(V, faces, pairs, eps):
    """For each pair (i, j) of convex polyhedra V[i], V[j] (vertex arrays of
    one shape, faces as index lists): whether they overlap by more than
    eps[pair], i.e. no separating axis among both shapes' face normals and
    the cross products of their edges."""
    f = np.array([face[:3] for face in faces])
    edges = sorted({tuple(sorted((face[i], face[(i + 1) % len(face)])))
                    for face in faces for i in range(len(face))})
    e = np.array(edges)
    out = []
    for c in range(0, len(pairs), 100):
        p = pairs[c:c + 100]
        A, B = V[p[:, 0]], V[p[:, 1]]

        def normals(X):
            return np.cross(X[:, f[:, 1]] - X[:, f[:, 0]], X[:, f[:, 2]] - X[:, f[:, 0]])
        eA, eB = A[:, e[:, 1]] - A[:, e[:, 0]], B[:, e[:, 1]] - B[:, e[:, 0]]
        cr = np.cross(eA[:, :, None], eB[:, None, :]).reshape(len(p), -1, 3)
        axes = np.concatenate([normals(A), normals(B), cr], axis=1)
        ln = np.linalg.norm(axes, axis=2)
        ok = ln > 1e-9 * ln.max()
        # parallel edges give no axis: use a face normal instead (already tested)
        axes = np.where(ok[:, :, None], axes / np.where(ok, ln, 1)[:, :, None], axes[:, :1] /
                        ln[:, :1, None])
        pa = np.einsum("pxc,pkc->pxk", axes, A)
        pb = np.einsum("pxc,pkc->pxk", axes, B)
        tol = eps[c:c + 100, None]
        sep = (pa.max(2) <= pb.min(2) + tol) | (pb.max(2) <= pa.min(2) + tol)
        out.append(~sep.any(axis=1))
    return np.concatenate(out) if out else np.zeros(0, bool)


def section_instances():
    """Realized instances are P + pscale R(orient) v for every vertex v of
    the library's unit shape; no two overlap (separating axes for solids,
    centre distances for spheres)."""
    s = fresh()
    obj = test_cube(location=(0, 0, 0), scale=1.0)
    for shape, method in (("cube", "rsa"), ("tetrahedron", "rsa"), ("icosahedron", "lattice"),
                          ("sphere", "rsa")):
        s.method, s.shape, s.seed = method, shape, 9
        s.size_by, s.radius = "RADIUS", 0.07
        set_passes(s, [dict(count=40, radius=0.1), dict(count=200, radius=0.05)])
        activate(obj)
        r, err = fill()
        if not check(r == {'FINISHED'}, "%s: %s %s" % (shape, r, err)):
            continue
        res = results("Container")[0]
        a = attrs(res)
        n = len(a["P"])
        V, polys = realized(res)
        if shape == "sphere":
            segs, rings = 32, 16
            k = segs * (rings - 1) + 2
            ok = check(len(V) == n * k, "spheres: %d realized vertices, expected %d x %d"
                       % (len(V), n, k))
            if ok:
                d = np.linalg.norm(V.reshape(n, k, 3) - a["P"][:, None, :], axis=2)
                err = np.abs(d - a["pscale"][:, None]).max()
                check(err < 1e-5, "spheres: vertices off the sphere of radius pscale by %g" % err)
            P, R = a["P"].astype(np.float64), a["pscale"].astype(np.float64)
            dist = np.linalg.norm(P[:, None] - P[None], axis=2)
            np.fill_diagonal(dist, np.inf)
            gap = (dist - (R[:, None] + R[None])).min()
            check(gap > -1e-6, "spheres: centre distance below the radii's sum by %g" % -gap)
            print("spheres: %d, smallest gap %.3g" % (n, gap))
            continue
        unit_path = os.path.join(TMP, shape + ".obj")
        vdbpack.Packing(np.zeros((1, 3)), [1.0], [[0, 0, 0, 1]], shape=shape).write_shape(
            unit_path)
        u, faces = read_obj(unit_path)
        k = len(u)
        if not check(len(V) == n * k, "%s: %d realized vertices, expected %d x %d"
                     % (shape, len(V), n, k)):
            continue
        Rm = quat_matrix(a["orient"])
        want = a["P"][:, None, :] + a["pscale"][:, None, None] * np.einsum("nij,kj->nki", Rm, u)
        err = np.abs(V.reshape(n, k, 3) - want).max()
        check(err < 2e-5, "%s: realized vertices differ from P + pscale R(orient) v by %g"
              % (shape, err))
        # every pair whose bounding spheres meet, by separating axes
        Vn = V.reshape(n, k, 3)
        P, R = a["P"].astype(np.float64), a["pscale"].astype(np.float64)
        dist = np.linalg.norm(P[:, None] - P[None], axis=2)
        close = np.argwhere(np.triu(dist < R[:, None] + R[None], 1))
        over = sat_overlaps(Vn, faces, close, 1e-5 * (R[close[:, 0]] + R[close[:, 1]]))
        bad = close[over]
        check(not len(bad), "%s: %d overlapping pairs by separating axes, e.g. %s"
              % (shape, len(bad), bad[:3].tolist()))
        # the check can fail: the same instances each pushed halfway to its
        # nearest close neighbour overlap
        if len(close):
            i, j = close[0]
            moved = Vn.copy()
            moved[i] += 0.5 * (P[j] - P[i])
            check(sat_overlaps(moved, faces, close[:1], np.array([0.0]))[0],
                  "%s: the separating-axis check misses a planted overlap" % shape)
        print("%s: %d particles, %d vertices each, max deviation %.2g, %d close pairs tested"
              % (shape, n, k, err, len(close)))


def section_rerun():
    """A re-run replaces the earlier result; a rotated container is filled
    in world space; the container itself is untouched."""
    s = fresh()
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=(1, 2, 3), rotation=(0.4, -0.3, 0.7))
    box = bpy.context.active_object
    box.name = "Box"
    before = np.empty(3 * len(box.data.vertices), np.float32)
    box.data.vertices.foreach_get("co", before)
    s.method, s.shape, s.seed = "rsa", "cube", 1
    set_passes(s, [dict(count=200, radius=0.1)])
    for k in range(3):
        activate(box)
        r, err = fill()
        check(r == {'FINISHED'}, "run %d: %s %s" % (k, r, err))
        s.seed += 1
    res = results("Box")
    check(len(res) == 1, "after three runs, %d result objects (expected 1)" % len(res))
    check(len([m for m in bpy.data.meshes if m.name.startswith("Box particles")]) == 1,
          "meshes of earlier results remain: %s" % [m.name for m in bpy.data.meshes])
    check(len([g for g in bpy.data.node_groups if g.name.startswith("vdbpack")]) == 1,
          "node groups of earlier results remain: %s" % [g.name for g in bpy.data.node_groups])
    after = np.empty_like(before)
    box.data.vertices.foreach_get("co", after)
    check(np.array_equal(before, after) and len(box.modifiers) == 0, "the container changed")
    o = res[0]
    check(o["vdbpack_source"] == "Box", "vdbpack_source is %r" % o.get("vdbpack_source"))
    a = attrs(o)
    # every particle's bounding sphere inside the box (half size 1) in its frame
    M = np.array(box.matrix_world, np.float64)
    local = (a["P"].astype(np.float64) - M[:3, 3]) @ M[:3, :3]
    # a cube's inscribed sphere is 1/sqrt(3) of its bounding sphere (pscale)
    worst = (np.abs(local).max(axis=1) + a["pscale"] / math.sqrt(3) - 1.0).max()
    check(worst < 1e-4, "a particle's inscribed sphere leaves the rotated box by %g" % worst)
    check(len(a["P"]) == 200, "rotated box: %d particles" % len(a["P"]))
    print("rotated box: 200 cubes inside (worst %.3g), one result after 3 runs" % worst)


def section_cancel():
    """Cancelling (as Esc does, through the library's progress) leaves no
    object, mesh or node group, and the earlier result as it was."""
    s = fresh()
    obj = test_cube(location=(0, 0, 0), scale=1.0)
    s.method, s.shape = "rsa", "sphere"
    set_passes(s, [dict(count=100, radius=0.05)])
    fill()
    first = attrs(results("Container")[0])
    counts = (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.node_groups))
    set_passes(s, [dict(count=100000, radius=0.008)])  # a job of some seconds
    activate(obj)
    t0 = time.perf_counter()
    r = bpy.ops.vdbpack.fill(cancel_at=0.3, cancel_stage="rsa")
    t = time.perf_counter() - t0
    check(r == {'CANCELLED'}, "cancelled fill returned %s" % r)
    check("cancelled (rsa, 3" in s.report, "report after cancel: %r" % s.report)
    now = (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.node_groups))
    check(now == counts, "objects, meshes, node groups %s before, %s after" % (counts, now))
    res = results("Container")
    check(len(res) == 1 and np.array_equal(attrs(res[0])["P"], first["P"]),
          "the earlier result is gone or changed")
    check(t < 30, "cancelling took %.1f s" % t)
    print("%s; %d objects as before" % (s.report, counts[0]))


def expect_error(what, needle):
    r, err = fill(expect_ok=False)
    ok = check(r == {'CANCELLED'} and err is not None and needle in err,
               "%s: %s, report %r (expected one containing %r)" % (what, r, err, needle))
    check(err is None or "Traceback" not in err, what + ": a traceback in the report")
    if ok:
        print("%-28s -> %s" % (what, err.strip().splitlines()[-1]))
    return err


def section_errors():
    s = fresh()
    s.method, s.shape, s.size_by, s.radius = "lattice", "sphere", "RADIUS", 0.1
    bpy.ops.curve.primitive_bezier_circle_add()
    activate(bpy.context.active_object)
    expect_error("a curve", "is a curve, not a mesh")
    bpy.ops.object.empty_add()
    activate(bpy.context.active_object)
    expect_error("an empty", "is a empty, not a mesh")
    me = bpy.data.meshes.new("nothing")
    o = bpy.data.objects.new("Nothing", me)
    bpy.context.scene.collection.objects.link(o)
    activate(o)
    expect_error("an empty mesh", "has no faces")
    me = bpy.data.meshes.new("dots")
    me.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [])
    o = bpy.data.objects.new("Dots", me)
    bpy.context.scene.collection.objects.link(o)
    activate(o)
    expect_error("vertices only", "has no faces")
    # a flat open mesh: the library's own message, as vdbpack.pack gives it
    bpy.ops.mesh.primitive_plane_add(size=2)
    plane = bpy.context.active_object
    activate(plane)
    err = expect_error("a plane (open, flat)", "vdbpack: ")
    try:
        vdbpack.pack(world_obj(plane, os.path.join(TMP, "plane.obj")), radius=0.1)
        check(False, "the module packs a plane")
    except vdbpack.Error as e:  # the same words after the container's name
        words = e.message.split(": ", 1)[1]
        check(err is not None and "Plane: " + words in err,
              "plane: report %r lacks the library's %r" % (err, words))
    # an open mesh with a volume: a cube missing its top face is filled
    # (inside by winding number, as the library decides)
    bpy.ops.mesh.primitive_cube_add(size=2, location=(5, 0, 0))
    open_box = bpy.context.active_object
    open_box.name = "OpenBox"
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.select_all(action='DESELECT')
    bpy.ops.object.mode_set(mode='OBJECT')
    top = max(open_box.data.polygons, key=lambda p: p.center.z)
    top.select = True
    bpy.ops.object.mode_set(mode='EDIT')
    bpy.ops.mesh.delete(type='ONLY_FACE')
    bpy.ops.object.mode_set(mode='OBJECT')
    activate(open_box)
    r, err = fill(expect_ok=False)
    if r == {'FINISHED'}:
        n = len(results("OpenBox")[0].data.vertices)
        expected = vdbpack.pack(world_obj(open_box, os.path.join(TMP, "open.obj")), radius=0.1)
        check(n == len(expected), "open box: %d particles, the module %d" % (n, len(expected)))
        print("open box (5 faces) filled by winding number: %d particles" % n)
    else:
        check(err is not None and "vdbpack:" in err, "open box: %r" % err)
    # settings that cannot pack, and a library refusal
    bpy.ops.mesh.primitive_cube_add(size=2, location=(0, 5, 0))
    cube = bpy.context.active_object
    activate(cube)
    s.method, s.shape = "relax", "cube"
    expect_error("relax with cubes", "packs spheres only")
    s.method, s.shape = "rsa", "OBJECT"
    expect_error("mesh shape without object", "choose the particle's mesh object")
    s.shape = "sphere"
    set_passes(s, [dict(maximal=True, distribution="uniform:0.1:0.2")])
    # (refused before issue 31: "single radius"; now it fills until no room is
    # left for the smallest radius of the distribution)
    r, err = fill()
    check(r == {'FINISHED'} and err is None,
          "max with a distribution: %s, report %r (expected it to fill)" % (r, err))
    set_passes(s, [dict(count=10, radius=5.0)])
    err = expect_error("particles too large", "vdbpack: ")
    try:
        vdbpack.pack(world_obj(cube, os.path.join(TMP, "c.obj")), method="rsa",
                     passes=[{"count": 10, "radius": 5.0}])
        check(False, "the module packs radius 5 in a cube of size 2")
    except vdbpack.Error as e:
        check(err is not None and e.message in err, "radius 5: report %r lacks %r"
              % (err, e.message))
    set_passes(s, [dict(count=10, distribution="uniform:0.3:0.1")])
    expect_error("a bad distribution", "uniform")
    check(not s.report_ok and s.report, "the panel's report does not show the error")


def dump(path):
    """dump_points (OpenVDB's API only): id -> (P, pscale, orient, group)."""
    out = subprocess.run([os.environ["VP_DUMP_POINTS"], path], check=True,
                         capture_output=True, text=True).stdout
    rows = {}
    for line in out.splitlines():
        f = line.split()
        rows[int(f[0])] = ([float(x) for x in f[1:4]], float(f[4]),
                           [float(x) for x in f[5:9]] if len(f) > 6 else None, f[-1])
    return rows


def section_io():
    """Import of a .vdb written by the command line (and its .ply and
    .csv), compared with what OpenVDB's API and the CSV text hold; export
    back to .vdb, read with OpenVDB's API."""
    fresh()
    cli = os.environ["VDBPACK"]
    vdb = os.path.join(TMP, "cli.vdb")
    subprocess.run([cli, "pack", os.path.join(SRC, "vdb_samples", "peanut.obj"), "--method", "rsa",
                    "--shape", "octahedron", "--pass", "count=50,radius=0.12,name=big",
                    "--pass", "count=400,radius=0.05", "--seed", "3", "-o", vdb],
                   check=True, capture_output=True)
    for ext in ("csv", "ply"):
        subprocess.run([cli, "convert", vdb, vdb[:-3] + ext], check=True, capture_output=True)
    want = dump(vdb)
    rows = list(csv.DictReader(open(vdb[:-3] + "csv")))
    check(len(rows) == len(want) == 450, "CLI wrote %d / %d particles" % (len(rows), len(want)))
    for ext in ("vdb", "ply", "csv"):
        path = vdb[:-3] + ext
        kw = {"shape": "octahedron"} if ext == "csv" else {}
        try:
            r = bpy.ops.vdbpack.import_packing(filepath=path, **kw)
        except RuntimeError as e:
            check(False, "import %s: %s" % (ext, e))
            continue
        check(r == {'FINISHED'}, "import %s: %s" % (ext, r))
        obj = results("cli." + ext)[0]
        a = attrs(obj)
        ids = a["id"]
        P = np.array([want[i][0] for i in ids], np.float32)
        pscale = np.array([want[i][1] for i in ids], np.float32)
        orient = np.array([want[i][2] for i in ids], np.float32)
        names = obj["vdbpack_groups"].split(",")
        groups = [names[g] for g in a["group"]]
        ok = check(len(ids) == 450 and sorted(ids) == list(range(450)), ext + ": ids")
        if ok:
            check(np.abs(a["P"] - P).max() <= 1e-6, "%s: positions off by %g"
                  % (ext, np.abs(a["P"] - P).max()))
            check(np.array_equal(a["pscale"], pscale), ext + ": pscale")
            check(np.abs(np.abs((a["orient"] * orient).sum(1)) - 1).max() < 1e-6,
                  ext + ": orient")
            check(groups == [want[i][3] for i in ids], ext + ": groups")
            check(np.array_equal(a["P"][ids.argsort()],
                                 np.array([[float(r[k]) for k in "xyz"] for r in rows],
                                          np.float32)), ext + ": positions against the CSV text")
        check(obj.modifiers["vdbpack instances"].node_group is not None, ext + ": instancer")
        print("imported %s: %d octahedra, groups %s" % (ext, len(ids), names))
    # export the .vdb import (moved by the user) back to .vdb
    obj = results("cli.vdb")[0]
    obj.location = (1.0, 0.0, 0.0)
    activate(obj)
    out = os.path.join(TMP, "export.vdb")
    r = bpy.ops.vdbpack.export_packing(filepath=out)
    check(r == {'FINISHED'}, "export: %s" % r)
    got = dump(out)
    check(sorted(got) == sorted(want), "export: ids %d" % len(got))
    errs = [max(abs(got[i][0][k] - want[i][0][k] - (1.0 if k == 0 else 0.0)) for k in range(3))
            for i in want]
    check(max(errs) < 1e-6, "export: positions off by %g" % max(errs))
    check(all(abs(got[i][1] - want[i][1]) < 1e-7 and got[i][3] == want[i][3] for i in want),
          "export: pscale or groups differ")
    check(all(abs(abs(np.dot(got[i][2], want[i][2])) - 1) < 1e-6 for i in want),
          "export: orient differ")
    info = subprocess.run([cli, "info", out], capture_output=True, text=True)
    check(info.returncode == 0 and "octahedron" in info.stdout,
          "vdbpack info on the export: %s%s" % (info.stdout, info.stderr))
    # errors: a missing file, not a packing
    for bad, needle in ((os.path.join(TMP, "missing.vdb"), "missing.vdb"),
                        (os.path.join(SRC, "vdb_samples", "sphere_ls.vdb"), "vdbpack: ")):
        try:
            bpy.ops.vdbpack.import_packing(filepath=bad)
            check(False, "importing %s succeeded" % bad)
        except RuntimeError as e:
            check(needle in str(e) and "Traceback" not in str(e), "import %s: %s" % (bad, e))
            print("import %s -> %s" % (os.path.basename(bad), str(e).strip().splitlines()[-1]))


def section_images():
    """Workbench renders of filled meshes for docs/blender.md, written to
    $VP_BLENDER_IMAGES (the build folder; VP_BLENDER_DOC_IMAGES=1 also to
    docs/img), and checked: particles cover part of the frame."""
    outdir = os.environ.get("VP_BLENDER_IMAGES", TMP)
    os.makedirs(outdir, exist_ok=True)
    shots = []
    s = fresh()
    bpy.ops.wm.obj_import(filepath=os.path.join(SRC, "vdb_samples", "peanut.obj"),
                          forward_axis='Y', up_axis='Z')
    peanut = bpy.context.selected_objects[0]
    s.method, s.shape, s.seed = "rsa", "icosahedron", 2
    set_passes(s, [dict(count=60, radius=0.12, name="large", grow=True),
                   dict(count=1500, radius=0.045, name="small")])
    activate(peanut)
    fill()
    shots.append(("blender-rsa-passes", peanut, "large"))
    s = bpy.context.scene.vdbpack
    bpy.ops.mesh.primitive_torus_add(major_radius=1.0, minor_radius=0.45, location=(3.2, 0, 0.4))
    torus = bpy.context.active_object
    s.method, s.shape = "rsa", "cube"
    set_passes(s, [dict(count=400, radius=0.1, grow=True, name="cubes")])
    activate(torus)
    fill()
    shots.append(("blender-rsa-cubes", torus, None))
    sc = bpy.context.scene
    sc.render.engine = 'BLENDER_WORKBENCH'
    sc.display.shading.light = 'STUDIO'
    sc.render.resolution_x, sc.render.resolution_y = 480, 300
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    sc.render.image_settings.color_mode = 'RGB'
    sc.render.image_settings.compression = 100
    sc.world = bpy.data.worlds.new("grey")
    sc.world.color = (0.18, 0.18, 0.2)
    res_objs = {o["vdbpack_source"]: o for o in bpy.data.objects if o.get("vdbpack_source")}
    res_objs[torus.name].color = (0.3, 0.55, 0.85, 1)
    # the peanut's passes in two colours (the test's own nodes: realized
    # instances, a material where the boolean attribute "large" is set)
    sc.display.shading.color_type = 'MATERIAL'
    ng = res_objs[peanut.name].modifiers["vdbpack instances"].node_group
    out = [n for n in ng.nodes if n.type == 'GROUP_OUTPUT'][0]
    src = out.inputs[0].links[0].from_socket
    real = ng.nodes.new('GeometryNodeRealizeInstances')
    mats = []
    for name, rgb in (("small", (0.3, 0.55, 0.85)), ("large", (0.9, 0.45, 0.15))):
        m = bpy.data.materials.new(name)
        m.diffuse_color = rgb + (1.0,)
        mats.append(m)
    set_all = ng.nodes.new('GeometryNodeSetMaterial')
    set_all.inputs["Material"].default_value = mats[0]
    set_large = ng.nodes.new('GeometryNodeSetMaterial')
    set_large.inputs["Material"].default_value = mats[1]
    sel = ng.nodes.new('GeometryNodeInputNamedAttribute')
    sel.data_type = 'BOOLEAN'
    sel.inputs["Name"].default_value = "large"
    ng.links.new(src, real.inputs[0])
    ng.links.new(real.outputs[0], set_all.inputs["Geometry"])
    ng.links.new(set_all.outputs[0], set_large.inputs["Geometry"])
    ng.links.new([o for o in sel.outputs if o.enabled][0], set_large.inputs["Selection"])
    ng.links.new(set_large.outputs[0], out.inputs[0])
    mt = bpy.data.materials.new("cubes")
    mt.diffuse_color = (0.3, 0.55, 0.85, 1)
    bpy.data.objects["vdbpack shape cube"].data.materials.append(mt)
    cam_data = bpy.data.cameras.new("cam")
    cam = bpy.data.objects.new("cam", cam_data)
    sc.collection.objects.link(cam)
    sc.camera = cam
    import mathutils
    for name, target, _g in shots:
        for o in (peanut, torus):  # the particles alone; the container would hide them
            res_objs[o.name].hide_render = o is not target
            o.hide_render = True
        c = mathutils.Vector(target.location) + mathutils.Vector((0, 0, 0))
        if target is peanut:
            c = mathutils.Vector([(a + b) / 2 for a, b in zip(
                [min(v.co[k] for v in peanut.data.vertices) for k in range(3)],
                [max(v.co[k] for v in peanut.data.vertices) for k in range(3)])])
        size = max(target.dimensions)
        cam.location = c + mathutils.Vector((1.2, -1.6, 1.0)) * size * 0.9
        cam.rotation_euler = (c - cam.location).to_track_quat('-Z', 'Y').to_euler()
        cam_data.lens = 45
        path = os.path.join(outdir, name + ".png")
        sc.render.filepath = path
        bpy.ops.render.render(write_still=True)
        img = bpy.data.images.load(path)
        px = np.empty(len(img.pixels), np.float32)
        img.pixels.foreach_get(px)
        rgb = px.reshape(-1, 4)[:, :3]
        bg = rgb[0]
        cover = (np.abs(rgb - bg).sum(1) > 0.05).mean()
        check(0.05 < cover < 0.95, "%s: %.0f%% of the frame differs from the background"
              % (name, 100 * cover))
        print("%s: %s, %.0f%% covered" % (name, path, 100 * cover))
        if os.environ.get("VP_BLENDER_DOC_IMAGES") == "1":
            shutil.copy(path, os.path.join(SRC, "docs", "img", name + ".png"))


class FakeLayout:
    """Stands in for Blender's UILayout (there is none headless): records
    the properties and operators drawn and checks each property exists."""
    def __init__(self, log):
        self.log = log

    def __getattr__(self, name):  # use_property_split, active, alert, scale_y, ...
        return None

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)

    def _sub(self, *a, **k):
        return FakeLayout(self.log)
    row = column = box = _sub

    def prop(self, data, name, **k):
        check(hasattr(data, name) or name in data.bl_rna.properties,
              "the panel draws a property %r that does not exist" % name)
        self.log.append(("prop", name))

    def label(self, text="", **k):
        self.log.append(("label", text))

    def operator(self, idname, **k):
        mod, _, op = idname.partition(".")
        check(hasattr(getattr(bpy.ops, mod), op), "the panel's operator %s exists" % idname)
        self.log.append(("operator", idname))
        return FakeLayout(self.log)

    def template_list(self, listtype, _id, data, prop, active_data, active_prop, **k):
        check(hasattr(bpy.types, listtype), "UIList %s registered" % listtype)
        ul = getattr(bpy.types, listtype)
        for i, item in enumerate(getattr(data, prop)):
            ul.draw_item(None, bpy.context, FakeLayout(self.log), data, item, 0, active_data,
                         active_prop, i)
        self.log.append(("list", prop))

    def separator(self, **k):
        pass


def section_panel():
    """The sidebar panel draws, for every method and shape, the settings
    that method takes (through a stand-in layout: headless Blender has no
    UI to draw into), and the report of the last run."""
    s = fresh()
    panel = bpy.types.VDBPACK_PT_panel
    check(panel.bl_category == "vdbpack" and panel.bl_region_type == 'UI'
          and panel.bl_space_type == 'VIEW_3D', "the panel is not in the sidebar's vdbpack tab")
    want = {"lattice": {"lattice", "size_by", "radius"}, "rsa": {"orient"},
            "relax": {"radius", "distribution", "count", "use_target_fraction"}}
    common = {"method", "shape", "fit", "seed", "voxel_size", "threads"}
    set_passes(s, [dict(count=10, radius=0.1, name="a"), dict(maximal=True, radius=0.05)])
    for method in [m for m in ("lattice", "rsa", "relax", "jam") if m in vdbpack.METHODS]:
        for shape in ("sphere", "cube", "OBJECT"):
            s.method, s.shape = method, shape
            log = []
            fake = type("P", (), {})()
            fake.layout = FakeLayout(log)
            panel.draw(fake, bpy.context)
            props = {n for k, n in log if k == "prop"}
            need = common | want.get(method, set()) | ({"shape_object"} if shape == "OBJECT"
                                                       else set())
            if method == "rsa" and shape == "sphere":
                need = need - {"orient"}
            check(need <= props, "%s/%s: the panel lacks %s" % (method, shape, need - props))
            if method == "rsa":
                check(("list", "passes") in log, "rsa: no pass list")
                check(any(k == "label" and n == "pass2" for k, n in log),
                      "rsa: the unnamed second pass is not shown as pass2")
            check(("operator", "vdbpack.fill") in log, "%s: no Fill button" % method)
    s.report, s.report_ok = "12 particles, fraction 0.5000, 0.10 s", True
    log = []
    fake = type("P", (), {})()
    fake.layout = FakeLayout(log)
    panel.draw(fake, bpy.context)
    check(("label", "fraction 0.5000") in log, "the report is not shown: %s" % log[-4:])
    # the scripting example of docs/blender.md runs as written, on a peanut
    s = fresh()
    bpy.ops.wm.obj_import(filepath=os.path.join(SRC, "vdb_samples", "peanut.obj"),
                          forward_axis='Y', up_axis='Z')
    peanut = bpy.context.selected_objects[0]
    peanut.name = "Peanut"
    activate(peanut)
    doc = open(os.path.join(SRC, "docs", "blender.md")).read()
    blocks = doc.split("```python\n")[1:]
    check(len(blocks) == 1, "docs/blender.md has %d python blocks (expected 1)" % len(blocks))
    scope = {}
    exec(blocks[0].split("```")[0], scope)
    check(scope["obj"]["vdbpack_source"] == "Peanut" and len(scope["obj"].data.vertices) > 50,
          "the docs' example made no packing of Peanut")
    check(s.report.startswith("%d particles" % len(scope["obj"].data.vertices)),
          "the docs' example's report: %r" % s.report)
    print("docs/blender.md example: %s" % s.report)
    print("panel: drawn for %d methods x 3 shapes" % len([m for m in ("lattice", "rsa", "relax",
                                                                      "jam")
                                                          if m in vdbpack.METHODS]))


def superball_inside(u, p):
    """|x|^2p + |y|^2p + |z|^2p of points u (N, 3) in the frame of a
    superball of exponent p scaled to bounding radius 1 (computed here:
    the unscaled superball's bounding radius is 1 for p <= 1, else that of
    its corner, 3^(1/2 - 1/2p)): < 1 inside, 1 on the surface."""
    c = 1.0 if p <= 1 else 3.0 ** (0.5 - 0.5 / p)
    return (np.abs(u * c) ** (2 * p)).sum(axis=-1)


def section_superball():
    """Superballs (Shape: Superball, its Exponent): a fill equals
    vdbpack.pack(shape="superball:P") on the same mesh as a file; the
    realized instances are P + pscale R(orient) v for every vertex v of the
    library's tessellation, whose vertices lie on the superball's surface;
    no vertex of one particle is inside another; the Exponent is drawn for
    superballs only; Relax refuses them."""
    s = fresh()
    obj = test_cube(location=(0, 0, 0), scale=1.0)
    path = world_obj(obj, os.path.join(TMP, "sb_container.obj"))
    for what, panel, kwargs in (
            ("rsa superball:2", dict(method="rsa", superball_exponent=2.0, seed=4),
             dict(method="rsa", shape="superball:2", seed=4,
                  passes=[{"count": 30, "radius": 0.1, "grow": True},
                          {"count": 150, "radius": 0.05}])),
            ("lattice superball:0.75", dict(method="lattice", superball_exponent=0.75,
                                            size_by="COUNT", count=150, seed=1),
             dict(method="lattice", shape="superball:0.75", count=150, seed=1))):
        s.shape = "superball"
        for k, v in panel.items():
            setattr(s, k, v)
        set_passes(s, [dict(count=30, radius=0.1, grow=True), dict(count=150, radius=0.05)]
                   if panel["method"] == "rsa" else [])
        activate(obj)
        r, err = fill()
        if not check(r == {'FINISHED'}, "%s: fill gave %s %s" % (what, r, err)):
            continue
        expected = vdbpack.pack(path, **kwargs)
        res = results("Container")[0]
        same_particles(res, expected, what)
        check(res["vdbpack_shape"] == kwargs["shape"] == expected.shape,
              "%s: vdbpack_shape %r" % (what, res.get("vdbpack_shape")))
        pexp = float(kwargs["shape"].split(":")[1])
        a = attrs(res)
        n = len(a["P"])
        V, _ = realized(res)
        unit_path = os.path.join(TMP, "superball.obj")
        vdbpack.Packing(np.zeros((1, 3)), [1.0], [[0, 0, 0, 1]], shape=kwargs["shape"]) \
            .write_shape(unit_path)
        u, _faces = read_obj(unit_path)
        k = len(u)
        f = superball_inside(u, pexp)
        check(np.abs(f - 1).max() < 1e-6 and k > 100,
              "%s: %d unit vertices, off the surface by up to %g" % (what, k, np.abs(f - 1).max()))
        if not check(len(V) == n * k, "%s: %d realized vertices, expected %d x %d"
                     % (what, len(V), n, k)):
            continue
        Rm = quat_matrix(a["orient"])
        want = a["P"][:, None, :] + a["pscale"][:, None, None] * np.einsum("nij,kj->nki", Rm, u)
        dev = np.abs(V.reshape(n, k, 3) - want).max()
        check(dev < 2e-5, "%s: realized vertices differ from P + pscale R(orient) v by %g"
              % (what, dev))
        # no realized vertex of a particle inside another particle (in the
        # other's frame, by the superball's own inequality)
        Vn = V.reshape(n, k, 3)
        P, R = a["P"].astype(np.float64), a["pscale"].astype(np.float64)
        dist = np.linalg.norm(P[:, None] - P[None], axis=2)
        close = np.argwhere(np.triu(dist < R[:, None] + R[None], 1))

        def inside(i, j, X):
            loc = (X - P[j]) @ Rm[j] / R[j]  # world to j's unit frame (R^T (x - P))
            return superball_inside(loc, pexp).min() < 1 - 1e-4
        bad = [(i, j) for i, j in close if inside(i, j, Vn[i]) or inside(j, i, Vn[j])]
        check(not bad, "%s: %d pairs with a vertex inside the other, e.g. %s"
              % (what, len(bad), bad[:3]))
        if len(close):  # the test can fail: one moved halfway to its neighbour
            i, j = close[0]
            check(inside(i, j, Vn[i] + 0.5 * (P[j] - P[i])),
                  "%s: the vertex test misses a planted overlap" % what)
        print("%-24s %4d particles, %d vertices each, max deviation %.2g, %d close pairs"
              % (what, n, k, dev, len(close)))
    # the panel: Exponent with superballs only
    panel = bpy.types.VDBPACK_PT_panel
    for shape in ("superball", "cube", "sphere"):
        s.method, s.shape = "rsa", shape
        log = []
        fake = type("P", (), {})()
        fake.layout = FakeLayout(log)
        panel.draw(fake, bpy.context)
        shown = ("prop", "superball_exponent") in log
        check(shown == (shape == "superball"), "%s: Exponent shown: %s" % (shape, shown))
    items = [i.identifier for i in s.bl_rna.properties["shape"].enum_items]
    check(len(items) == 21 and "superball" in items and "snub-dodecahedron" in items,
          "the shape list is not sphere, 18 solids, superball, object: %s" % items)
    s.method, s.shape, s.count, s.radius = "relax", "superball", 100, 0.05
    activate(obj)
    expect_error("relax superballs", "packs spheres only")
    # import: a .vdb records the exponent; a .csv takes it from the operator
    balls = vdbpack.pack("box:1,1,1", method="rsa", shape="superball:3", radius=0.1, count=40)
    for ext, kw in ((".vdb", {}), (".csv", dict(shape="superball", superball_exponent=3.0))):
        f = os.path.join(TMP, "balls" + ext)
        balls.write(f)
        r = bpy.ops.vdbpack.import_packing(filepath=f, **kw)
        got = [o for o in bpy.data.objects if o.get("vdbpack_source") == "balls" + ext]
        if check(r == {'FINISHED'} and len(got) == 1, "import %s: %s" % (ext, r)):
            check(got[0]["vdbpack_shape"] == "superball:3" and len(got[0].data.vertices) == 40
                  and "vdbpack shape superball:3" in bpy.data.objects,
                  "import %s: shape %r" % (ext, got[0].get("vdbpack_shape")))


SECTIONS = {"fill": section_fill, "instances": section_instances, "rerun": section_rerun,
            "cancel": section_cancel, "errors": section_errors, "io": section_io,
            "images": section_images, "panel": section_panel, "superball": section_superball}


def main():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else list(SECTIONS)
    t0 = time.perf_counter()
    for name in argv:
        print("== %s" % name)
        SECTIONS[name]()
    print("%d checks, %d failed, %.1f s" % (CHECKS[0], len(FAILS), time.perf_counter() - t0))
    if FAILS or not CHECKS[0]:
        sys.exit(1)


main()
