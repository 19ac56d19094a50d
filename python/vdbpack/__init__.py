# SPDX-License-Identifier: Apache-2.0
"""vdbpack: fill containers with non-overlapping particles (Python module).

ctypes over the shared library libvdbpack (docs/python.md): no compile
step, and the same module works in any CPython 3 with numpy that can load
the library (Blender's and Houdini's own Pythons too).

    import vdbpack
    p = vdbpack.pack("vdb_samples/peanut.obj", method="lattice", count=20000)
    p.write("peanut.vdb")
    print(len(p), p.fraction, p.check("vdb_samples/peanut.obj").ok)

The library is found through $VDBPACK_LIBRARY (a path; when set, the only
one tried), else the path the build or installation wrote into
_libpath.py, else ctypes.util.find_library("vdbpack").
"""
from ._lib import LIBRARY_PATH as _LIBRARY_PATH, VERSION as _VERSION, SHAPES as _SHAPES
from ._errors import (Error, InvalidArgumentError, FileError, FormatError, OpenMeshError,
                      NotLevelSetError, BadContainerError, NoFitError, OutOfMemoryError,
                      CancelledError, InternalError)
from ._container import Container, MeshShape
from ._packing import Packing, Image, Report, read
from ._pack import pack, container_params

__version__ = _VERSION

SHAPES = _SHAPES
METHODS = ("lattice", "rsa", "relax", "jam")


def version():
    """The loaded library's version (vp_version()), "MAJOR.MINOR.PATCH"."""
    return _VERSION


def library_path():
    """The path (or name) of the libvdbpack that was loaded."""
    return _LIBRARY_PATH


__all__ = [
    "Container", "MeshShape", "Packing", "Image", "Report", "pack", "container_params", "read",
    "version",
    "library_path", "Error", "InvalidArgumentError", "FileError", "FormatError",
    "OpenMeshError", "NotLevelSetError", "BadContainerError", "NoFitError",
    "OutOfMemoryError", "CancelledError", "InternalError", "SHAPES", "METHODS",
]
