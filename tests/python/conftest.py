# SPDX-License-Identifier: Apache-2.0
"""Fixtures of the Python module's tests (run by CTest as python_module:
python3 -m pytest -q tests/python, with PYTHONPATH=<build>/python).

Environment (set by tests/CMakeLists.txt): VDBPACK, the command-line tool
the results are compared with; VP_SAMPLES, vdb_samples/; VP_ABI_LAYOUT, the
struct-layout program (tests/abi_layout.c). Results are checked against the
command line's own files (read here with numpy alone) and against geometry
computed here, never against the module itself."""
import os
import subprocess
import sys

import numpy as np
import pytest

# the module must load the library of this build, not one named elsewhere
os.environ.pop("VDBPACK_LIBRARY", None)

import vdbpack  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.dirname(os.path.dirname(HERE))


def _cli():
    p = os.environ.get("VDBPACK")
    if not p:  # run by hand: the tool beside the library of the build
        p = os.path.join(os.path.dirname(os.path.realpath(vdbpack.library_path())), "vdbpack")
    return p


CLI = _cli()
SAMPLES = os.environ.get("VP_SAMPLES") or os.path.join(SRC, "vdb_samples")


@pytest.fixture(scope="session")
def cli():
    assert os.access(CLI, os.X_OK), "no vdbpack tool at %s (set VDBPACK)" % CLI
    return CLI


@pytest.fixture(scope="session")
def samples():
    return SAMPLES


def run_cli(*args, check=True):
    """Runs the command-line tool; returns the CompletedProcess."""
    r = subprocess.run([CLI] + [str(a) for a in args], capture_output=True, text=True,
                       timeout=300)
    if check and r.returncode != 0:
        raise AssertionError("vdbpack %s failed (%d): %s" % (" ".join(map(str, args)),
                                                             r.returncode, r.stderr))
    return r


def read_csv(path):
    """A CSV written by vdbpack, read with numpy alone: dict of arrays
    (id, P, pscale, q or None, group names)."""
    a = np.atleast_1d(np.genfromtxt(path, delimiter=",", names=True, dtype=None,
                                    encoding="ascii"))
    q = None
    if "qx" in a.dtype.names:
        q = np.stack([a["qx"], a["qy"], a["qz"], a["qw"]], axis=1)
    return {"id": a["id"], "P": np.stack([a["x"], a["y"], a["z"]], axis=1),
            "pscale": a["pscale"], "q": q, "group": [str(g) for g in a["group"]]}


def assert_same_particles(packing, csv_path, exact_positions=True, atol=0.0):
    """packing holds the particles of the CSV: ids, positions (bit for bit
    unless told), radii and orientations as the float32 the library holds,
    group names."""
    c = read_csv(csv_path)
    n = len(c["id"])
    assert len(packing) == n
    np.testing.assert_array_equal(packing.ids, c["id"])
    if exact_positions:
        np.testing.assert_array_equal(packing.positions, c["P"])
    else:
        np.testing.assert_allclose(packing.positions, c["P"], rtol=0, atol=atol)
    np.testing.assert_array_equal(packing.radii.astype(np.float32), c["pscale"].astype(np.float32))
    if c["q"] is None:
        assert packing.orient is None
    else:
        np.testing.assert_array_equal(packing.orient.astype(np.float32),
                                      c["q"].astype(np.float32))
    assert [packing.group_names[g] for g in packing.groups] == c["group"]


def overlapping_pairs(P, r, tol=1e-9):
    """Pairs (i, j) of spheres closer than (r_i + r_j)(1 - tol): numpy
    only, a sweep along x after sorting."""
    P = np.asarray(P, np.float64)
    r = np.asarray(r, np.float64)
    order = np.argsort(P[:, 0], kind="stable")
    Ps, rs = P[order], r[order]
    reach = 2 * rs.max() if len(rs) else 0.0
    bad = []
    for k in range(1, len(Ps)):
        dx = Ps[k:, 0] - Ps[:-k, 0]
        near = dx < reach
        if not near.any():
            break
        i = np.nonzero(near)[0]
        d = np.linalg.norm(Ps[i + k] - Ps[i], axis=1)
        hit = d < (rs[i] + rs[i + k]) * (1 - tol)
        bad += [(int(order[a]), int(order[a + k])) for a in i[hit]]
    return bad


def python_exe():
    return sys.executable
