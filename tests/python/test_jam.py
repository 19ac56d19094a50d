# SPDX-License-Identifier: Apache-2.0
"""method="jam" (vp_pack_jam, docs/jam.md) through Python: no overlap by
a pair check of its own (every pair, numpy), the wall kept, the report's
figures present, sane and the command line's (--json), cancellation
through progress, and the option checks of `vdbpack pack --method jam`
as the module's exceptions. The particles themselves are compared with
the command line's in test_against_cli.py. 300-500 spheres: a second or
two each."""
import json
import os

import numpy as np
import pytest

import vdbpack
from conftest import SAMPLES, run_cli

SPHERE_LS = os.path.join(SAMPLES, "sphere_ls.vdb")

REPORT_KEYS = ("radius", "requested_count", "target_fraction", "tolerance", "radius_scale",
               "max_overlap", "mean_contacts", "rattler_fraction", "core_fraction",
               "core_count", "core_volume", "minimizations", "iterations", "list_builds",
               "seconds")


def pair_gaps(P, r):
    """|x_i - x_j| - (r_i + r_j) over every pair i < j, in double."""
    P = np.asarray(P, np.float64)
    r = np.asarray(r, np.float64)
    i, j = np.triu_indices(len(P), 1)
    return np.linalg.norm(P[i] - P[j], axis=1) - (r[i] + r[j])


def test_box_no_overlap_and_report():
    p = vdbpack.pack("box:1,1,1", method="jam", count=400, seed=2)
    assert len(p) == 400 and p.method == "jam" and p.shape == "sphere"
    # no pair overlaps at all (docs/jam.md: the exact last step), and the
    # spheres are wholly inside the box [-0.5, 0.5]^3
    gaps = pair_gaps(p.positions, p.radii)
    assert gaps.min() >= 0.0, gaps.min()
    r = p.radii.astype(np.float64)[:, None]
    assert np.all(p.positions - r >= -0.5) and np.all(p.positions + r <= 0.5)
    # jammed: many pairs touch (gap below 1e-4 of r_i + r_j)
    i, j = np.triu_indices(len(p), 1)
    rr = p.radii.astype(np.float64)
    touching = np.count_nonzero(gaps < 1e-4 * (rr[i] + rr[j]))
    assert touching > 2 * len(p), touching
    rep = p.report
    for key in REPORT_KEYS:
        assert key in rep, key
    assert rep["count"] == 400 and rep["requested_count"] == 400
    assert rep["target_fraction"] is None  # count given: no target
    assert rep["radius"] == "1"  # equal spheres: the jamming point sets the scale
    assert 4.5 <= rep["mean_contacts"] <= 6.5, rep["mean_contacts"]
    assert 0 <= rep["rattler_fraction"] < 0.3
    assert 0 <= rep["max_overlap"] <= rep["tolerance"] == 1e-6
    assert rep["radius_scale"] == pytest.approx(float(p.radii.max()), rel=1e-6)
    assert rep["core_count"] == 0 and rep["core_fraction"] == 0  # fewer than 100 in a core
    assert rep["minimizations"] > 0 and rep["iterations"] > rep["minimizations"]
    assert rep["list_builds"] > 0 and rep["seconds"] > 0
    assert 0.5 < p.fraction < 0.66 and rep["packing_fraction"] == p.fraction
    for key in ("radius", "radius_scale", "max_overlap", "mean_contacts", "rattler_fraction",
                "core_fraction"):
        assert key in p.metadata, key
    assert p.metadata["method"] == "jam"


def test_report_is_the_clis(tmp_path, cli):
    """The figures of `vdbpack pack --json` for the same options and seed
    (the command line on 2 threads, Python on 1)."""
    args = ["--radius", "uniform:0.05:0.07", "--target-fraction", "0.4", "--seed", "9"]
    want = json.loads(run_cli("pack", "box:1,1,1", "--method", "jam", *args, "-o",
                              tmp_path / "x.csv", "--json", "--threads", "2").stdout)
    p = vdbpack.pack("box:1,1,1", method="jam", radius="uniform:0.05:0.07",
                     target_fraction=0.4, seed=9, threads=1)
    assert 300 <= len(p) <= 500
    rep = p.report
    assert rep["count"] == want["count"] == len(p)
    assert rep["requested_count"] == want["requested_count"] == 0
    assert rep["target_fraction"] == 0.4
    for key in ("packing_fraction", "max_radius", "radius_scale", "max_overlap",
                "mean_contacts", "rattler_fraction", "core_fraction", "core_count",
                "core_volume", "minimizations", "iterations"):
        assert rep[key] == want[key], key
    assert pair_gaps(p.positions, p.radii).min() >= 0.0
    assert 4.5 <= rep["mean_contacts"] <= 6.5


def test_level_set_inside():
    p = vdbpack.pack(SPHERE_LS, method="jam", count=400, grid="sphere", tolerance=1e-5, seed=4)
    assert len(p) == 400
    assert pair_gaps(p.positions, p.radii).min() >= 0.0
    # wholly inside, by the level set loaded with a band that reaches the
    # spheres' centres (the file's own band is 0.06, the radii about 0.11)
    c = vdbpack.Container.from_file(SPHERE_LS, grid="sphere", particle_radius=0.2)
    assert (c.distance(p.positions) + p.radii).max() <= 1e-6
    assert p.report["max_overlap"] <= p.report["tolerance"] == 1e-5
    assert 4.5 <= p.report["mean_contacts"] <= 6.5


def test_level_set_centre_fit_refused_not_vanishing():
    # with fit="center" in a level set, centres pushed past the narrow band
    # (no wall force there) escaped and every radius was shrunk to about
    # 1e-18 with success returned; the library now refuses that state
    with pytest.raises(vdbpack.NoFitError) as e:
        vdbpack.pack(SPHERE_LS, method="jam", count=400, grid="sphere", fit="center", seed=4)
    assert "no jammed state" in str(e.value)
    # fit="inside" in the same level set packs, every sphere inside
    p = vdbpack.pack(SPHERE_LS, method="jam", count=400, grid="sphere", seed=4)
    c = vdbpack.Container.from_file(SPHERE_LS, grid="sphere", particle_radius=0.2)
    assert (c.distance(p.positions) + p.radii).max() <= 1e-5
    assert p.radii.min() > 0.05 and 4.5 <= p.report["mean_contacts"] <= 6.5


def test_false_cancels_the_jam():
    stages = []

    def progress(fraction, stage):
        stages.append(stage)
        return len(stages) < 2

    with pytest.raises(vdbpack.CancelledError) as e:
        vdbpack.pack("box:1,1,1", method="jam", count=500, progress=progress)
    assert e.value.code == "VP_ERR_CANCELLED" and str(e.value)
    assert len(stages) == 2 and stages[-1] == "jam"
    # nothing left behind: the module packs again
    assert len(vdbpack.pack("box:1,1,1", method="jam", count=300)) == 300


def test_bad_options(tmp_path):
    with pytest.raises(ValueError, match="count=N or target_fraction=F, not both"):
        vdbpack.pack("box:1,1,1", method="jam", count=300, target_fraction=0.6)
    with pytest.raises(ValueError, match="count=N or target_fraction=F, not both"):
        vdbpack.pack("box:1,1,1", method="jam", radius=0.05, count=300, target_fraction=0.6)
    with pytest.raises(ValueError, match="needs count=N, or radius=SIZE"):
        vdbpack.pack("box:1,1,1", method="jam", target_fraction=0.6)
    # more than the densest packing of equal spheres holds: the library's
    # own check, before any work
    with pytest.raises(vdbpack.NoFitError, match="0.7405"):
        vdbpack.pack("box:1,1,1", method="jam", radius=0.05, target_fraction=0.75)
    # N equal spheres of this radius cannot fit at all (jam_count_check)
    with pytest.raises(vdbpack.NoFitError, match="fill .* times the container's volume"):
        vdbpack.pack("box:1,1,1", method="jam", radius=0.2, count=300)
    with pytest.raises(ValueError, match="target_fraction must be a number in"):
        vdbpack.pack("box:1,1,1", method="jam", radius=0.05, target_fraction=1.2)
    with pytest.raises(ValueError, match="tolerance must be a number in"):
        vdbpack.pack("box:1,1,1", method="jam", count=300, tolerance=0.5)
    with pytest.raises(ValueError, match="jam' packs spheres"):
        vdbpack.pack("box:1,1,1", method="jam", shape="cube", count=300)
    with pytest.raises(ValueError, match="max_sweeps goes with method='relax'"):
        vdbpack.pack("box:1,1,1", method="jam", count=300, max_sweeps=5)
    with pytest.raises(ValueError, match="count='max' goes with method='rsa'"):
        vdbpack.pack("box:1,1,1", method="jam", count="max")
    with pytest.raises(vdbpack.InvalidArgumentError, match="radius"):
        vdbpack.pack("box:1,1,1", method="jam", radius="uniform:0.07:0.05", count=300)
    assert "jam" in vdbpack.METHODS
    assert not list(tmp_path.iterdir())


def test_the_cli_refuses_what_python_refuses(tmp_path, cli):
    """The same refusals on the command line (exit 2: usage; 1: no fit)."""
    out = tmp_path / "x.csv"
    r = run_cli("pack", "box:1,1,1", "--method", "jam", "--count", "300",
                "--target-fraction", "0.6", "-o", out, check=False)
    assert r.returncode == 2 and "not both" in r.stderr
    r = run_cli("pack", "box:1,1,1", "--method", "jam", "--radius", "0.05",
                "--target-fraction", "0.75", "-o", out, check=False)
    assert r.returncode == 1 and "0.7405" in r.stderr
    r = run_cli("pack", "box:1,1,1", "--method", "jam", "--radius", "0.2", "--count", "300",
                "-o", out, check=False)
    assert r.returncode == 1 and "times the container's volume" in r.stderr
    assert not out.exists()


# the palette of render --colour contacts (src/render/render.c), by class:
# fewer than 4, 4, 5, 6, 7, 8 or more touching neighbours
CONTACT_PALETTE = np.array([[0.45, 0.45, 0.45], [0.10, 0.25, 0.85], [0.05, 0.65, 0.75],
                            [0.20, 0.70, 0.15], [0.90, 0.75, 0.05], [0.85, 0.12, 0.08]])


def test_render_colours_by_contacts():
    """Each visible sphere's colour is its class of touching neighbours,
    counted here by numpy (gap below 1e-4 of r_i + r_j): pixels whose 3x3
    neighbourhood shows one particle, compared by chromaticity (the light
    scales the colour, not its hue)."""
    p = vdbpack.pack("box:1,1,1", method="jam", count=400, seed=5)
    P = np.asarray(p.positions, np.float64)
    r = np.asarray(p.radii, np.float64)
    i, j = np.triu_indices(len(P), 1)
    e = r[i] + r[j]
    touch = np.linalg.norm(P[i] - P[j], axis=1) - e < 1e-4 * e
    z = np.bincount(i[touch], minlength=len(P)) + np.bincount(j[touch], minlength=len(P))
    assert z.max() >= 6 and (z < 4).any(), np.bincount(z)
    cls = np.clip(z - 3, 0, 5)
    img = p.render(size=(320, 240), colour="contacts", cut="z:0", ao=0)
    ids = img.id.astype(np.int64)
    core = ids[1:-1, 1:-1]
    same = np.ones(core.shape, bool)
    for dy in (-1, 0, 1):
        for dx in (-1, 0, 1):
            same &= ids[1 + dy:ids.shape[0] - 1 + dy, 1 + dx:ids.shape[1] - 1 + dx] == core
    same &= core != 0xFFFFFFFF
    rgb = img.rgba[1:-1, 1:-1, :3][same].astype(np.float64)
    lit = rgb.sum(axis=1) > 0.05
    rgb, pid = rgb[lit], core[same][lit]
    assert len(pid) > 2000, len(pid)
    chroma = rgb / rgb.sum(axis=1, keepdims=True)
    pal = CONTACT_PALETTE / CONTACT_PALETTE.sum(axis=1, keepdims=True)
    nearest = np.argmin(((chroma[:, None, :] - pal[None, :, :]) ** 2).sum(axis=2), axis=1)
    order = np.argsort(np.asarray(p.ids))
    want = cls[order[np.searchsorted(np.asarray(p.ids)[order], pid)]]
    agree = (nearest == want).mean()
    # several classes are on screen, and the colours say which
    assert len(np.unique(want)) >= 3, np.unique(want)
    assert agree > 0.99, agree
