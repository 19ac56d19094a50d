# SPDX-License-Identifier: Apache-2.0
"""Each packer through Python gives the command line's particles for the
same options and seed: the same ids, the same positions bit for bit (the
CLI's CSV prints them with %.17g), the same float32 radii and orientations,
the same groups. Containers from files (a mesh, a .vdb level set) and
analytic ones. Python runs on 1 thread, the command line on 2: the result
must not depend on it."""
import os

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, assert_same_particles, run_cli

PEANUT = os.path.join(SAMPLES, "peanut.obj")
SPHERE_LS = os.path.join(SAMPLES, "sphere_ls.vdb")
BOX_OBJ = os.path.join(SAMPLES, "box.obj")

CASES = [
    # id, container, CLI options, pack() keywords
    ("lattice-peanut-count", PEANUT, ["--count", "2000"], dict(count=2000)),
    ("lattice-levelset-hcp-center", SPHERE_LS,
     ["--grid", "sphere", "--lattice", "hcp", "--fit", "center", "--radius", "0.1"],
     dict(grid="sphere", lattice="hcp", fit="center", radius=0.1)),
    ("lattice-bcc-box-offsets", "box:1,0.8,0.6",
     ["--lattice", "bcc", "--radius", "0.08", "--offsets", "8"],
     dict(lattice="bcc", radius=0.08, offsets=8)),
    ("lattice-sc-sphere-seed", "sphere:1", ["--lattice", "sc", "--radius", "0.15", "--seed", "7"],
     dict(lattice="sc", radius=0.15, seed=7)),
    ("lattice-densest-is-fcc", "sphere:1", ["--lattice", "densest", "--radius", "0.15"],
     dict(lattice="densest", radius=0.15)),
    ("lattice-cubes-rotations", "box:1,1,1", ["--shape", "cube", "--count", "300",
                                              "--rotations", "4"],
     dict(shape="cube", count=300, rotations=4)),
    ("lattice-octahedra-peanut", PEANUT, ["--shape", "octahedron", "--radius", "0.12",
                                          "--voxel-size", "0.03"],
     dict(shape="octahedron", radius=0.12, voxel_size=0.03)),
    # (short runs, which exit 4 since issue 31: --allow-short; Python has no
    # exit status, its report gives placed and requested)
    ("rsa-grow-then-maximal", PEANUT,
     ["--method", "rsa", "--pass", "count=100,radius=0.12,grow", "--pass", "count=max,radius=0.05",
      "--allow-short"],
     dict(passes=[{"count": 100, "radius": 0.12, "grow": True}, {"count": "max", "radius": 0.05}])),
    ("rsa-distributions-levelset", SPHERE_LS,
     ["--method", "rsa", "--pass", "count=300,radius=uniform:0.04:0.08,name=big",
      "--pass", "count=800,radius=lognormal:0.03:0.005,retries=2000", "--seed", "3"],
     dict(passes=["count=300,radius=uniform:0.04:0.08,name=big",
                  {"count": 800, "radius": "lognormal:0.03:0.005", "retries": 2000}], seed=3)),
    ("rsa-one-pass-maximal-center", "sphere:1",
     ["--method", "rsa", "--radius", "0.06", "--count", "max", "--fit", "center"],
     dict(radius=0.06, count="max", fit="center")),
    ("rsa-maximal-uniform", "box:1,1,1",
     ["--method", "rsa", "--radius", "uniform:0.04:0.08", "--count", "max"],
     dict(radius="uniform:0.04:0.08", count="max")),
    ("rsa-maximal-list-passes", SPHERE_LS,
     ["--method", "rsa", "--pass", "count=20,radius=0.15", "--pass", "count=max,radius=list:0.04:0.07"],
     dict(passes=[{"count": 20, "radius": 0.15}, "count=max,radius=list:0.04:0.07"])),
    ("rsa-list-retries", "box:1,1,1",
     ["--method", "rsa", "--radius", "list:0.03:0.05:0.07", "--count", "400", "--retries", "300",
      "--allow-short"],
     dict(radius="list:0.03:0.05:0.07", count=400, retries=300)),
    ("rsa-cubes-random-grow", "box:1,1,1",
     ["--method", "rsa", "--shape", "cube", "--radius", "0.08", "--count", "200", "--grow"],
     dict(shape="cube", radius=0.08, count=200, grow=True)),
    ("rsa-tetrahedra-bbox", "box:1,1,1",
     ["--method", "rsa", "--shape", "tetrahedron", "--overlap", "bbox", "--radius", "0.07",
      "--count", "150"],
     dict(shape="tetrahedron", overlap="bbox", radius=0.07, count=150)),
    ("rsa-icosahedra-fixed", "sphere:1",
     ["--method", "rsa", "--shape", "icosahedron", "--orient", "fixed",
      "--pass", "count=50,radius=0.15", "--pass", "count=200,radius=0.07"],
     dict(shape="icosahedron", orient="fixed", passes=[dict(count=50, radius=0.15),
                                                       dict(count=200, radius=0.07)])),
    ("rsa-mesh-shape-file", "sphere:1",
     ["--method", "rsa", "--shape", BOX_OBJ, "--radius", "0.12", "--count", "80"],
     dict(shape=BOX_OBJ, radius=0.12, count=80)),
    ("relax-box-target", "box:1,1,1",
     ["--method", "relax", "--radius", "0.05", "--count", "400", "--target-fraction", "0.5"],
     dict(radius=0.05, count=400, target_fraction=0.5)),
    ("relax-peanut-uniform", PEANUT,
     ["--method", "relax", "--radius", "uniform:0.04:0.06", "--count", "300",
      "--tolerance", "1e-5"],
     dict(radius="uniform:0.04:0.06", count=300, tolerance=1e-5)),
    ("jam-peanut-uniform", PEANUT,
     ["--method", "jam", "--radius", "uniform:0.04:0.06", "--count", "300",
      "--tolerance", "1e-5", "--seed", "3"],
     dict(radius="uniform:0.04:0.06", count=300, tolerance=1e-5, seed=3)),
    ("jam-box-target", "box:1,1,1",
     ["--method", "jam", "--radius", "0.06", "--target-fraction", "0.36"],
     dict(radius=0.06, target_fraction=0.36)),
    ("jam-sphere-equal-center", "sphere:1",
     ["--method", "jam", "--count", "500", "--fit", "center", "--seed", "5"],
     dict(count=500, fit="center", seed=5)),
    ("jam-levelset-count", SPHERE_LS, ["--method", "jam", "--grid", "sphere", "--count", "400"],
     dict(grid="sphere", count=400)),
]


def _method(cli_args):
    return cli_args[cli_args.index("--method") + 1] if "--method" in cli_args else "lattice"


@pytest.mark.parametrize("name,container,cli_args,kwargs", CASES, ids=[c[0] for c in CASES])
def test_same_particles_as_the_cli(tmp_path, cli, name, container, cli_args, kwargs):
    out = tmp_path / "cli.csv"
    run_cli("pack", container, *cli_args, "-o", out, "-q", "--threads", "2")
    p = vdbpack.pack(container, method=_method(cli_args), threads=1, **kwargs)
    assert len(p) > 0
    assert_same_particles(p, out)
    # and the file Python writes is the command line's file
    mine = tmp_path / "py.csv"
    p.write(mine)
    assert mine.read_bytes() == out.read_bytes()


def test_vdb_written_by_python_is_the_clis(tmp_path, cli):
    """The .vdb: same particles (dumped by the command line's convert to
    CSV), the same precision choice, and the metadata `vdbpack check` reads
    (fit, voxel_size, inside) with the command line's values."""
    args = ["--method", "rsa", "--radius", "0.07", "--count", "300", "--fit", "center"]
    run_cli("pack", PEANUT, *args, "-o", tmp_path / "cli.vdb", "-q")
    p = vdbpack.pack(PEANUT, method="rsa", radius=0.07, count=300, fit="center")
    rep = p.write(tmp_path / "py.vdb")
    assert rep["full_precision"] == 1  # rsa: float P, as the command line
    for f in ("cli", "py"):
        run_cli("convert", tmp_path / (f + ".vdb"), tmp_path / (f + ".csv"), "-q")
    assert (tmp_path / "cli.csv").read_bytes() == (tmp_path / "py.csv").read_bytes()
    import json
    meta = {f: json.loads(run_cli("info", tmp_path / (f + ".vdb"), "--json").stdout)["metadata"]
            for f in ("cli", "py")}
    for key in ("creator", "seed", "method", "shape", "fit", "container", "particle_count",
                "max_radius", "container_volume", "packing_fraction", "voxel_size", "inside",
                "passes", "position_precision"):
        assert meta["py"][key] == meta["cli"][key], key
    # lattice packings keep 16-bit positions by default, as the command line
    q = vdbpack.pack("box:1,1,1", radius=0.1)
    assert q.write(tmp_path / "l.vdb")["full_precision"] == 0
    assert q.write(tmp_path / "l2.vdb", precision="full")["full_precision"] == 1


def test_mesh_shape_from_numpy_is_the_file_shape(tmp_path, cli):
    """A particle shape built in numpy (MeshShape.from_mesh) packs as the same
    mesh given to the command line as an OBJ file (coordinates exact in
    float, as Assimp reads them)."""
    # a notched block: concave, 12 vertices
    v = np.array([[0, 0, 0], [4, 0, 0], [4, 2, 0], [2.5, 2, 0], [2.5, 1, 0], [1.5, 1, 0],
                  [1.5, 2, 0], [0, 2, 0]], np.float64)
    top = v + [0, 0, 1.5]
    verts = np.vstack([v, top])
    n = len(v)
    # bottom face (facing -z) and top face as fans of the L-free outline:
    # triangulate the 8-gon by hand (it is not convex)
    poly = [(0, 1, 4), (1, 2, 4), (2, 3, 4), (0, 4, 5), (0, 5, 7), (5, 6, 7)]
    tris = [(a, c, b) for a, b, c in poly] + [(a + n, b + n, c + n) for a, b, c in poly]
    for i in range(n):
        j = (i + 1) % n
        tris += [(i, j, j + n), (i, j + n, i + n)]
    tris = np.array(tris, np.int64)
    obj = tmp_path / "notch.obj"
    with open(obj, "w") as f:
        for x in verts:
            f.write("v %r %r %r\n" % tuple(x))
        for t in tris:
            f.write("f %d %d %d\n" % tuple(t + 1))
    shape = vdbpack.MeshShape.from_mesh(verts, tris, name="notch.obj")
    assert shape.triangles == len(tris)
    run_cli("pack", "sphere:1", "--method", "rsa", "--shape", obj, "--radius", "0.15",
            "--count", "60", "-o", tmp_path / "cli.csv", "-q")
    p = vdbpack.pack("sphere:1", method="rsa", shape=shape, radius=0.15, count=60)
    assert p.shape == "mesh" and p.mesh_shape is shape
    assert_same_particles(p, tmp_path / "cli.csv")


def test_threads_do_not_change_the_result():
    a = vdbpack.pack("box:1,1,1", method="rsa", radius=0.04, count="max", threads=1)
    b = vdbpack.pack("box:1,1,1", method="rsa", radius=0.04, count="max", threads=2)
    np.testing.assert_array_equal(a.positions, b.positions)
    assert a.report["passes"][0]["stop"] == "maximal"


def test_report_figures_are_the_clis(tmp_path, cli):
    import json
    r = run_cli("pack", "box:1,1,1", "--method", "rsa", "--pass", "count=50,radius=0.1,grow",
                "--pass", "count=max,radius=0.05", "-o", tmp_path / "x.csv", "--json")
    want = json.loads(r.stdout)
    p = vdbpack.pack("box:1,1,1", method="rsa",
                     passes=["count=50,radius=0.1,grow", "count=max,radius=0.05"])
    assert p.report["count"] == want["count"]
    assert p.report["packing_fraction"] == want["packing_fraction"]
    assert p.fraction == want["packing_fraction"]
    for mine, theirs in zip(p.report["passes"], want["passes"]):
        for key in ("group", "radius", "requested", "maximal", "placed", "stop", "tries",
                    "grow", "grow_mean"):
            assert mine[key] == theirs[key], key
    r = run_cli("pack", "sphere:1", "--shape", "dodecahedron", "--radius", "0.2", "-o",
                tmp_path / "y.csv", "--json")
    want = json.loads(r.stdout)
    p = vdbpack.pack("sphere:1", shape="dodecahedron", radius=0.2)
    for key in ("lattice", "radius", "lattice_fraction", "offsets_tried", "offset", "rotation"):
        assert p.report[key] == (tuple(want[key]) if isinstance(want[key], list) else want[key])
