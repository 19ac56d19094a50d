# SPDX-License-Identifier: Apache-2.0
"""pack()'s fields and masks (docs/fields.md): mask=, radius_field=,
radius_field_mode=, density_field= give the command line's particles for
the same options (bit for bit, from its CSV), the metadata records them,
and bad fields raise with the command line's message. The fields are
written by OpenVDB's own Python module (tests/make_fields.py)."""
import os
import subprocess
import sys

import numpy as np
import pytest

import vdbpack
from conftest import SRC, assert_same_particles, run_cli

pytest.importorskip("pyopenvdb")


@pytest.fixture(scope="module")
def fields(tmp_path_factory):
    d = tmp_path_factory.mktemp("fields")
    subprocess.run([sys.executable, os.path.join(SRC, "tests", "make_fields.py"), str(d)],
                   check=True)
    return d


CASES = [
    # id, CLI options, pack() keywords ({d}: the fields' directory)
    ("rsa-radius-scale", ["--method", "rsa", "--radius", "0.03", "--count", "800",
                          "--radius-field", "{d}/halve.vdb"],
     dict(method="rsa", radius=0.03, count=800, radius_field="{d}/halve.vdb")),
    ("rsa-radius-absolute", ["--method", "rsa", "--count", "800", "--radius-field",
                             "{d}/halve_abs.vdb:radius", "--radius-field-mode", "absolute"],
     dict(method="rsa", count=800, radius_field="{d}/halve_abs.vdb:radius",
          radius_field_mode="absolute")),
    ("rsa-density", ["--method", "rsa", "--radius", "0.01", "--count", "2000",
                     "--density-field", "{d}/density.vdb"],
     dict(method="rsa", radius=0.01, count=2000, density_field="{d}/density.vdb")),
    ("rsa-mask-levelset", ["--method", "rsa", "--radius", "0.03", "--count", "max", "--mask",
                           "{d}/ball.vdb"],
     dict(method="rsa", radius=0.03, count="max", mask="{d}/ball.vdb")),
    ("lattice-mask-sphere", ["--radius", "0.04", "--mask", "sphere:0.25"],
     dict(radius=0.04, mask="sphere:0.25")),
    ("jam-radius-field", ["--method", "jam", "--count", "300", "--radius-field",
                          "{d}/halve.vdb"],
     dict(method="jam", count=300, radius_field="{d}/halve.vdb")),
    ("relax-radius-field-mask", ["--method", "relax", "--radius", "0.04", "--count", "300",
                                 "--radius-field", "{d}/halve.vdb", "--mask", "sphere:0.2"],
     dict(method="relax", radius=0.04, count=300, radius_field="{d}/halve.vdb",
          mask="sphere:0.2")),
]


@pytest.mark.parametrize("name,cli_args,kwargs", CASES, ids=[c[0] for c in CASES])
def test_same_particles_as_the_cli(tmp_path, fields, name, cli_args, kwargs):
    args = [a.replace("{d}", str(fields)) for a in cli_args]
    kw = {k: v.replace("{d}", str(fields)) if isinstance(v, str) else v
          for k, v in kwargs.items()}
    out = tmp_path / "cli.csv"
    run_cli("pack", "box:1,1,1", *args, "-o", out, "-q", "--threads", "2")
    p = vdbpack.pack("box:1,1,1", threads=1, **kw)
    assert len(p) > 0
    assert_same_particles(p, out)
    for k in ("mask", "radius_field", "density_field"):
        if k in kw:
            assert p.metadata[k] == kw[k]


def test_radius_field_follows_the_field(fields):
    p = vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count=1000,
                     radius_field=str(fields / "halve.vdb"))
    slope, icpt = np.polyfit(p.positions[:, 0], p.radii, 1)
    assert abs(icpt - 0.5 * slope - 0.03) < 3e-4 and abs(icpt + 0.5 * slope - 0.015) < 1.5e-4
    assert p.report["radius_field_mode"] == "scale"


def test_mask_container_object(fields):
    """A Container as the mask; the masked packing stays out of it."""
    ball = vdbpack.Container.sphere((0.1, 0, 0), 0.2)
    p = vdbpack.pack("box:1,1,1", method="rsa", radius=0.02, count="max", mask=ball)
    d = np.linalg.norm(p.positions - [0.1, 0, 0], axis=1) - p.radii
    assert len(p) > 1000 and d.min() >= 0.2 - 1e-9


@pytest.mark.parametrize("kw,text", [
    (dict(radius_field="{d}/nan.vdb"), "NaN value"),
    (dict(radius_field="{d}/vec3.vdb:velocity"), "not float"),
    (dict(radius_field="{d}/small.vdb"), "does not cover the container"),
    (dict(radius_field="{d}/negative.vdb"), "radii must be positive"),
    (dict(density_field="{d}/neg_density.vdb"), "must not be negative"),
    (dict(radius_field="{d}/missing.vdb"), "cannot open file"),
])
def test_bad_fields(fields, kw, text):
    kw = {k: v.replace("{d}", str(fields)) for k, v in kw.items()}
    with pytest.raises(vdbpack.Error, match=text):
        vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count=100, **kw)


def test_bad_options(fields):
    with pytest.raises(ValueError, match="goes with radius_field"):
        vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count=10,
                     radius_field_mode="absolute")
    with pytest.raises(ValueError, match="leave out"):
        vdbpack.pack("box:1,1,1", method="rsa", radius=0.03, count=10,
                     radius_field=str(fields / "halve_abs.vdb"), radius_field_mode="absolute")
    with pytest.raises(ValueError, match="goes with method"):
        vdbpack.pack("box:1,1,1", radius=0.03, radius_field=str(fields / "halve.vdb"))
