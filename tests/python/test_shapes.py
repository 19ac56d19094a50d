# SPDX-License-Identifier: Apache-2.0
"""Every built-in shape the command line takes (the sphere, the platonic
and Archimedean solids, superball:P) through vdbpack.pack: the same
particles as `vdbpack pack --shape ...` for the same settings and seed, the
shape named on the Packing, in its report and in the files it writes as the
command line names it, files that `vdbpack check` passes; and a bad shape
is one ValueError with the command line's words."""
import json
import os

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, assert_same_particles, read_csv, run_cli

PEANUT = os.path.join(SAMPLES, "peanut.obj")

CASES = [
    # id, container, CLI options, pack() keywords
    ("lattice-superball2-count", "box:1,1,1", ["--shape", "superball:2", "--count", "300"],
     dict(shape="superball:2", count=300)),
    ("lattice-superball0.7-radius", "sphere:1", ["--shape", "superball:0.7", "--radius", "0.15"],
     dict(shape="superball:0.7", radius=0.15)),
    ("lattice-superball2-peanut", PEANUT, ["--shape", "superball:2", "--radius", "0.1"],
     dict(shape="superball:2", radius=0.1)),
    ("rsa-superball2-peanut", PEANUT,
     ["--method", "rsa", "--shape", "superball:2", "--radius", "0.1", "--count", "150",
      "--seed", "5"],
     dict(shape="superball:2", radius=0.1, count=150, seed=5)),
    ("rsa-superball3-passes-grow", "box:1,1,1",
     ["--method", "rsa", "--shape", "superball:3", "--pass", "count=20,radius=0.15,grow",
      "--pass", "count=100,radius=0.07"],
     dict(shape="superball:3", passes=["count=20,radius=0.15,grow", "count=100,radius=0.07"])),
    ("lattice-truncated-octahedron", "box:1,1,1",
     ["--shape", "truncated-octahedron", "--count", "200"],
     dict(shape="truncated-octahedron", count=200)),
    ("rsa-snub-cube", "sphere:1",
     ["--method", "rsa", "--shape", "snub-cube", "--radius", "0.12", "--count", "100"],
     dict(shape="snub-cube", radius=0.12, count=100)),
]


def _method(cli_args):
    return cli_args[cli_args.index("--method") + 1] if "--method" in cli_args else "lattice"


@pytest.mark.parametrize("name,container,cli_args,kwargs", CASES, ids=[c[0] for c in CASES])
def test_same_particles_and_files_as_the_cli(tmp_path, cli, name, container, cli_args, kwargs):
    shape = kwargs["shape"]
    run_cli("pack", container, *cli_args, "-o", tmp_path / "cli.csv", "-q", "--threads", "2")
    run_cli("pack", container, *cli_args, "-o", tmp_path / "cli.vdb", "-q", "--allow-short",
            "--shape-out", tmp_path / "cli_shape.obj")
    p = vdbpack.pack(container, method=_method(cli_args), threads=1, **kwargs)
    assert len(p) > 20
    assert_same_particles(p, tmp_path / "cli.csv")  # positions, pscale, orient (float32), groups
    assert p.orient is not None
    assert p.shape == p.report["shape"] == p.metadata["shape"] == shape
    assert repr(p).endswith("%ss>" % shape)

    # the files Python writes: the CSV byte for byte, a .vdb that `vdbpack
    # check` passes and whose metadata names the shape as the CLI's does
    p.write(tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    wrote = p.write(tmp_path / "py.vdb")
    r = run_cli("check", tmp_path / "py.vdb", "--container", container, "--json", check=False)
    assert r.returncode == 0, r.stdout + r.stderr
    rep = json.loads(r.stdout)
    assert rep["ok"] and rep["overlapping_pairs"] == 0 and rep["outside"] == 0
    meta = {f: json.loads(run_cli("info", tmp_path / (f + ".vdb"), "--json").stdout)["metadata"]
            for f in ("cli", "py")}
    for key in ("shape", "method", "seed", "particle_count", "packing_fraction"):
        assert meta["py"][key] == meta["cli"][key], key
    assert meta["py"]["shape"] == shape
    run_cli("convert", tmp_path / "py.vdb", tmp_path / "py_vdb.csv", "-q")
    # (lattice packings: 16-bit positions, within the writer's bound)
    np.testing.assert_allclose(read_csv(tmp_path / "py_vdb.csv")["P"], p.positions,
                               rtol=0, atol=max(wrote["position_error"], 1e-7))

    # read back: the shape with its exponent, and the same particle volume
    q = vdbpack.read(tmp_path / "py.vdb")
    assert q.shape == shape and len(q) == len(p)
    assert q.volume() == pytest.approx(p.volume(), rel=1e-6)
    # the instancing shape: the command line's --shape-out, byte for byte
    p.write_shape(tmp_path / "py_shape.obj")
    assert (tmp_path / "py_shape.obj").read_bytes() == (tmp_path / "cli_shape.obj").read_bytes()


def test_every_builtin_name_packs_as_the_cli(tmp_path, cli):
    """Each name in vdbpack.SHAPES (as the CLI also takes it: any case, _
    for -) and two superballs: a small lattice packing equal to the CLI's."""
    names = [s for s in vdbpack.SHAPES if s != "sphere"]
    assert len(names) == 5 + 13
    for k, shape in enumerate(names + ["superball:1.5", "superball:1000"]):
        given = shape.upper().replace("-", "_") if k % 2 else shape
        out = tmp_path / ("%d.csv" % k)
        run_cli("pack", "box:1,1,1", "--shape", given, "--count", "40", "-o", out, "-q")
        p = vdbpack.pack("box:1,1,1", shape=given, count=40)
        assert p.shape == shape, given
        assert_same_particles(p, out)


def _cli_error(tmp_path, shape, method="lattice"):
    r = run_cli("pack", "box:1,1,1", "--method", method, "--shape", shape, "--radius", "0.1",
                "--count", "10", "-o", tmp_path / "x.vdb", check=False)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    return r.stderr.strip()


@pytest.mark.parametrize("shape", ["superball:0.3", "superball:nan", "superball:inf",
                                   "superball:1001", "superball:", "superball:2x"])
@pytest.mark.parametrize("method", ["lattice", "rsa"])
def test_a_bad_exponent_is_the_clis_error(tmp_path, cli, shape, method):
    with pytest.raises(ValueError) as e:
        if method == "lattice":
            vdbpack.pack("box:1,1,1", shape=shape, radius=0.1)
        else:
            vdbpack.pack("box:1,1,1", method=method, shape=shape, radius=0.1, count=10)
    msg = str(e.value)
    assert "\n" not in msg and msg.startswith("shape '%s': " % shape)
    # the command line's message, after its "pack: --shape 'X': "
    want = _cli_error(tmp_path, shape, method)
    assert want.endswith(msg.split("': ", 1)[1]), (want, msg)
    assert "[0.5, 1000]" in msg


def test_unknown_and_misplaced_shapes(tmp_path, cli):
    for bad in ("blob", "superballs", "superball", "mesh"):
        with pytest.raises(ValueError, match="unknown shape '%s' .*superball:P" % bad):
            vdbpack.pack("box:1,1,1", method="rsa", shape=bad, radius=0.1, count=5)
        assert "unknown --shape '%s'" % bad in _cli_error(tmp_path, bad, "rsa")
    # superballs pack on their densest lattice, by lattice and rsa only
    with pytest.raises(ValueError, match="lattice='fcc' is for spheres"):
        vdbpack.pack("box:1,1,1", shape="superball:2", radius=0.1, lattice="fcc")
    for method in ("relax", "jam"):
        with pytest.raises(ValueError, match="packs spheres"):
            vdbpack.pack("box:1,1,1", method=method, shape="superball:2", radius=0.1, count=10)


def test_packings_made_in_python_take_superballs(tmp_path, cli):
    """A Packing built from arrays with shape='superball:P' is written and
    checked as one (the library's overlap test for that exponent: two
    superballs whose bounding spheres overlap but which do not touch)."""
    q = np.array([[0.0, 0.0, 0.0, 1.0]] * 2)
    # two unit-bounding-radius superballs of p = 4 face to face along x: their
    # half-width is 1/sqrt(3)^(...) < 1, so centres 1.5 apart do not overlap
    # for a cube-like p and do overlap as spheres
    pos = np.array([[0.0, 0.0, 0.0], [1.5, 0.0, 0.0]])
    box = vdbpack.Container.box((-3, -3, -3), (3, 3, 3))
    for shape, overlapping in (("superball:4", 0), ("sphere", 1)):
        p = vdbpack.Packing(pos, [1.0, 1.0], None if shape == "sphere" else q, shape=shape)
        assert p.check(box).overlapping_pairs == overlapping, shape
    p = vdbpack.Packing(pos, [1.0, 1.0], q, shape="superball:4")
    p.write(tmp_path / "two.csv")
    r = vdbpack.read(tmp_path / "two.csv", shape="superball:4")
    assert r.shape == "superball:4"
    p.write(tmp_path / "two.vdb")
    assert vdbpack.read(tmp_path / "two.vdb").shape == "superball:4"
    for bad in ("superball:0.2", "blob"):
        p.shape = bad
        with pytest.raises(ValueError, match=bad):
            p.write(tmp_path / "bad.vdb")
    assert not (tmp_path / "bad.vdb").exists()
    with pytest.raises(ValueError, match="superball:0.4"):
        vdbpack.read(tmp_path / "two.csv", shape="superball:0.4")


def _read_obj(path):
    v, f = [], []
    for line in open(path):
        if line.startswith("v "):
            v.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            f.append([int(t.split("/")[0]) - 1 for t in line.split()[1:]])
    return np.array(v), f


@pytest.mark.parametrize("shape", ["cube", "snub-cube", "truncated-icosidodecahedron",
                                   "superball:2", "superball:0.6", "mesh"])
def test_shape_mesh_is_the_written_shape(tmp_path, shape):
    """Packing.shape_mesh (vp_shape_mesh, no file) gives the vertices and
    faces write_shape writes (the OBJ read here), the faces outward."""
    if shape == "mesh":
        ms = vdbpack.MeshShape.from_file(os.path.join(SAMPLES, "box.obj"))
        p = vdbpack.Packing(np.zeros((1, 3)), [1.0], [[0, 0, 0, 1]], shape=ms)
    else:
        p = vdbpack.Packing(np.zeros((1, 3)), [1.0], [[0, 0, 0, 1]], shape=shape)
    v, faces = p.shape_mesh()
    p.write_shape(tmp_path / "u.obj")
    ov, of = _read_obj(tmp_path / "u.obj")
    assert v.dtype == np.float64 and v.shape == ov.shape
    np.testing.assert_array_equal(v, ov)
    assert faces == of
    assert np.linalg.norm(v, axis=1).max() == pytest.approx(1.0, abs=1e-9)
    for f in faces:  # outward: Newell's normal against the face's centre
        a = v[f]
        b = np.roll(a, -1, axis=0)
        n = np.sum(np.cross(a, b), axis=0)
        assert n @ a.mean(axis=0) > 0


def test_shape_mesh_refuses_spheres():
    with pytest.raises(ValueError, match="sphere has no polygons"):
        vdbpack.Packing(np.zeros((1, 3)), [1.0]).shape_mesh()
    with pytest.raises(ValueError, match="mesh_shape"):
        vdbpack.Packing(np.zeros((1, 3)), [1.0], [[0, 0, 0, 1]], shape="mesh").shape_mesh()
