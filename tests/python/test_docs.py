# SPDX-License-Identifier: Apache-2.0
"""docs/python.md: every ```python block runs (in order, in a fresh folder
with vdb_samples/ at hand); the Houdini snippet against a stand-in `hou`
whose points must carry the packing's P, pscale, orient, id and groups; the
Blender snippet compiles (it needs Blender's bpy)."""
import os
import re

import pytest

import doc_examples
from conftest import SAMPLES, SRC

DOC = os.path.join(SRC, "docs", "python.md")


def test_every_python_block_is_seen():
    text = open(DOC, encoding="utf-8").read()
    fences = re.findall(r"^```python.*$", text, re.M)
    found = doc_examples.blocks(text)
    assert len(found) == len(fences) >= 10
    tags = [t for t, _, _ in found]
    assert tags.count("houdini") == 1 and tags.count("blender") == 1
    assert set(tags) <= {"", "houdini", "blender"}


def test_the_examples_run(tmp_path, capsys):
    ran, compiled = doc_examples.run(DOC, SAMPLES, str(tmp_path / "work"))
    assert ran >= 10 and compiled == 1
    out = capsys.readouterr().out
    assert "houdini: 350 points with P, pscale, orient, id and 2 groups" in out
    # what the examples say they write is there
    for f in ("peanut.vdb", "binary.vdb", "ico.vdb", "ico.ply", "ico.csv", "ico.obj",
              "icosahedron.obj", "peanut.png", "peanut_ls.vdb"):
        assert (tmp_path / "work" / f).stat().st_size > 0, f


def test_the_houdini_check_can_fail(tmp_path):
    """A snippet that forgets pscale, or gets orient's order wrong, fails."""
    base = ("import numpy as np, vdbpack\n"
            "geo = hou.pwd().geometry()\n"
            "packing = vdbpack.pack('box:1,1,1', method='rsa', shape='cube', radius=0.1, "
            "count=20)\n"
            "points = geo.createPoints(packing.positions.tolist())\n"
            "geo.addAttrib(hou.attribType.Point, 'pscale', 1.0)\n"
            "geo.addAttrib(hou.attribType.Point, 'orient', (0.0, 0.0, 0.0, 1.0))\n"
            "geo.addAttrib(hou.attribType.Point, 'id', 0)\n"
            "geo.setPointIntAttribValuesFromString('id', packing.ids.tobytes())\n"
            "geo.createPointGroup('pass1').add(list(points))\n")
    wxyz = ("geo.setPointFloatAttribValuesFromString('pscale', "
            "packing.radii.astype(np.float32).tobytes())\n"
            "geo.setPointFloatAttribValuesFromString('orient', "
            "packing.orient[:, [3, 0, 1, 2]].astype(np.float32).tobytes())\n")
    for body in (base, base + wxyz):
        hou = doc_examples.FakeHou()
        ns = {"hou": hou}
        exec(body, ns)
        with pytest.raises(AssertionError):
            doc_examples.check_houdini(ns, hou)
