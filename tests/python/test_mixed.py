# SPDX-License-Identifier: Apache-2.0
"""Several shapes in one packing (rsa passes with shapes of their own,
docs/rsa.md "Several shapes in one packing"; docs/python.md): the Python
pack of a ternary set (cubes, a mesh shape from peanut.obj, grown
spheres) is the command line's for the same passes and seed, down to the
CSV's bytes; the files (.vdb, .ply, .csv) keep each particle's shape and
the list of shapes; check, render, write_shape and the OBJ export take
mixed sets; bad pass shapes fail with the command line's words."""
import json
import os
import warnings

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, assert_same_particles, run_cli

PEANUT = os.path.join(SAMPLES, "peanut.obj")
BOX_OBJ = os.path.join(SAMPLES, "box.obj")
CLI_PASSES = ["--pass", "count=60,radius=0.1,shape=cube",
              "--pass", "count=250,radius=0.06,shape=" + PEANUT,
              "--pass", "count=max,radius=0.025,grow"]
PASSES = [{"count": 60, "radius": 0.1, "shape": "cube"},
          {"count": 250, "radius": 0.06, "shape": PEANUT},
          "count=max,radius=0.025,grow"]
SHAPES = ["cube", "mesh:peanut.obj", "sphere"]


def read_shapes_column(path):
    """The CSV's shape column (the name of each particle's shape)."""
    lines = open(path, encoding="ascii").read().splitlines()
    assert lines[0].split(",")[-1] == "shape"
    return [ln.rsplit(",", 1)[1] for ln in lines[1:]]


@pytest.fixture(scope="module")
def ternary(tmp_path_factory):
    """The command line's ternary packing (CSV, .vdb, --json, --shape-out)
    and Python's of the same passes (1 thread against the CLI's 2)."""
    d = tmp_path_factory.mktemp("ternary")
    r = run_cli("pack", "box:1,1,1", "--method", "rsa", *CLI_PASSES, "-o", d / "cli.csv",
                "--json", "--threads", "2", "--shape-out", d / "cli_shapes.obj")
    want = json.loads(r.stdout)
    run_cli("pack", "box:1,1,1", "--method", "rsa", *CLI_PASSES, "-o", d / "cli.vdb", "-q")
    p = vdbpack.pack("box:1,1,1", method="rsa", passes=PASSES, threads=1)
    return d, want, p


def test_ternary_is_the_clis(ternary):
    d, want, p = ternary
    assert p.shape == "mixed" and p.shapes == SHAPES
    assert p.shape_index.dtype == np.uint8 and p.shape_index.shape == (len(p),)
    assert isinstance(p.mesh_shapes[1], vdbpack.MeshShape)
    assert p.mesh_shapes[1].name == "peanut.obj"
    assert p.mesh_shapes[0] is None and p.mesh_shapes[2] is None
    assert p.mesh_shape is None
    # positions bit for bit, float32 radii and orientations, groups ...
    assert_same_particles(p, d / "cli.csv")
    # ... and each particle's shape: the pass's
    names = read_shapes_column(d / "cli.csv")
    assert [p.shapes[k] for k in p.shape_index] == names
    counts = np.bincount(p.shape_index, minlength=3)
    assert counts[0] == 60 and counts[1] == 250 and counts[2] > 1000
    np.testing.assert_array_equal(p.shape_index, p.groups)  # one pass, one shape here
    # the file Python writes is the command line's, byte for byte
    p.write(d / "py.csv")
    assert (d / "py.csv").read_bytes() == (d / "cli.csv").read_bytes()
    # the report as --json: the shapes with their counts, each pass's shape
    assert p.report["shape"] == want["shape"] == "mixed"
    assert [dict(s) for s in p.report["shapes"]] == want["shapes"]
    assert [q["shape"] for q in p.report["passes"]] == [q["shape"] for q in want["passes"]] \
        == SHAPES
    assert p.report["orient"] == want["orient"] and p.report["overlap"] == want["overlap"]
    assert p.report["count"] == want["count"]
    assert p.report["packing_fraction"] == want["packing_fraction"]
    for mine, theirs in zip(p.report["passes"], want["passes"]):
        for key in ("group", "radius", "requested", "maximal", "placed", "stop", "tries",
                    "grow", "grow_mean"):
            assert mine[key] == theirs[key], key
    assert "shape_file" not in p.report and "shape_file" not in p.metadata


def test_vdb_metadata_is_the_clis(ternary, tmp_path):
    d, _, p = ternary
    p.write(tmp_path / "py.vdb")
    meta = {f: json.loads(run_cli("info", path, "--json").stdout)["metadata"]
            for f, path in (("cli", d / "cli.vdb"), ("py", tmp_path / "py.vdb"))}
    for key in ("shape", "shapes", "passes", "orient", "overlap", "particle_count",
                "packing_fraction", "max_radius", "method", "seed"):
        assert meta["py"][key] == meta["cli"][key], key
    assert meta["py"]["shape"] == "mixed"
    assert meta["py"]["shapes"] == ";".join(SHAPES)
    # the particles: the command line's convert of both files gives one CSV
    for f, path in (("cli", d / "cli.vdb"), ("py", tmp_path / "py.vdb")):
        run_cli("convert", path, tmp_path / (f + ".csv"), "-q")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


@pytest.mark.parametrize("ext", ["vdb", "ply", "csv"])
def test_files_keep_the_shapes(ternary, tmp_path, ext):
    _, _, p = ternary
    f = tmp_path / ("t." + ext)
    p.write(f)
    back = vdbpack.read(f)
    assert back.shape == "mixed" and back.shapes == SHAPES
    np.testing.assert_array_equal(back.shape_index, p.shape_index)
    assert back.shape_index.dtype == np.uint8
    assert back.mesh_shapes == [None, None, None]  # a file records the mesh's name only
    assert back.group_names == p.group_names
    np.testing.assert_array_equal(back.groups, p.groups)
    np.testing.assert_array_equal(back.radii.astype(np.float32), p.radii.astype(np.float32))
    np.testing.assert_array_equal(back.orient.astype(np.float32), p.orient.astype(np.float32))
    if ext == "csv":
        np.testing.assert_array_equal(back.positions, p.positions)
    else:
        assert np.abs(back.positions - p.positions).max() <= max(back.position_error, 1e-7)
    # without its mesh, what needs the mesh says how to give it
    assert back.fraction is None
    with pytest.raises(ValueError, match=r"mesh_shapes\[1\].*shape=\[MeshShape"):
        back.check("box:1,1,1")
    with pytest.raises(ValueError, match="mesh:peanut.obj"):
        back.write(tmp_path / "x.obj")
    # with it (once per mesh shape, as the command line's --shape)
    m = vdbpack.MeshShape.from_file(PEANUT)
    full = vdbpack.read(f, shape=[m])
    assert full.mesh_shapes[1] is m and full.shapes == SHAPES
    if ext == "vdb":
        assert full.fraction == pytest.approx(p.fraction, rel=1e-6)
    assert vdbpack.read(f, shape=m).mesh_shapes[1] is m  # one mesh shape: also alone
    # written again, the same file (the shapes written from the arrays)
    if ext != "vdb":
        again = tmp_path / ("again." + ext)
        full.write(again)
        assert again.read_bytes() == f.read_bytes()


def test_read_the_clis_files_with_their_meshes(ternary, tmp_path):
    d, _, p = ternary
    m = vdbpack.MeshShape.from_file(PEANUT)
    back = vdbpack.read(d / "cli.vdb", shape=[m])
    assert back.shapes == SHAPES and back.mesh_shapes[1] is m
    np.testing.assert_array_equal(back.shape_index, p.shape_index)
    csv = vdbpack.read(d / "cli.csv")
    assert csv.shapes == SHAPES
    np.testing.assert_array_equal(csv.shape_index, p.shape_index)
    # errors: the wrong number of meshes, a name for a file that records its shapes
    with pytest.raises(ValueError, match="holds 1 mesh shape"):
        vdbpack.read(d / "cli.vdb", shape=[m, m])
    with pytest.raises(ValueError, match="records its shapes"):
        vdbpack.read(d / "cli.csv", shape="cube")
    with pytest.raises(TypeError, match=r"shape\[0\]"):
        vdbpack.read(d / "cli.vdb", shape=["peanut.obj"])
    # another mesh than the recorded one: a warning, as the command line's
    other = vdbpack.MeshShape.from_file(BOX_OBJ)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        b = vdbpack.read(d / "cli.vdb", shape=[other])
    assert any("was the mesh shape 'peanut.obj', not 'box.obj'" in str(x.message) for x in w)
    assert b.shapes[1] == "mesh:box.obj"


def test_check_is_the_clis(ternary, tmp_path):
    """The .vdb read back checks as `vdbpack check --shape peanut.obj`
    checks it: no overlap, nothing outside, the same contacts."""
    d, _, p = ternary
    want = json.loads(run_cli("check", d / "cli.vdb", "--container", "box:1,1,1", "--shape",
                              PEANUT, "--json").stdout)
    assert want["ok"] and want["overlapping_pairs"] == 0
    back = vdbpack.read(d / "cli.vdb", shape=[vdbpack.MeshShape.from_file(PEANUT)])
    r = back.check("box:1,1,1")
    assert r.ok and r.shape == "mixed"
    for key in ("count", "overlapping_pairs", "outside", "contact_pairs", "packing_fraction",
                "max_overlap", "position_error"):
        assert r[key] == want[key], key
    # the packing in memory (exact positions): no overlap beyond 1e-5 of the
    # smaller radius, nothing outside, the same contacts
    mine = p.check("box:1,1,1", overlap_tolerance=1e-5)
    assert mine.ok and mine.outside == 0 and mine.overlapping_pairs == 0
    assert mine.contact_pairs == want["contact_pairs"]


def test_a_planted_overlap_is_found(ternary):
    """A sphere moved onto a cube: the check of the mixed set sees it."""
    _, _, p = ternary
    q = vdbpack.Packing(p.positions.copy(), p.radii, p.orient, p.groups, p.group_names,
                        "mixed", shapes=p.shapes, shape_index=p.shape_index,
                        mesh_shapes=p.mesh_shapes)
    cube = int(np.flatnonzero(p.shape_index == 0)[0])
    sphere = int(np.flatnonzero(p.shape_index == 2)[0])
    # inside the cube's insphere (the cube of bounding radius r has inradius r/sqrt(3))
    q.positions[sphere] = p.positions[cube] + [0.0, 0.0, 0.5 * p.radii[cube] / np.sqrt(3)]
    r = q.check("box:1,1,1")
    assert not r.ok and r.overlapping_pairs >= 1


def test_write_shape_and_obj(ternary, tmp_path):
    d, _, p = ternary
    p.write_shape(tmp_path / "shapes.obj")  # vp_particles_write_shapes_obj
    assert (tmp_path / "shapes.obj").read_bytes() == (d / "cli_shapes.obj").read_bytes()
    groups = [ln for ln in open(tmp_path / "shapes.obj") if ln.startswith("g ")]
    assert groups == ["g shape0\n", "g shape1\n", "g shape2\n"]
    v, faces = p.shape_mesh(1)  # the mesh shape's triangles
    assert v.shape[1] == 3 and len(faces) == p.mesh_shapes[1].triangles
    v, faces = p.shape_mesh(0)  # the cube
    assert v.shape == (8, 3) and len(faces) == 6
    with pytest.raises(ValueError, match="sphere"):
        p.shape_mesh(2)
    with pytest.raises(ValueError, match="index"):
        p.shape_mesh()
    # every particle's surface (a few of each shape: the file is large)
    pick = np.concatenate([np.flatnonzero(p.shape_index == k)[:3] for k in range(3)])
    few = vdbpack.Packing(p.positions[pick], p.radii[pick], p.orient[pick], p.groups[pick],
                          p.group_names, "mixed", shapes=p.shapes,
                          shape_index=p.shape_index[pick], mesh_shapes=p.mesh_shapes)
    few.write(tmp_path / "few.obj")
    text = open(tmp_path / "few.obj").read()
    assert text.count("\nv ") > 3 * p.mesh_shapes[1].triangles // 2


def test_render(ternary, tmp_path):
    _, _, p = ternary
    img = p.render(tmp_path / "m.png", size="320x180", cut="z:0", ao=0)
    ids = img.id[img.id != 0xFFFFFFFF]
    assert len(ids) and (tmp_path / "m.png").stat().st_size > 0
    assert set(p.shape_index[np.unique(ids)].tolist()) == {0, 1, 2}


def test_one_shape_passes_make_a_one_shape_packing():
    """Passes of one shape: an ordinary packing of it, the one shape=
    makes; a mesh file named twice is read once (one shape)."""
    a = vdbpack.pack("box:1,1,1", method="rsa", passes=[
        {"count": 20, "radius": 0.1, "shape": "cube"}, "count=50,radius=0.05,shape=cube"])
    b = vdbpack.pack("box:1,1,1", method="rsa", shape="cube",
                     passes=[{"count": 20, "radius": 0.1}, "count=50,radius=0.05"])
    assert a.shape == b.shape == "cube" and a.shapes is None and a.shape_index is None
    np.testing.assert_array_equal(a.positions, b.positions)
    np.testing.assert_array_equal(a.orient, b.orient)
    m = vdbpack.pack("sphere:1", method="rsa", shape=PEANUT, passes=[
        {"count": 10, "radius": 0.15, "shape": PEANUT}, {"count": 20, "radius": 0.1}])
    assert m.shape == "mesh" and m.mesh_shape.name == "peanut.obj"
    assert m.metadata["shape_file"] == "peanut.obj" and m.report["shape_file"] == "peanut.obj"
    # a MeshShape object in two passes is one shape too
    ms = vdbpack.MeshShape.from_file(PEANUT)
    n = vdbpack.pack("sphere:1", method="rsa", passes=[
        {"count": 10, "radius": 0.15, "shape": ms}, {"count": 20, "radius": 0.1, "shape": ms}])
    assert n.shape == "mesh" and n.mesh_shape is ms
    np.testing.assert_array_equal(n.positions, m.positions)
    # every pass of another mesh than shape='s: that mesh is the packing's
    o = vdbpack.pack("sphere:1", method="rsa", shape=PEANUT, passes=[
        {"count": 10, "radius": 0.15, "shape": BOX_OBJ}])
    assert o.shape == "mesh" and o.mesh_shape.name == "box.obj"
    assert o.metadata["shape_file"] == "box.obj" and o.report["passes"][0]["shape"] == \
        "mesh:box.obj"


def test_a_mesh_file_in_two_passes_is_one_shape(tmp_path):
    """Passes naming one file share its mesh (read once): one shape of the
    set, as the command line's; the packing's call names MeshShapes by name."""
    passes = ["count=8,radius=0.2,shape=" + PEANUT, "count=20,radius=0.1,shape=cube",
              "count=30,radius=0.08,shape=" + PEANUT]
    p = vdbpack.pack("sphere:1", method="rsa", passes=passes)
    assert p.shapes == ["mesh:peanut.obj", "cube"]
    assert [q["shape"] for q in p.report["passes"]] == ["mesh:peanut.obj", "cube",
                                                        "mesh:peanut.obj"]
    np.testing.assert_array_equal(np.bincount(p.shape_index), [38, 20])
    args = [a for t in passes for a in ("--pass", t)]
    run_cli("pack", "sphere:1", "--method", "rsa", *args, "-o", tmp_path / "cli.csv", "-q")
    p.write(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    ms = vdbpack.MeshShape.from_file(PEANUT)
    q = vdbpack.pack("sphere:1", method="rsa", passes=[
        {"count": 8, "radius": 0.2, "shape": ms}, "count=20,radius=0.1,shape=cube",
        {"count": 30, "radius": 0.08, "shape": ms}])
    assert q.mesh_shapes == [ms, None]
    np.testing.assert_array_equal(q.positions, p.positions)
    assert "'shape': 'peanut.obj'" in q.metadata["command_line"]


def test_mesh_shape_objects_and_superballs(tmp_path):
    ms = vdbpack.MeshShape.from_file(BOX_OBJ)
    p = vdbpack.pack("sphere:1", method="rsa", seed=3, passes=[
        {"count": 15, "radius": 0.2, "shape": ms},
        "count=40,radius=0.1,shape=superball:2",
        {"count": 60, "radius": 0.07, "shape": "octahedron"}])
    assert p.shapes == ["mesh:box.obj", "superball:2", "octahedron"]
    assert p.mesh_shapes[0] is ms
    assert p.metadata["passes"].split(";")[0].endswith(",shape=box.obj")
    run_cli("pack", "sphere:1", "--method", "rsa", "--seed", "3",
            "--pass", "count=15,radius=0.2,shape=" + BOX_OBJ,
            "--pass", "count=40,radius=0.1,shape=superball:2",
            "--pass", "count=60,radius=0.07,shape=octahedron", "-o", tmp_path / "cli.csv", "-q")
    p.write(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    assert p.check("sphere:1", overlap_tolerance=1e-5).overlapping_pairs == 0
    # a mixed Packing made from arrays, a MeshShape in its shapes
    q = vdbpack.Packing(p.positions, p.radii, p.orient, shape="mixed",
                        shapes=[ms, "superball:2", "octahedron"], shape_index=p.shape_index)
    assert q.shapes == p.shapes and q.mesh_shapes == [ms, None, None]
    q.write(tmp_path / "q.csv")
    back = vdbpack.read(tmp_path / "q.csv", shape=[ms])
    np.testing.assert_array_equal(back.shape_index, p.shape_index)
    assert repr(back) == "<vdbpack.Packing of %d particles of 3 shapes>" % len(p)


BAD_PASSES = [
    ({"shape": "superball:0.3"}, ValueError,
     r"passes\[1\]: shape 'superball:0.3': a superball's exponent P must be a number in "
     r"\[0.5, 1000\]"),
    ({"shape": "superball:nan"}, ValueError, "superball's exponent"),
    ({"shape": "cubee"}, ValueError,
     r"passes\[1\]: shape 'cubee' is no shape name \(.*\) and no file"),
    ({"shape": "no-such.obj"}, ValueError, "'no-such.obj' is no shape name"),
    ({"shape": ""}, ValueError, "shape needs a value"),
    ({"shape": 3}, TypeError, "shape must be a shape name"),
    ({"shape": "mixed"}, ValueError, "'mixed' is no shape name"),
]


@pytest.mark.parametrize("extra,exc,msg", BAD_PASSES, ids=[str(b[0]["shape"]) for b in BAD_PASSES])
def test_bad_pass_shapes(extra, exc, msg):
    passes = [{"count": 3, "radius": 0.1, "shape": "cube"}, dict(count=5, radius=0.05, **extra)]
    with pytest.raises(exc, match=msg):
        vdbpack.pack("box:1,1,1", method="rsa", passes=passes)


def test_bad_pass_shapes_as_text():
    with pytest.raises(ValueError, match="shape needs a value"):
        vdbpack.pack("box:1,1,1", method="rsa", passes=["count=5,radius=0.1,shape="])
    with pytest.raises(ValueError, match="shape is given twice"):
        vdbpack.pack("box:1,1,1", method="rsa", passes=["count=5,radius=0.1,shape=cube,shape=cube"])
    with pytest.raises(ValueError, match=r"unknown field 'shap' \(count, radius, retries, grow, "
                                         r"name, shape\)"):
        vdbpack.pack("box:1,1,1", method="rsa", passes=["count=5,radius=0.1,shap=cube"])


def test_open_mesh_pass_shape(tmp_path):
    f = tmp_path / "open.obj"
    f.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n")
    r = run_cli("pack", "box:1,1,1", "--method", "rsa", "--pass", "count=3,radius=0.1",
                "--pass", "count=5,radius=0.05,shape=%s" % f, "-o", tmp_path / "x.csv",
                check=False)
    assert r.returncode == 1 and "not closed" in r.stderr
    with pytest.raises(vdbpack.OpenMeshError, match=r"passes\[1\]: .*not closed"):
        vdbpack.pack("box:1,1,1", method="rsa", passes=[
            {"count": 3, "radius": 0.1}, {"count": 5, "radius": 0.05, "shape": str(f)}])


def test_margin_and_gap_with_pass_shapes(tmp_path):
    # kept by solids and mixed sets; a gap is refused with a mesh pass
    p = vdbpack.pack("box:1,1,1", method="rsa", seed=2, margin=0.02, gap=0.01, passes=[
        {"count": 20, "radius": 0.1, "shape": "cube"}, {"count": 40, "radius": 0.05, "grow": True}])
    assert p.shape == "mixed"
    c = p.check("box:1,1,1")
    assert c["overlapping_pairs"] == 0 and c["outside"] == 0, c
    with pytest.raises(ValueError, match="not a mesh shape"):
        vdbpack.pack("box:1,1,1", method="rsa", gap=0.01, passes=[
            {"count": 3, "radius": 0.1, "shape": os.path.join(SAMPLES, "peanut.obj")},
            {"count": 5, "radius": 0.05}])


@pytest.mark.parametrize("kw,msg", [
    (dict(overlap="bbox"), "overlap='bbox' takes one shape"),
    (dict(density_field="d.vdb"), "radius_field and density_field pack spheres in this "
                                  "version, not passes with a shape of their own"),
])
def test_options_that_take_one_shape(kw, msg):
    passes = [{"count": 3, "radius": 0.1, "shape": "cube"}, {"count": 5, "radius": 0.05}]
    with pytest.raises(ValueError, match=msg):
        vdbpack.pack("box:1,1,1", method="rsa", passes=passes, **kw)


def test_orient_goes_with_a_solid_pass():
    # spheres only: orient is refused, as --orient is
    with pytest.raises(ValueError, match="other than sphere"):
        vdbpack.pack("box:1,1,1", method="rsa", orient="fixed",
                     passes=[{"count": 3, "radius": 0.1, "shape": "sphere"}])
    # a pass of cubes: orient is taken
    p = vdbpack.pack("box:1,1,1", method="rsa", orient="fixed", passes=[
        {"count": 3, "radius": 0.1, "shape": "cube"}, {"count": 5, "radius": 0.05}])
    assert p.shape == "mixed" and p.report["orient"] == "fixed"
    np.testing.assert_array_equal(p.orient, np.tile([0.0, 0.0, 0.0, 1.0], (len(p), 1)))


def test_bad_mixed_arrays():
    p = vdbpack.Packing(np.zeros((2, 3)) + [[0, 0, 0], [0.3, 0, 0]], [0.1, 0.1], shape="mixed",
                        shapes=["cube", "sphere"], shape_index=[0, 2])
    with pytest.raises(ValueError, match=r"shape_index must hold indices into shapes \(0..1\)"):
        p.check("box:1,1,1")
    p.shape_index = np.array([0, 1])
    assert p.check("box:1,1,1").ok  # no orient given: the identity
    p.shapes = ["cube", "blob"]
    with pytest.raises(ValueError, match=r"shapes\[1\]: unknown shape 'blob'"):
        p.check("box:1,1,1")
    p.shapes = None
    with pytest.raises(TypeError, match="needs shapes"):
        p.write("x.csv")
