# SPDX-License-Identifier: Apache-2.0
"""Runs the ```python blocks of docs/python.md, in order, in one working
directory where vdb_samples/ is at hand, so that the documentation's
examples stay true. Blocks marked ```python houdini run with a stand-in
`hou` module that records what the snippet makes (FakeHou, below) and
whose result check_houdini() compares with the packing; blocks marked
```python blender are only compiled (they need Blender's bpy).

Used by tests/python/test_docs.py and, from an installed prefix, by
tests/sh_install.sh:  python3 doc_examples.py DOC.md SAMPLES_DIR WORKDIR
"""
import os
import re
import struct
import sys
import types

FENCE = re.compile(r"^```python(?:[ \t]+(\w+))?[ \t]*\n(.*?)^```[ \t]*$", re.M | re.S)


def blocks(text):
    """(tag, code, line) for every ```python block; tag is "" for plain
    Python, else the word after `python`."""
    out = []
    for m in FENCE.finditer(text):
        out.append((m.group(1) or "", m.group(2), text.count("\n", 0, m.start()) + 2))
    return out


# ---------------------------------------------------------------------------
# A stand-in for Houdini's hou module: the calls a Python SOP makes to turn
# a packing into points, recorded.

class _Attrib:
    def __init__(self, name, default):
        self._name = name
        self.default = default
        self.size = len(default) if isinstance(default, (tuple, list)) else 1
        self.is_int = isinstance(default, int) or (
            isinstance(default, (tuple, list)) and all(isinstance(x, int) for x in default))
        self.options = {}

    def name(self):
        return self._name

    def size_(self):
        return self.size

    def setOption(self, name, value, type_hint=None):
        self.options[name] = value


class _Point:
    def __init__(self, geo, number):
        self.geo, self._number = geo, number

    def number(self):
        return self._number

    def setAttribValue(self, name, value):
        self.geo._set(name, self._number, value)

    def attribValue(self, name):
        return self.geo.values[name][self._number]

    def position(self):
        return self.geo.values["P"][self._number]

    def setPosition(self, p):
        self.geo._set("P", self._number, tuple(float(x) for x in p))


class _Group:
    def __init__(self, name):
        self._name = name
        self.members = set()

    def name(self):
        return self._name

    def add(self, what):
        items = what if isinstance(what, (list, tuple)) else [what]
        for p in items:
            assert isinstance(p, _Point), "PointGroup.add takes points"
            self.members.add(p.number())


class _Geometry:
    def __init__(self):
        self.points = []
        self.attribs = {"P": _Attrib("P", (0.0, 0.0, 0.0))}
        self.values = {"P": []}
        self.groups = {}
        self.calls = []

    def _set(self, name, i, value):
        assert name in self.attribs, "no point attribute %r (addAttrib it first)" % name
        a = self.attribs[name]
        v = tuple(value) if isinstance(value, (tuple, list)) else (value,)
        assert len(v) == a.size, "%s holds %d values, not %d" % (name, a.size, len(v))
        self.values[name][i] = v if a.size > 1 else v[0]

    def createPoint(self):
        self.calls.append("createPoint")
        p = _Point(self, len(self.points))
        self.points.append(p)
        for name, a in self.attribs.items():
            self.values[name].append(a.default)
        return p

    def createPoints(self, positions):
        self.calls.append("createPoints")
        made = []
        for pos in positions:
            p = self.createPoint()
            p.setPosition(pos)
            made.append(p)
        return tuple(made)

    def addAttrib(self, attrib_type, name, default_value, transform_as_normal=False,
                  create_local_variable=True):
        assert attrib_type == FakeHou.attribType.Point, "only point attributes here"
        assert name not in self.attribs, "attribute %r already exists" % name
        self.calls.append("addAttrib " + name)
        a = _Attrib(name, default_value)
        self.attribs[name] = a
        self.values[name] = [default_value] * len(self.points)
        return a

    def findPointAttrib(self, name):
        return self.attribs.get(name)

    def _from_string(self, name, data, fmt):
        a = self.attribs.get(name)
        assert a is not None, "no point attribute %r" % name
        n = len(self.points) * a.size
        assert len(data) == 4 * n, "%s: %d bytes for %d values" % (name, len(data), n)
        flat = struct.unpack("<%d%s" % (n, fmt), data)
        for i in range(len(self.points)):
            v = flat[i * a.size:(i + 1) * a.size]
            self.values[name][i] = v if a.size > 1 else v[0]

    def setPointFloatAttribValuesFromString(self, name, values, float_type=None):
        self.calls.append("setPointFloatAttribValuesFromString " + name)
        assert not self.attribs[name].is_int, "%s is an integer attribute" % name
        self._from_string(name, bytes(values), "f")

    def setPointIntAttribValuesFromString(self, name, values, int_type=None):
        self.calls.append("setPointIntAttribValuesFromString " + name)
        assert self.attribs[name].is_int, "%s is a float attribute" % name
        self._from_string(name, bytes(values), "i")

    def createPointGroup(self, name, is_ordered=False):
        assert name not in self.groups, "group %r exists" % name
        g = _Group(name)
        self.groups[name] = g
        return g


class _Node:
    def __init__(self):
        self._geo = _Geometry()

    def geometry(self):
        return self._geo


class FakeHou(types.ModuleType):
    class attribType:
        Point, Prim, Vertex, Global = "Point", "Prim", "Vertex", "Global"

    class numericData:
        Float32, Float64, Int32 = "Float32", "Float64", "Int32"

    def __init__(self):
        super().__init__("hou")
        self.node = _Node()

    def pwd(self):
        return self.node


def check_houdini(namespace, hou):
    """What the Houdini snippet made equals its `packing`: one point per
    particle with P, pscale, orient, id and a group per pass. Returns a
    line of what was checked."""
    import numpy as np
    p = namespace["packing"]
    geo = hou.node.geometry()
    n = len(p)
    assert len(geo.points) == n > 0
    P = np.array(geo.values["P"], np.float64)
    np.testing.assert_array_equal(P.astype(np.float32), p.positions.astype(np.float32))
    np.testing.assert_array_equal(np.array(geo.values["pscale"], np.float32),
                                  p.radii.astype(np.float32))
    if p.orient is not None:
        np.testing.assert_array_equal(np.array(geo.values["orient"], np.float32),
                                      p.orient.astype(np.float32))
    np.testing.assert_array_equal(np.array(geo.values["id"]), np.arange(n))
    for g, name in enumerate(p.group_names):
        assert geo.groups[name].members == set(np.flatnonzero(p.groups == g).tolist()), name
    return "houdini: %d points with P, pscale%s, id and %d groups" % (
        n, ", orient" if p.orient is not None else "", len(geo.groups))


def run(doc, samples, workdir, log=print):
    """Runs the blocks of doc in workdir (with vdb_samples -> samples).
    Returns the number of blocks run and compiled."""
    text = open(doc, encoding="utf-8").read()
    os.makedirs(workdir, exist_ok=True)
    link = os.path.join(workdir, "vdb_samples")
    if not os.path.exists(link):
        os.symlink(os.path.abspath(samples), link)
    old = os.getcwd()
    os.chdir(workdir)
    ran = compiled = 0
    try:
        for tag, code, line in blocks(text):
            where = "%s:%d" % (os.path.basename(doc), line)
            compiled_code = compile(code, where, "exec")
            if tag == "blender":
                compiled += 1
                continue
            assert tag in ("", "houdini"), "%s: unknown block tag %r" % (where, tag)
            ns = {"__name__": "__doc_example__"}
            hou = None
            if tag == "houdini":
                hou = FakeHou()
                sys.modules["hou"] = hou
                ns["hou"] = hou
            try:
                exec(compiled_code, ns)
            except BaseException as e:
                raise AssertionError("%s: the example failed: %r" % (where, e)) from e
            finally:
                sys.modules.pop("hou", None)
            if hou is not None:
                log("%s: %s" % (where, check_houdini(ns, hou)))
            ran += 1
    finally:
        os.chdir(old)
    return ran, compiled


if __name__ == "__main__":
    r, c = run(sys.argv[1], sys.argv[2], sys.argv[3])
    print("ok: %d examples of %s ran, %d Blender examples compiled" % (r, sys.argv[1], c))
