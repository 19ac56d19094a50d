# SPDX-License-Identifier: Apache-2.0
"""Containers and mesh particle shapes: Python objects that own a library
object (vp_container, vp_mesh_shape) and destroy it with a weakref
finalizer when they are collected."""
import ctypes
import math
import os
import re
import weakref

import numpy as np

from . import _arrays
from . import _call
from . import _lib
from ._lib import lib

# ---------------------------------------------------------------------------
# Container loading parameters


def _c_double(text):
    """A number as the command line parses one (strtod over the whole text,
    finite): no spaces, no underscores; hexadecimal floats too."""
    if not text or text != text.strip() or "_" in text:
        return None
    try:
        v = float.fromhex(text) if re.match(r"^[+-]?0[xX]", text) else float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


def parse_analytic(spec):
    """'sphere:R' or 'box:X,Y,Z' (centred at the origin) as ("sphere", R) or
    ("box", (X, Y, Z)); None when spec is not one; ValueError when it is
    malformed. As the command line, a file of that name wins (checked by
    the caller)."""
    def bad():
        return ValueError("malformed analytic container '%s' (sphere:R or box:X,Y,Z with "
                          "positive sizes)" % spec)
    if spec.startswith("sphere:"):
        r = _c_double(spec[7:])
        if r is None or not r > 0:
            raise bad()
        return ("sphere", r)
    if spec.startswith("box:"):
        parts = spec[4:].split(",")
        # strtok skips empty fields: "box:1,,1,1" is 1,1,1 on the command line
        parts = [p for p in parts if p]
        if len(parts) != 3:
            raise bad()
        e = [_c_double(p) for p in parts]
        if any(x is None or not x > 0 for x in e):
            raise bad()
        return ("box", tuple(e))
    return None


_LOAD_KEYS = ("voxel_size", "inside", "iso", "grid", "name", "particle_radius",
              "particle_count", "space_per_particle", "narrow_band", "extra_depth")


def container_params(cp, keep, voxel_size=None, inside=None, iso=None, grid=None, name=None,
                     particle_radius=None, particle_count=None, space_per_particle=None,
                     narrow_band=None, allow_open=None, extra_depth=None):
    """Fills vp_container_params cp (already initialised) from keywords;
    `keep` collects the bytes that cp points to."""
    if allow_open is not None:
        raise TypeError("allow_open was removed in vdbpack 0.2.0: an open mesh gets the inside "
                        "its winding number gives (inside='auto', the default; "
                        "inside='winding' forces it, inside='closed' refuses open meshes)")
    if voxel_size is not None:
        cp.voxel_size = _arrays.number(voxel_size, "voxel_size", positive=True, allow_zero=False)
    if inside is not None:
        cp.inside = _arrays.choice(inside, "inside", _lib.INSIDE_MODES)
    if iso is not None:
        cp.has_iso = 1
        cp.iso = _arrays.number(iso, "iso")
    if grid is not None:
        b = _arrays.text(grid, "grid")
        keep.append(b)
        cp.grid_name = b
    if name is not None:
        b = _arrays.text(name, "name")
        keep.append(b)
        cp.name = b
    if particle_radius is not None:
        cp.particle_radius = _arrays.number(particle_radius, "particle_radius", positive=True)
    if particle_count is not None:
        cp.particle_count = _arrays.whole(particle_count, "particle_count", 0)
    if space_per_particle is not None:
        cp.space_per_particle = _arrays.number(space_per_particle, "space_per_particle",
                                               positive=True)
    if narrow_band is not None:
        cp.narrow_band = 1 if narrow_band else 0
    if extra_depth is not None:
        cp.extra_depth = _arrays.number(extra_depth, "extra_depth", positive=True)
    return cp


def _info_dict(ci):
    def s(b):
        return b.decode("utf-8", "replace")
    kind = _lib.KINDS[ci.kind] if 0 <= ci.kind < len(_lib.KINDS) else str(ci.kind)
    d = {
        "kind": kind,
        "bmin": tuple(ci.bmin), "bmax": tuple(ci.bmax),
        "bounds": (tuple(ci.bmin), tuple(ci.bmax)),
        "volume": ci.volume, "voxel_size": ci.voxel_size, "interior_band": ci.interior_band,
        "voxel_reason": s(ci.voxel_reason), "grid_name": s(ci.grid_name),
        "active_voxels": ci.active_voxels,
    }
    if kind == "mesh":
        inside = {v: k for k, v in _lib.INSIDE_MODES.items()}.get(ci.inside, str(ci.inside))
        d.update({
            "mesh_vertices": ci.mesh_vertices, "mesh_vertices_raw": ci.mesh_vertices_raw,
            "mesh_triangles": ci.mesh_triangles, "boundary_edges": ci.boundary_edges,
            "nonmanifold_edges": ci.nonmanifold_edges, "mesh_volume": ci.mesh_volume,
            "inconsistent_edges": ci.inconsistent_edges, "mesh_pieces": ci.mesh_pieces,
            "inside": inside, "duplicate_triangles": ci.duplicate_triangles,
            "opposite_triangles": ci.opposite_triangles,
            "reoriented_triangles": ci.reoriented_triangles, "turned_pieces": ci.turned_pieces,
            "cavities": ci.cavities,
            "volume_estimate_kind": _lib.ESTIMATES[ci.volume_estimate_kind]
            if 0 <= ci.volume_estimate_kind < len(_lib.ESTIMATES) else str(ci.volume_estimate_kind),
            "volume_estimate": ci.volume_estimate, "volume_mismatch": bool(ci.volume_mismatch),
        })
    if ci.iso or kind == "level_set":
        d["iso"] = ci.iso
    return d


# ---------------------------------------------------------------------------
# Containers


class Container:
    """A closed region to fill: from a mesh or level-set file
    (from_file), numpy triangle arrays (from_mesh), an analytic box or
    sphere, or a Python distance function (from_function).

    Attributes: ``info`` (a dict: kind, bmin, bmax, bounds, volume,
    voxel_size, voxel_reason, grid_name, active_voxels, and for meshes
    the mesh counts and how the inside was decided), ``name`` (what
    metadata records as the container), ``volume``, ``bounds``."""

    def __init__(self, *args, **kwargs):
        raise TypeError("make a Container with Container.from_file, from_mesh, from_spec, "
                        "box, sphere or from_function")

    @classmethod
    def _wrap(cls, ptr, name, inside=None, keep=()):
        self = object.__new__(cls)
        self._ptr = ptr
        self._keep = tuple(keep)
        self._callback_error = None
        self.name = name
        self._inside = inside  # the inside mode asked for (metadata records it)
        # keep: ctypes callbacks the C object calls; they must outlive it
        self._finalizer = weakref.finalize(self, _destroy_container, ptr.value, self._keep)
        ci = _lib.vp_container_info()
        lib.vp_container_get_info(ptr, ctypes.byref(ci))
        self._info = _info_dict(ci)
        return self

    @property
    def info(self):
        return dict(self._info)

    @property
    def volume(self):
        return self._info["volume"]

    @property
    def bounds(self):
        return self._info["bounds"]

    @property
    def kind(self):
        return self._info["kind"]

    def __repr__(self):
        return "<vdbpack.Container %s %r volume %.6g>" % (self.kind, self.name, self.volume)

    # -- constructors ------------------------------------------------------

    @classmethod
    def from_file(cls, path, *, threads=None, max_memory=None, progress=None, **params):
        """Loads a closed mesh (OBJ, PLY, STL, glTF, anything Assimp reads)
        or a float level set from a .vdb. Keywords (all optional):
        voxel_size (world units; default automatic), inside ("auto",
        "closed", "winding": how a mesh's inside is decided), iso (a fog or
        density grid: inside where its value >= iso), grid (the .vdb grid's
        name), particle_radius / particle_count / space_per_particle /
        narrow_band / extra_depth (what the job needs of the level set, as
        vp_container_params; pack() sets them itself from its options when
        given a path), threads, max_memory, progress."""
        p = _arrays.path(path)
        _check_keys(params, _LOAD_KEYS + ("allow_open",), "Container.from_file")
        cp = _lib.vp_container_params()
        lib.vp_container_params_init(ctypes.byref(cp))
        keep = []
        container_params(cp, keep, **params)
        return _load(p, cp, os.path.basename(os.fsdecode(p)), params.get("inside", "auto"),
                     threads, max_memory, progress)

    @classmethod
    def from_spec(cls, spec, **params):
        """A file path, or an analytic 'box:X,Y,Z' / 'sphere:R' centred at the
        origin, as the command line takes a container (a file of that name
        wins). Keywords as for from_file (files only)."""
        s = os.fsdecode(os.fspath(spec)) if not isinstance(spec, str) else spec
        if not os.path.exists(s):
            a = parse_analytic(s)
            if a is not None:
                loading = [k for k in params if k in _LOAD_KEYS and params[k] is not None]
                if loading:
                    raise ValueError("%s need a mesh or .vdb container, not '%s'"
                                     % (", ".join(loading), s))
                return _analytic(a, s)
        return cls.from_file(spec, **params)

    @classmethod
    def from_mesh(cls, vertices, triangles, *, threads=None, max_memory=None, progress=None,
                  **params):
        """A container from a triangle mesh in memory: vertices (N, 3) real
        numbers (converted to float64), triangles (M, 3) integer indices
        into them (from 0). Welded, checked and voxelized exactly as a mesh
        file is. Keywords as for from_file, and name (the mesh's name in
        messages; default "mesh")."""
        v = _arrays.points(vertices, "vertices")
        t = _arrays.triangles(triangles)
        _check_keys(params, _LOAD_KEYS + ("allow_open",), "Container.from_mesh")
        cp = _lib.vp_container_params()
        lib.vp_container_params_init(ctypes.byref(cp))
        keep = [v, t]
        container_params(cp, keep, **params)
        out = ctypes.c_void_p()
        name = params.get("name") or "mesh"

        def call(ctx):
            return lib.vp_container_from_mesh(ctx, _arrays.ptr(v), v.shape[0], _arrays.ptr(t),
                                              t.shape[0], ctypes.byref(cp), ctypes.byref(out))
        try:
            _call.run(call, threads, max_memory, progress)
        except BaseException:
            lib.vp_container_destroy(out)
            raise
        return cls._wrap(out, name, params.get("inside", "auto"))

    @classmethod
    def box(cls, bmin, bmax):
        """The exact box [bmin, bmax] (world units)."""
        lo, hi = _arrays.vec3(bmin, "bmin"), _arrays.vec3(bmax, "bmax")
        out = ctypes.c_void_p()
        _call.quick(lambda ctx: lib.vp_container_create_box(ctx, _lib.c_double3(*lo),
                                                            _lib.c_double3(*hi),
                                                            ctypes.byref(out)))
        return cls._wrap(out, "box")

    @classmethod
    def sphere(cls, center, radius):
        """The exact ball of `radius` about `center`."""
        c = _arrays.vec3(center, "center")
        r = _arrays.number(radius, "radius")
        out = ctypes.c_void_p()
        _call.quick(lambda ctx: lib.vp_container_create_sphere(ctx, _lib.c_double3(*c), r,
                                                               ctypes.byref(out)))
        return cls._wrap(out, "sphere")

    @classmethod
    def from_function(cls, distance, bmin, bmax, volume, name="function"):
        """A container given by a Python signed-distance function
        distance(x, y, z) -> float (negative inside, positive outside, in
        world units; it should be a true distance, or at least never larger
        than one, near the wall), with bounds [bmin, bmax] that enclose the
        inside and its volume.

        The library calls it from its worker threads; each call takes the
        GIL, so they run one at a time, several microseconds each: fine for
        small jobs and prototypes, slow for large ones (write a level set to
        a .vdb instead). An exception in it, or a value that is not a
        finite number, stops the running call, which raises that exception
        (or ValueError)."""
        if not callable(distance):
            raise TypeError("distance must be a callable distance(x, y, z) -> float")
        lo, hi = _arrays.vec3(bmin, "bmin"), _arrays.vec3(bmax, "bmax")
        vol = _arrays.number(volume, "volume")
        holder = {"self": None}

        def fail(e):
            c = holder["self"]() if holder["self"] is not None else None
            if c is not None and c._callback_error is None:
                c._callback_error = e

        def trampoline(user, p):
            # Library threads, under the GIL. Never raise into C: record the
            # error (the running call is cancelled and raises it) and answer
            # "far outside", which no packer accepts.
            try:
                d = float(distance(p[0], p[1], p[2]))
                if math.isfinite(d):
                    return d
                fail(ValueError("the container's distance function returned %r at (%r, %r, %r)"
                                % (d, p[0], p[1], p[2])))
            except BaseException as e:  # noqa: B902
                fail(e)
            return 1e30

        fn = _lib.DISTANCE_FN(trampoline)
        ops = _lib.vp_container_ops()
        ops.distance = fn
        # gradient and destroy stay NULL: central differences, nothing to free
        out = ctypes.c_void_p()
        _call.quick(lambda ctx: lib.vp_container_create_custom(
            ctx, ctypes.byref(ops), None, _lib.c_double3(*lo), _lib.c_double3(*hi), vol,
            ctypes.byref(out)))
        self = cls._wrap(out, _arrays.text(name, "name").decode(), keep=(fn, ops))
        holder["self"] = weakref.ref(self)
        return self

    # -- queries -----------------------------------------------------------

    def distance(self, points):
        """Signed distances (negative inside) at points: an (N, 3) array
        gives (N,) float64, one point (x, y, z) a float."""
        a = np.asarray(points) if not isinstance(points, np.ndarray) else points
        single = a.ndim == 1
        pts = _arrays.points(a.reshape(1, -1) if single else a, "points", allow_empty=True)
        out = np.empty(pts.shape[0], np.float64)
        if pts.shape[0]:
            self._callback_error = None
            lib.vp_container_distances(self._ptr, _arrays.ptr(pts), pts.shape[0],
                                       _arrays.ptr(out))
            if self._callback_error is not None:
                e, self._callback_error = self._callback_error, None
                raise e
        return float(out[0]) if single else out

    def save(self, path, *, threads=None, max_memory=None, progress=None):
        """Writes a level-set container (from a file or a mesh) as its own
        .vdb, atomically. Analytic and function containers are refused
        (InvalidArgumentError)."""
        p = _arrays.path(path)
        _call.run(lambda ctx: lib.vp_container_save(ctx, self._ptr, p), threads, max_memory,
                  progress)


def _destroy_container(ptr, keep):
    lib.vp_container_destroy(ptr)


def _check_keys(params, allowed, where):
    for k in params:
        if k not in allowed:
            raise TypeError("%s() got an unexpected keyword argument '%s'" % (where, k))


def _load(path_bytes, cp, name, inside, threads, max_memory, progress, watch=()):
    out = ctypes.c_void_p()
    try:
        _call.run(lambda ctx: lib.vp_container_load(ctx, path_bytes, ctypes.byref(cp),
                                                    ctypes.byref(out)),
                  threads, max_memory, progress, watch)
    except BaseException:
        lib.vp_container_destroy(out)
        raise
    return Container._wrap(out, name, inside)


def _analytic(a, spec):
    kind, v = a
    if kind == "sphere":
        c = Container.sphere((0, 0, 0), v)
    else:
        c = Container.box(tuple(-x / 2 for x in v), tuple(x / 2 for x in v))
    c.name = spec
    return c


# ---------------------------------------------------------------------------
# Mesh particle shapes


class MeshShape:
    """A particle shape from a closed mesh, normalised as the library does
    (centroid of its volume at the origin, bounding radius 1). Attributes:
    name, volume (at bounding radius 1), inradius, triangles."""

    def __init__(self, *args, **kwargs):
        raise TypeError("make a MeshShape with MeshShape.from_file or MeshShape.from_mesh")

    @classmethod
    def _wrap(cls, ptr):
        self = object.__new__(cls)
        self._ptr = ptr
        self._finalizer = weakref.finalize(self, lib.vp_mesh_shape_destroy, ptr.value)
        self.name = lib.vp_mesh_shape_name(ptr).decode("utf-8", "replace")
        self.volume = lib.vp_mesh_shape_volume(ptr)
        self.inradius = lib.vp_mesh_shape_inradius(ptr)
        self.triangles = lib.vp_mesh_shape_triangles(ptr)
        return self

    def __repr__(self):
        return "<vdbpack.MeshShape %r, %d triangles>" % (self.name, self.triangles)

    @classmethod
    def from_file(cls, path, *, threads=None, progress=None):
        """A closed mesh file (anything Assimp reads; concave too)."""
        p = _arrays.path(path)
        out = ctypes.c_void_p()
        try:
            _call.run(lambda ctx: lib.vp_mesh_shape_load(ctx, p, ctypes.byref(out)), threads,
                      None, progress)
        except BaseException:
            lib.vp_mesh_shape_destroy(out)
            raise
        return cls._wrap(out)

    @classmethod
    def from_mesh(cls, vertices, triangles, name=None):
        """A closed triangle mesh in memory: vertices (N, 3), triangles
        (M, 3) integer indices; name is what files record (default
        "mesh")."""
        v = _arrays.points(vertices, "vertices")
        t = _arrays.triangles(triangles)
        n = _arrays.text(name, "name") if name is not None else None
        out = ctypes.c_void_p()
        try:
            _call.run(lambda ctx: lib.vp_mesh_shape_from_mesh(ctx, n, _arrays.ptr(v), v.shape[0],
                                                              _arrays.ptr(t), t.shape[0],
                                                              ctypes.byref(out)))
        except BaseException:
            lib.vp_mesh_shape_destroy(out)
            raise
        return cls._wrap(out)

    def write_obj(self, path):
        """Writes the normalised shape as OBJ (for instancing), atomically."""
        p = _arrays.path(path)
        _call.quick(lambda ctx: lib.vp_mesh_shape_write_obj(ctx, self._ptr, p))
