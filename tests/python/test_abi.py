# SPDX-License-Identifier: Apache-2.0
"""The ctypes mirror of the public structs (python/vdbpack/_lib.py) has
the size and field offsets the C compiler gives them from the headers
(tests/abi_layout.c, built by CMake: VP_ABI_LAYOUT), and the constants the
module copies have the headers' values."""
import ctypes
import json
import os
import subprocess

import pytest

from vdbpack import _lib


@pytest.fixture(scope="module")
def layout():
    prog = os.environ.get("VP_ABI_LAYOUT")
    assert prog and os.access(prog, os.X_OK), "VP_ABI_LAYOUT must name the abi_layout program"
    return json.loads(subprocess.run([prog], capture_output=True, text=True, check=True).stdout)


def test_every_struct_is_laid_out_as_in_c(layout):
    names = {s.__name__ for s in _lib.STRUCTS}
    assert names == set(layout["structs"]), "structs mirrored and structs measured differ"
    for s in _lib.STRUCTS:
        c = layout["structs"][s.__name__]
        assert ctypes.sizeof(s) == c["size"], s.__name__
        py_fields = [f[0] for f in s._fields_]
        assert py_fields == list(c["fields"]), "%s: fields %s, C has %s" % (
            s.__name__, py_fields, list(c["fields"]))
        for name, (offset, size) in c["fields"].items():
            assert getattr(s, name).offset == offset, "%s.%s" % (s.__name__, name)
            assert getattr(s, name).size == size, "%s.%s" % (s.__name__, name)


def test_enums_are_ints(layout):
    assert layout["enum_size"] == ctypes.sizeof(ctypes.c_int)


def test_constants(layout):
    k = layout["constants"]
    assert k["VP_MAX_GROUPS"] == _lib.VP_MAX_GROUPS
    assert k["VP_GROUP_NAME_MAX"] == _lib.VP_GROUP_NAME_MAX
    assert k["VP_SIZE_LIST_MAX"] == _lib.VP_SIZE_LIST_MAX
    assert k["VP_RSA_DEFAULT_RETRIES"] == _lib.VP_RSA_DEFAULT_RETRIES
    assert k["VP_RENDER_BACKGROUND_ID"] == _lib.VP_RENDER_BACKGROUND_ID
    for i, name in enumerate(_lib.RESULT_NAMES):
        assert k[name] == i
    assert k["VP_ERR_CANCELLED"] == _lib.VP_ERR_CANCELLED
    assert k["VP_ERR_INTERNAL"] == _lib.VP_ERR_INTERNAL
    for i, name in enumerate(_lib.SHAPES):
        assert k["VP_SHAPE_" + name.upper().replace("-", "_")] == i
    assert k["VP_SHAPE_COUNT"] == len(_lib.SHAPES)
    assert k["VP_SHAPE_MESH"] == _lib.VP_SHAPE_MESH
    assert k["VP_SHAPE_MIXED"] == _lib.VP_SHAPE_MIXED
    assert k["VP_MAX_SHAPES"] == _lib.VP_MAX_SHAPES
    assert k["VP_SHAPE_NAME_MAX"] == _lib.VP_SHAPE_NAME_MAX
    assert k["VP_LATTICE_DEFAULT"] == _lib.VP_LATTICE_DEFAULT
    for name, v in _lib.LATTICES.items():
        assert k["VP_LATTICE_" + name.upper()] == v
    assert (k["VP_FIT_INSIDE"], k["VP_FIT_CENTER"]) == (_lib.FITS["inside"], _lib.FITS["center"])
    for name, v in _lib.ORIENTS.items():
        assert k["VP_ORIENT_" + name.upper()] == v
    for name, v in _lib.OVERLAPS.items():
        assert k["VP_OVERLAP_" + name.upper()] == v
    for name, v in _lib.INSIDE_MODES.items():
        assert k["VP_INSIDE_" + name.upper()] == v
    for i, name in enumerate(_lib.KINDS):
        assert k["VP_CONTAINER_" + name.upper()] == i
    for i, name in enumerate(_lib.ESTIMATES):
        assert k["VP_ESTIMATE_" + name.upper()] == i
    for i, name in enumerate(_lib.RSA_STOPS):
        assert k["VP_RSA_STOP_" + name.upper()] == i
    for name, v in _lib.FORMATS.items():
        assert k["VP_FORMAT_" + name.upper()] == v
    for name, v in _lib.VIEWS.items():
        assert k["VP_VIEW_" + name.upper()] == v
    for name, v in _lib.COLOURS.items():
        assert k["VP_COLOUR_" + name.upper()] == v
    assert (k["VP_META_STRING"], k["VP_META_INT"], k["VP_META_DOUBLE"]) == (
        _lib.VP_META_STRING, _lib.VP_META_INT, _lib.VP_META_DOUBLE)
    assert k["VP_SIZE_CONSTANT"] == 0  # _pack.py tests radius.kind != 0 for distributions
