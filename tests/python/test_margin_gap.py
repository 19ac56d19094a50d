# SPDX-License-Identifier: Apache-2.0
"""pack()'s margin and gap (rsa, relax, jam) and rsa's count=N without a
radius (issue 31): the command line's particles for the same settings,
both distances measured here with numpy against the analytic wall, and
`vdbpack check` holding the Python-written file to the margin and gap its
metadata records."""
import os

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, assert_same_particles, run_cli

CASES = [
    ("rsa", {"count": 500, "radius": 0.04}),
    ("relax", {"count": 400, "radius": 0.05, "target_fraction": 0.4}),
    ("jam", {"count": 400}),
]


def _cli_args(method, opts):
    out = []
    for k, v in opts.items():
        out += ["--" + k.replace("_", "-"), v]
    return ["--method", method] + out


@pytest.mark.parametrize("method,opts", CASES)
@pytest.mark.parametrize("fit", ["inside", "center"])
def test_margin_gap_as_cli_and_measured(tmp_path, method, opts, fit):
    margin, gap = 0.05, 0.01
    p = vdbpack.pack("sphere:1", method=method, margin=margin, gap=gap, fit=fit, seed=2, **opts)
    csv = tmp_path / "c.csv"
    run_cli("pack", "sphere:1", *_cli_args(method, opts), "--margin", margin, "--gap", gap,
            "--fit", fit, "--seed", 2, "-o", csv, "-q")
    assert_same_particles(p, csv)
    P, r = p.positions, p.radii.astype(np.float64)
    wall = 1.0 - np.linalg.norm(P, axis=1) - (r if fit == "inside" else 0.0)
    d = np.linalg.norm(P[:, None, :] - P[None, :, :], axis=2) - r[:, None] - r[None, :]
    d[np.diag_indices(len(r))] = np.inf
    assert wall.min() >= margin * (1 - 1e-9), wall.min()
    assert d.min() >= gap * (1 - 1e-6), d.min()
    # the gap shaped the dense packings: some pair sits at it
    if method != "rsa":
        assert d.min() < gap * 1.05, d.min()
    assert p.metadata["margin"] == margin and p.metadata["gap"] == gap
    f = tmp_path / "p.vdb"
    p.write(str(f))
    run_cli("check", f, "--container", "sphere:1", "-q")  # the file's margin and gap
    assert run_cli("check", f, "--container", "sphere:1", "--gap", 2 * gap, "-q",
                   check=False).returncode == 3


def test_rsa_count_without_radius(tmp_path):
    p = vdbpack.pack("box:1,1,1", method="rsa", count=3000, seed=5)
    csv = tmp_path / "c.csv"
    run_cli("pack", "box:1,1,1", "--method", "rsa", "--count", 3000, "--seed", 5, "-o", csv, "-q")
    assert_same_particles(p, csv)
    assert len(p) == 3000
    # the radius at which 3000 spheres fill 0.3 of the unit box
    r = (0.3 / (3000 * 4.0 / 3.0 * np.pi)) ** (1.0 / 3.0)
    assert np.allclose(p.radii, r, rtol=1e-6)
    assert abs(p.fraction - 0.3) < 1e-5
    q = vdbpack.pack("box:1,1,1", method="rsa", count=1000, target_fraction=0.2, seed=5)
    assert abs(q.fraction - 0.2) < 1e-5 and q.report["target_fraction"] == 0.2


@pytest.mark.parametrize("kw,words", [
    ({"method": "rsa", "count": 10, "radius": 0.1, "target_fraction": 0.2}, "not both"),
    ({"method": "rsa", "count": "max"}, "needs radius"),
    ({"method": "rsa", "count": 10, "radius": 0.1, "gap": 0.01,
      "shape": os.path.join(SAMPLES, "peanut.obj")}, "not a mesh shape"),
    ({"method": "jam", "count": 10, "margin": -1}, ">= 0"),
    ({"method": "relax", "count": 10, "radius": 0.1, "gap": float("nan")}, "gap must be"),
    ({"method": "rsa", "count": 10, "gap": 0.5}, "smaller than the radius"),
    ({"method": "lattice", "radius": 0.1, "shape": "cube", "gap": 0.01}, "lattice of spheres"),
])
def test_bad_margin_gap(kw, words):
    with pytest.raises(ValueError) as e:
        vdbpack.pack("box:1,1,1", **kw)
    assert words in str(e.value)


def test_jam_gap_too_large_is_the_library_message():
    with pytest.raises(vdbpack.InvalidArgumentError) as e:
        vdbpack.pack("box:1,1,1", method="jam", count=100, gap=0.2)
    assert "not smaller than the smallest radius" in str(e.value)


def test_lattice_margin_and_gap_as_the_cli(tmp_path):
    # a simple cubic lattice of radius 0.05 spaced for a gap of 0.02 and
    # kept 0.03 from the walls of the unit box: 8 per axis (centres in
    # [-0.42, 0.42], 0.12 apart), the CLI's particles
    p = vdbpack.pack("box:1,1,1", method="lattice", lattice="sc", radius=0.05, margin=0.03,
                     gap=0.02)
    assert len(p) == 512
    d = np.linalg.norm(p.positions[:, None, :] - p.positions[None, :, :], axis=-1)
    np.fill_diagonal(d, np.inf)
    assert abs(d.min() - 0.12) < 1e-9
    assert (0.5 - np.abs(p.positions).max() - 0.05) >= 0.03 - 1e-9
    out = tmp_path / "l.csv"
    run_cli("pack", "box:1,1,1", "--lattice", "sc", "--radius", "0.05", "--margin", "0.03",
            "--gap", "0.02", "-o", out)
    assert_same_particles(p, out)
