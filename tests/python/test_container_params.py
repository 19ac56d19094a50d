# SPDX-License-Identifier: Apache-2.0
"""vdbpack.container_params: a mesh handed over in memory
(Container.from_mesh) with the sizing it returns packs exactly the
particles that pack() gives the same mesh as a file, for every method
(the Blender add-on relies on it). The file is read here with numpy."""
import os

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES

PEANUT = os.path.join(SAMPLES, "peanut.obj")


def read_obj(path):
    v, f = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith("v "):
                v.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                f.append([int(t.split("/")[0]) - 1 for t in line.split()[1:4]])
    # the library reads mesh files through Assimp, which keeps coordinates
    # as float
    return np.array(v, np.float32).astype(np.float64), np.array(f, np.int64)


JOBS = [
    ("lattice", {"count": 400}),
    ("lattice", {"radius": 0.05, "shape": "cube"}),
    ("rsa", {"passes": [{"count": 150, "radius": 0.08}, {"count": 300, "radius": 0.04}]}),
    ("rsa", {"radius": 0.06, "count": "max"}),
    ("relax", {"radius": "uniform:0.04:0.06", "count": 300}),
    ("jam", {"count": 300}),
]


@pytest.mark.parametrize("method,opts", JOBS, ids=[m + "-" + "-".join(sorted(o)) for m, o in JOBS])
def test_in_memory_mesh_packs_as_the_file(method, opts):
    sizing = vdbpack.container_params(method, **opts)
    assert set(sizing) <= {"particle_radius", "particle_count", "space_per_particle",
                           "narrow_band"}
    assert "particle_radius" in sizing or "space_per_particle" in sizing, sizing
    v, t = read_obj(PEANUT)
    mem = vdbpack.Container.from_mesh(v, t, name="peanut", **sizing)
    a = vdbpack.pack(PEANUT, method=method, seed=3, **opts)
    b = vdbpack.pack(mem, method=method, seed=3, **opts)
    assert len(a) > 50 and len(a) == len(b)
    assert np.array_equal(np.asarray(a.positions), np.asarray(b.positions))
    assert np.array_equal(np.asarray(a.radii), np.asarray(b.radii))


def test_sizing_follows_the_job():
    # a finer job needs a finer level set: smaller particles, smaller radius
    big = vdbpack.container_params("lattice", radius=0.1)
    small = vdbpack.container_params("lattice", radius=0.01)
    assert small["particle_radius"] < big["particle_radius"], (small, big)


def test_bad_options_are_refused_as_pack_refuses_them():
    with pytest.raises(ValueError, match="unknown method"):
        vdbpack.container_params("nope", count=10)
    with pytest.raises(ValueError, match="radius=R or count=N"):
        vdbpack.container_params("lattice")
    with pytest.raises(TypeError, match="unexpected keyword"):
        vdbpack.container_params("lattice", count=10, colour="red")
