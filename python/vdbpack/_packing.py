# SPDX-License-Identifier: Apache-2.0
"""Packing: a particle set as numpy arrays, and what the library does with
one (write, check, render), and vdbpack.read.

A Packing holds only numpy arrays. Particle sets that the library makes
(pack, read) are copied into arrays and destroyed at once; for a library
call that takes a set, a vp_particles struct is built in Python whose
pointers point into C-contiguous copies of the arrays, kept alive for the
call. The library only reads such a set (every function that takes one
takes it const), so nothing is allocated by one side and freed by the
other: no leak, no double free."""
import ctypes
import json
import numbers
import os
import re
import warnings

import numpy as np

from . import _arrays
from . import _call
from . import _container
from . import _lib
from ._lib import lib

# what an unknown shape's message lists (as the command line's)
SHAPE_HELP = ("sphere, a platonic or Archimedean solid such as cube or truncated-octahedron "
              "(vdbpack.SHAPES lists them), superball:P")


def shape_name(shape_id, param=0.0):
    """The shape as files record it ("cube", "superball:2"): the library's
    vp_shape_format."""
    if shape_id == _lib.VP_SHAPE_MESH:
        return "mesh"
    buf = ctypes.create_string_buffer(64)
    lib.vp_shape_format(shape_id, float(param), buf, len(buf))
    return buf.value.decode() or str(shape_id)


def parse_shape(text):
    """A built-in shape's text as the command line takes it ("cube",
    "Truncated_Cube", "superball:2"; and "mesh"), parsed by the library
    (vp_shape_parse_param): (vp_shape id, exponent or 0, the name files
    record), or None when the text names no built-in shape. A superball
    whose exponent the library does not offer raises ValueError with the
    command line's message."""
    b = _arrays.text(text, "shape")
    if text == "mesh":
        return _lib.VP_SHAPE_MESH, 0.0, "mesh"
    sid, param = ctypes.c_int(0), ctypes.c_double(0.0)
    r = lib.vp_shape_parse_param(b, ctypes.byref(sid), ctypes.byref(param))
    if r == -2:
        raise ValueError("shape '%s': a superball's exponent P (superball:P) must be a number in "
                         "[0.5, 1000] (convex superballs; concave ones, P < 0.5, are not offered)"
                         % text)
    if r != 0:
        return None
    return sid.value, param.value, shape_name(sid.value, param.value)


def _ref_name(shape_id, param, mesh, recorded=""):
    """One shape of a mixed set as vp_particles_shape_list names it:
    "cube", "superball:2", "mesh:NAME" (the MeshShape's name, else the
    name the file recorded), or "mesh"."""
    if shape_id == _lib.VP_SHAPE_MESH:
        if mesh is not None:
            return "mesh:" + mesh.name
        return "mesh:" + recorded if recorded else "mesh"
    return shape_name(shape_id, param)


def _mesh_ptr_name(ptr):
    return lib.vp_mesh_shape_name(ptr).decode("utf-8", "replace")


def _known_shape(text, also=""):
    """parse_shape, raising ValueError for a text that names no built-in shape."""
    s = parse_shape(text)
    if s is None:
        raise ValueError("unknown shape '%s' (%s%s)" % (text, SHAPE_HELP, also))
    return s


def _shape_arrays(s, param, ptr):
    """vp_shape_mesh of one shape as (vertices, faces)."""
    n = [ctypes.c_size_t(0) for _ in range(3)]
    _call.quick(lambda ctx: lib.vp_shape_mesh(ctx, s, param, ptr, None, ctypes.byref(n[0]),
                                              None, ctypes.byref(n[1]), None,
                                              ctypes.byref(n[2])))
    v = np.empty((n[0].value, 3), np.float64)
    sizes = np.empty(n[1].value, np.uint32)
    idx = np.empty(n[2].value, np.uint32)
    _call.quick(lambda ctx: lib.vp_shape_mesh(
        ctx, s, param, ptr, v.ctypes.data, ctypes.byref(n[0]), sizes.ctypes.data,
        ctypes.byref(n[1]), idx.ctypes.data, ctypes.byref(n[2])))
    ends = np.cumsum(sizes.astype(np.int64))
    return v, [idx[e - k:e].tolist() for e, k in zip(ends, sizes.astype(np.int64))]


def _shape_list(c):
    """vp_particles_shape_list of the set c: "cube;mesh:rock.obj;sphere"."""
    buf = ctypes.create_string_buffer(4096)
    lib.vp_particles_shape_list(ctypes.byref(c), buf, len(buf))
    return buf.value.decode("utf-8", "replace")


class Report(dict):
    """A dict whose keys are also attributes (report.fraction)."""

    def __getattr__(self, key):
        try:
            return self[key]
        except KeyError:
            raise AttributeError(key) from None


class Image:
    """A rendered preview: rgba (H, W, 4) float32, linear, premultiplied;
    z (H, W) float32, the distance from the eye (+inf on the background);
    id (H, W) uint32, the visible particle's id (0xFFFFFFFF on the
    background). Row 0 is the top."""

    def __init__(self, rgba, z, id):  # noqa: A002 -- the channel's name
        self.rgba, self.z, self.id = rgba, z, id

    @property
    def width(self):
        return self.rgba.shape[1]

    @property
    def height(self):
        return self.rgba.shape[0]

    def __repr__(self):
        return "<vdbpack.Image %dx%d>" % (self.width, self.height)


class Packing:
    """Particles as numpy arrays:

    - ``positions`` (N, 3) float64: centres;
    - ``radii`` (N,) float64: bounding-sphere radii (pscale). The library
      holds radii as float32: these are those values exactly, and are
      rounded to float32 again when written or checked;
    - ``ids`` (N,) int32: 0..N-1, what files store as ``id`` (read-only);
    - ``orient`` (N, 4) float64 unit quaternions (x, y, z, w), or None for
      spheres (float32 in the library, as radii);
    - ``groups`` (N,) int32 indices into ``group_names`` (one group per rsa
      pass: pass1, pass2, ...);
    - ``shape``: as files record it: "sphere", a solid of vdbpack.SHAPES
      ("cube", "snub-cube", ...), "superball:P" with its exponent, or
      "mesh" (then ``mesh_shape`` is the MeshShape, or None when read from
      a file and not given), or "mixed": particles of several shapes (rsa
      passes with shapes of their own), then
    - ``shapes``: the shapes' names in index order, as files record them
      ("cube", "superball:2", "mesh:rock.obj"), ``shape_index`` (N,)
      uint8: each particle's index into them, and ``mesh_shapes``: a list
      aligned with ``shapes``, the MeshShape of each mesh shape (None for
      the others, and for a mesh shape read from a file and not given).
      All three are None for a packing of one shape;
    - ``report``: the packer's figures (dict), ``metadata``: what a .vdb
      records (dict), ``method``, ``fraction`` (particle volume / container
      volume, when the container is known), ``position_error`` (read from a
      .vdb: its positions' error bound, else 0).

    A Packing may be made from arrays (Packing(positions, radii, ...)) or
    changed in place; write, check and render use the arrays as they are
    then.
    """

    def __init__(self, positions, radii, orient=None, groups=None, group_names=None,
                 shape="sphere", mesh_shape=None, shapes=None, shape_index=None,
                 mesh_shapes=None):
        self.positions = _arrays.points(positions, "positions", allow_empty=True)
        n = len(self.positions)
        r = np.asarray(radii, dtype=np.float64) if not isinstance(radii, numbers.Real) else \
            np.full(n, float(radii))
        self.radii = r
        self.orient = None if orient is None else np.asarray(orient, dtype=np.float64)
        self.groups = np.zeros(n, np.int32) if groups is None else np.asarray(groups)
        self.group_names = list(group_names) if group_names is not None else ["pass1"]
        if isinstance(shape, _container.MeshShape):
            mesh_shape, shape = shape, "mesh"
        self.shape = shape
        self.mesh_shape = mesh_shape
        # a mixed set: shapes may name a mesh shape by its MeshShape
        if shapes is not None:
            shapes = list(shapes)
            ms = list(mesh_shapes) if mesh_shapes is not None else [None] * len(shapes)
            if len(ms) != len(shapes):
                raise ValueError("mesh_shapes must be aligned with shapes (%d), not hold %d"
                                 % (len(shapes), len(ms)))
            for k, v in enumerate(shapes):
                if isinstance(v, _container.MeshShape):
                    shapes[k], ms[k] = "mesh:" + v.name, v
            mesh_shapes = ms
        self.shapes = shapes
        self.shape_index = None if shape_index is None else np.asarray(shape_index)
        self.mesh_shapes = mesh_shapes
        self.report = Report()
        self.metadata = {}
        self.method = None
        self.fraction = None
        self.container_volume = None
        self.position_error = 0.0
        self._full_precision = True

    # -- conversion from and to the library's particle sets ----------------

    @classmethod
    def _from_c(cls, p, mesh_shape=None, meshes=None):
        """Copies the library's set *p (a POINTER(vp_particles)). meshes:
        {mesh pointer: MeshShape} of the mesh shapes the set may point to
        (a mixed set's, or a one-shape set's when mesh_shape is None)."""
        q = p.contents
        n = q.count

        def arr(ptr, ctype, count):
            if not count or not ptr:
                return np.zeros(count, ctype)
            return np.ctypeslib.as_array(ptr, shape=(count,)).copy()
        pos = arr(q.positions, np.float64, 3 * n).reshape(n, 3)
        radii = arr(q.radii, np.float32, n).astype(np.float64) if q.radii else \
            np.full(n, q.uniform_radius, np.float64)
        orient = None
        if q.has_orient:
            orient = arr(q.orients, np.float32, 4 * n).reshape(n, 4).astype(np.float64) \
                if q.orients else np.tile(np.array(q.uniform_orient, np.float64), (n, 1))
        groups = arr(q.groups, np.uint16, n).astype(np.int32) if q.groups else \
            np.zeros(n, np.int32)
        names = [q.group_names[i].value.decode("utf-8", "replace")
                 for i in range(max(1, min(q.group_count, _lib.VP_MAX_GROUPS)))]
        meshes = meshes or {}
        if q.shape == _lib.VP_SHAPE_MESH and q.mesh in meshes:
            mesh_shape = meshes[q.mesh]  # (a pass's own, perhaps not shape='s)
        shapes = shape_index = mesh_shapes = None
        if q.shape == _lib.VP_SHAPE_MIXED:
            k = min(q.shape_count, _lib.VP_MAX_SHAPES)
            mesh_shapes = [meshes.get(q.shapes[i].mesh) if q.shapes[i].mesh else None
                           for i in range(k)]
            shapes = []
            for i in range(k):
                ref = q.shapes[i]
                name = _ref_name(ref.shape, ref.param, None,
                                 q.shape_names[i].value.decode("utf-8", "replace"))
                if ref.shape == _lib.VP_SHAPE_MESH and ref.mesh:
                    name = "mesh:" + _mesh_ptr_name(ref.mesh)
                shapes.append(name)
            shape_index = arr(q.shape_index, np.uint8, n)
        self = cls(pos, radii, orient, groups, names, shape_name(q.shape, q.shape_param),
                   mesh_shape if q.shape == _lib.VP_SHAPE_MESH else None, shapes, shape_index,
                   mesh_shapes)
        self.position_error = q.position_error
        return self

    def _c(self, need_mesh=False, what="this"):
        """A vp_particles over C-contiguous copies of the arrays, and the
        list of what must stay alive while the library reads it."""
        pos = _arrays.points(self.positions, "positions", allow_empty=True)
        n = pos.shape[0]
        radii = np.asarray(self.radii)
        if radii.dtype.kind not in "fiu" or radii.shape != (n,):
            raise ValueError("radii must be %d real numbers (one per position), not %s of %s"
                             % (n, radii.shape, radii.dtype))
        radii = np.require(radii, np.float32, ["C_CONTIGUOUS", "ALIGNED"])
        if n and not (np.all(np.isfinite(pos))):
            raise ValueError("positions must be finite (row %d is not)"
                             % int(np.argwhere(~np.isfinite(pos))[0][0]))
        if n and not np.all((radii > 0) & np.isfinite(radii)):
            raise ValueError("radii must be finite and > 0 as float32 (radius %d is %r)"
                             % (int(np.argwhere(~((radii > 0) & np.isfinite(radii)))[0][0]),
                                float(radii[~((radii > 0) & np.isfinite(radii))][0])))
        shape = self.shape
        if not isinstance(shape, str):
            raise TypeError("shape must be a str (a name such as 'cube' or 'superball:2', "
                            "'mesh' or 'mixed'), not %r" % (shape,))
        mixed = shape == "mixed"
        shape_id, shape_param, _ = (_lib.VP_SHAPE_MIXED, 0.0, "mixed") if mixed else \
            _known_shape(shape, ", mesh, mixed")
        mesh = self.mesh_shape
        if shape == "mesh" and need_mesh and mesh is None:
            raise ValueError("%s packing holds particles of a mesh shape%s: set its mesh_shape "
                             "(vdbpack.MeshShape.from_file(...)) or read it with shape=MeshShape"
                             % (what, " (%s)" % self.metadata.get("shape_file")
                                if self.metadata.get("shape_file") else ""))
        orient = None
        if self.orient is not None:
            o = np.asarray(self.orient)
            if o.dtype.kind not in "fiu" or o.shape != (n, 4):
                raise ValueError("orient must be an (%d, 4) array of quaternions (x, y, z, w), "
                                 "not %s of %s" % (n, o.shape, o.dtype))
            orient = np.require(o, np.float32, ["C_CONTIGUOUS", "ALIGNED"])
        names = list(self.group_names)
        if not 1 <= len(names) <= _lib.VP_MAX_GROUPS:
            raise ValueError("group_names must hold 1 to %d names, not %d"
                             % (_lib.VP_MAX_GROUPS, len(names)))
        g = np.asarray(self.groups)
        if g.shape != (n,) or (n and g.dtype.kind not in "iu"):
            raise ValueError("groups must be %d integer group indices, not %s of %s"
                             % (n, g.shape, g.dtype))
        if n and (int(g.min()) < 0 or int(g.max()) >= len(names)):
            raise ValueError("groups must be indices into group_names (0..%d), not %d"
                             % (len(names) - 1, int(g.min()) if g.min() < 0 else int(g.max())))
        groups = np.require(g, np.uint16, ["C_CONTIGUOUS", "ALIGNED"])
        c = _lib.vp_particles()
        c.count = c.capacity = n
        c.positions = pos.ctypes.data_as(ctypes.POINTER(ctypes.c_double)) if n else None
        # One value for all is held as the library holds it (a NULL array
        # and the uniform value), so that a set read or packed and given
        # back is the same set to the library, down to the order of its sums.
        if n and np.all(radii == radii[0]):
            c.uniform_radius = float(radii[0])
        elif n:
            c.radii = radii.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
        c.uniform_orient[3] = 1.0
        if orient is not None:
            c.has_orient = 1
            if n and np.all(orient == orient[0]):
                c.uniform_orient[:] = [float(x) for x in orient[0]]
            elif n:
                c.orients = orient.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
        c.shape = shape_id
        c.shape_param = shape_param
        c.mesh = mesh._ptr.value if (shape == "mesh" and mesh is not None) else None
        mixed_keep = self._mixed_c(c, n, need_mesh, what) if mixed else None
        if n and np.any(groups != 0):
            c.groups = groups.ctypes.data_as(ctypes.POINTER(ctypes.c_uint16))
        c.group_count = len(names)
        for i, name in enumerate(names):
            c.group_names[i].value = _arrays.text(name, "group_names[%d]" % i,
                                                  _lib.VP_GROUP_NAME_MAX)
        c.position_error = float(self.position_error or 0.0)
        return c, [pos, radii, orient, groups, mesh, mixed_keep]

    def _mixed_refs(self):
        """A mixed set's shapes checked: [(vp_shape, exponent, MeshShape or
        None, recorded mesh name)] in index order."""
        shapes = self.shapes
        if isinstance(shapes, str) or not isinstance(shapes, (list, tuple)):
            raise TypeError("a packing of shape 'mixed' needs shapes, a list of shape names "
                            "('cube', 'superball:2', 'mesh:rock.obj'), not %r" % (shapes,))
        if not 1 <= len(shapes) <= _lib.VP_MAX_SHAPES:
            raise ValueError("shapes must hold 1 to %d shapes, not %d"
                             % (_lib.VP_MAX_SHAPES, len(shapes)))
        ms = self.mesh_shapes
        if ms is None:
            ms = [None] * len(shapes)
        if not isinstance(ms, (list, tuple)) or len(ms) != len(shapes):
            raise ValueError("mesh_shapes must be a list aligned with shapes (%d entries), not %r"
                             % (len(shapes), ms))
        out = []
        for k, (name, m) in enumerate(zip(shapes, ms)):
            if m is not None and not isinstance(m, _container.MeshShape):
                raise TypeError("mesh_shapes[%d] must be a vdbpack.MeshShape or None, not %r"
                                % (k, m))
            if not isinstance(name, str):
                raise TypeError("shapes[%d] must be a shape name, not %r" % (k, name))
            if name == "mesh" or name.startswith("mesh:"):
                out.append((_lib.VP_SHAPE_MESH, 0.0, m, name[5:]))
                continue
            if m is not None:
                raise ValueError("mesh_shapes[%d] is a MeshShape but shapes[%d] is %r, not a "
                                 "mesh shape ('mesh:NAME')" % (k, k, name))
            s = parse_shape(name)
            if s is None or s[0] == _lib.VP_SHAPE_MESH:
                raise ValueError("shapes[%d]: unknown shape '%s' (%s, mesh:NAME)"
                                 % (k, name, SHAPE_HELP))
            out.append((s[0], s[1], None, ""))
        return out

    def _mixed_c(self, c, n, need_mesh, what):
        """Fills a mixed set's shape_index, shapes and shape_names into c;
        returns what must stay alive."""
        refs = self._mixed_refs()
        if need_mesh:
            missing = [k for k, r in enumerate(refs) if r[0] == _lib.VP_SHAPE_MESH and
                       r[2] is None]
            if missing:
                raise ValueError("%s packing holds particles of mesh shapes (%s): set its "
                                 "mesh_shapes[%s] (vdbpack.MeshShape.from_file(...)) or read it "
                                 "with shape=[MeshShape, ...], one per mesh shape in the order "
                                 "of its shapes"
                                 % (what, ", ".join(self.shapes[k] for k in missing),
                                    ", ".join(str(k) for k in missing)))
        si = np.asarray(self.shape_index) if self.shape_index is not None else None
        if si is None or si.shape != (n,) or (n and si.dtype.kind not in "iu"):
            raise ValueError("shape_index must be %d integer indices into shapes, not %s"
                             % (n, "None" if si is None else "%s of %s" % (si.shape, si.dtype)))
        if n and (int(si.min()) < 0 or int(si.max()) >= len(refs)):
            raise ValueError("shape_index must hold indices into shapes (0..%d), not %d"
                             % (len(refs) - 1, int(si.min()) if si.min() < 0 else int(si.max())))
        si = np.require(si, np.uint8, ["C_CONTIGUOUS", "ALIGNED"])
        if n:
            c.shape_index = si.ctypes.data_as(ctypes.POINTER(ctypes.c_uint8))
        c.shape_count = len(refs)
        for k, (sid, param, m, recorded) in enumerate(refs):
            c.shapes[k].shape, c.shapes[k].param = sid, param
            c.shapes[k].mesh = m._ptr.value if m is not None else None
            b = recorded.encode("utf-8", "replace")[:_lib.VP_SHAPE_NAME_MAX - 1]
            c.shape_names[k].value = b
        if not c.has_orient:  # (every particle of a mixed set has an orientation)
            c.has_orient = 1
        c.mesh = None
        return [si, refs]

    # -- the basics --------------------------------------------------------

    def __len__(self):
        return len(self.positions)

    @property
    def ids(self):
        """0..N-1 (int32): the id a file stores for each particle."""
        return np.arange(len(self), dtype=np.int32)

    def __repr__(self):
        if self.shape == "mixed":
            return "<vdbpack.Packing of %d particle%s of %d shapes>" % (
                len(self), "" if len(self) == 1 else "s", len(self.shapes or ()))
        return "<vdbpack.Packing of %d %s%s>" % (len(self), self.shape,
                                                 "" if len(self) == 1 else "s")

    def volume(self):
        """The particles' volume (shape volume times radius cubed)."""
        c, keep = self._c(need_mesh=True, what="a volume of this")
        return lib.vp_particles_volume(ctypes.byref(c))

    # -- output ------------------------------------------------------------

    def write(self, path, format=None, precision=None, metadata=None, *,  # noqa: A002
              sphere_subdivisions=None, threads=None, max_memory=None, progress=None):
        """Writes the particles to path, atomically (a failed write leaves
        nothing there): .vdb (OpenVDB points: P, pscale, id, orient, a group
        per pass, and metadata), .ply, .csv or .obj, by the extension or
        format="vdb"|"ply"|"csv"|"obj" (docs/export.md).

        precision: .vdb positions, "fixed16" or "full" (32-bit float);
        default as the command line: fixed16 for lattice packings, full for
        rsa, relax and jam (whose particles touch) and for packings read from
        files. metadata: a dict added to (and overriding) the packing's own
        (str, int, float values; None removes a key); .ply and .obj get it
        as comments, .csv has none. sphere_subdivisions: .obj spheres (1..16,
        default 2). Returns the .vdb's write report (a dict: full_precision,
        promoted, voxel_size, position_error, ...) or None for other formats.
        """
        p = _arrays.path(path)
        if format is None:
            fmt = lib.vp_format_from_path(p)
            if not fmt:
                raise ValueError("cannot tell the format of '%s' from its extension: give "
                                 "format='vdb', 'ply', 'csv' or 'obj'" % os.fsdecode(p))
        else:
            fmt = _arrays.choice(format, "format", _lib.FORMATS)
        if precision is None:
            full = self._full_precision
        elif precision in ("full", "float"):
            full = True
        elif precision in ("fixed16", "16"):
            full = False
        else:
            raise ValueError("unknown precision %r (fixed16, full)" % (precision,))
        c, keep = self._c(need_mesh=fmt == _lib.FORMATS["obj"], what="an .obj of this")
        meta = dict(self.metadata)
        meta["particle_count"] = len(self)
        if c.shape == _lib.VP_SHAPE_MIXED:  # the shapes the "shape" attribute indexes
            meta["shapes"] = _shape_list(c)
        else:
            meta.pop("shapes", None)
        if metadata is not None:
            if not isinstance(metadata, dict):
                raise TypeError("metadata must be a dict, not %r" % (metadata,))
            meta.update(metadata)
        for k in _WRITER_KEYS:
            meta.pop(k, None)
        meta["shape"] = shape_name(c.shape, c.shape_param)  # as the library formats it
        metas, nmeta, mkeep = _meta_array(meta)
        ep = _lib.vp_export_params()
        lib.vp_export_params_init(ctypes.byref(ep))
        ep.format = fmt
        ep.vdb.full_precision = 1 if full else 0
        ep.vdb.meta = metas
        ep.vdb.meta_count = nmeta
        rep = _lib.vp_write_report()
        ep.vdb.report = ctypes.pointer(rep)
        if sphere_subdivisions is not None:
            ep.sphere_subdivisions = _arrays.whole(sphere_subdivisions, "sphere_subdivisions",
                                                   1, 16)
        _call.run(lambda ctx: lib.vp_export(ctx, p, ctypes.byref(c), ctypes.byref(ep)),
                  threads, max_memory, progress)
        del keep, mkeep
        if fmt != _lib.FORMATS["vdb"]:
            return None
        return Report((k, getattr(rep, k)) for k, _ in rep._fields_)

    def write_shape(self, path):
        """Writes the unit particle shape (circumradius 1, centroid at the
        origin, the orientation identity means) as OBJ, for instancing:
        the command line's --shape-out. A packing of several shapes writes
        them all to one OBJ, group shapeK for shape K (its shape_index;
        spheres as icospheres: vp_particles_write_shapes_obj)."""
        p = _arrays.path(path)
        if self.shape == "mixed":
            c, keep = self._c(need_mesh=True, what="to write the shapes of this")
            _call.quick(lambda ctx: lib.vp_particles_write_shapes_obj(ctx, ctypes.byref(c), p))
            del keep
            return None
        if self.shape == "mesh":
            if self.mesh_shape is None:
                raise ValueError("this packing holds particles of a mesh shape: set its "
                                 "mesh_shape first")
            return self.mesh_shape.write_obj(path)
        s, param, _ = _known_shape(self.shape)
        _call.quick(lambda ctx: lib.vp_shape_write_obj_param(ctx, s, param, p))

    def shape_mesh(self, index=None):
        """The unit particle shape that write_shape writes, as arrays
        (vp_shape_mesh, no file): vertices (V, 3) float64 and faces, a list
        of lists of vertex indices, each counter-clockwise seen from
        outside (a solid's polygons; a superball's or a mesh shape's
        triangles). ValueError for spheres, which have no polygons
        (instance a sphere of radius 1). A packing of several shapes:
        index K gives shapes[K]'s."""
        if self.shape == "mixed":
            if index is None:
                raise ValueError("this packing holds several shapes (%s): give shape_mesh the "
                                 "index of one" % ";".join(self.shapes or ()))
            refs = self._mixed_refs()
            k = _arrays.whole(index, "index", 0, len(refs) - 1)
            s, param, m, _ = refs[k]
            if s == _lib.VP_SHAPE_MESH and m is None:
                raise ValueError("shape %d (%s) is a mesh shape: set mesh_shapes[%d] first"
                                 % (k, self.shapes[k], k))
            if s == _lib.VP_SHAPE_SPHERE:
                raise ValueError("shape %d is a sphere, which has no polygons (instance a sphere "
                                 "of radius 1)" % k)
            return _shape_arrays(s, param, m._ptr.value if m is not None else None)
        if index is not None:
            raise ValueError("index is for packings of several shapes; this one holds %ss"
                             % self.shape)
        if self.shape == "mesh":
            if self.mesh_shape is None:
                raise ValueError("this packing holds particles of a mesh shape: set its "
                                 "mesh_shape first")
            s, param, ptr = _lib.VP_SHAPE_MESH, 0.0, self.mesh_shape._ptr.value
        else:
            s, param, _ = _known_shape(self.shape)
            ptr = None
        return _shape_arrays(s, param, ptr)

    # -- checking ----------------------------------------------------------

    def check(self, container, fit=None, *, overlap_tolerance=None, contact_tolerance=None,
              wall_tolerance=None, position_tolerance=None, margin=None, gap=None, threads=None,
              max_memory=None, progress=None, **load):
        """Recomputes overlaps, particles outside the container, the packing
        fraction and contacts (vdbpack check). container: a Container, or a
        path / 'box:X,Y,Z' / 'sphere:R' loaded as `vdbpack check` loads it
        (voxel_size, inside, iso from the packing's metadata unless given;
        grid). fit: "inside" or "center" (default: the metadata's fit, else
        inside). margin, gap: distances to keep from the wall and between
        sphere surfaces (default: the metadata's, else 0). Returns a Report (dict with attribute access) with the
        keys of `vdbpack check --json`: overlapping_pairs, max_overlap,
        outside, packing_fraction (also as fraction), mean_contacts, ok,
        ..."""
        for k in load:
            if k not in ("voxel_size", "inside", "iso", "grid"):
                raise TypeError("check() got an unexpected keyword argument '%s'" % k)
        cp = _lib.vp_check_params()
        lib.vp_check_params_init(ctypes.byref(cp))
        md = self.metadata
        if fit is None:
            fit = "center" if md.get("fit") == "center" else "inside"
        cp.fit = _arrays.choice(fit, "fit", _lib.FITS)
        for name in ("overlap_tolerance", "contact_tolerance", "position_tolerance"):
            v = locals()[name]
            if v is not None:
                setattr(cp, name, _arrays.number(v, name, positive=True))
        if wall_tolerance is not None:
            cp.wall_tolerance = _arrays.number(wall_tolerance, "wall_tolerance", positive=True)
        for name, v in (("margin", margin), ("gap", gap)):
            if v is None:
                v = _meta_float(md.get(name))
                if v is None or not v >= 0:
                    continue
            setattr(cp, name, _arrays.number(v, name, positive=True))
        c, keep = self._c(need_mesh=True, what="to check this")
        watch = ()
        if isinstance(container, _container.Container):
            if any(v is not None for v in load.values()):
                raise ValueError("%s are for loading a container from a file: pass them to "
                                 "Container.from_file, or give check() the path"
                                 % ", ".join(k for k, v in load.items() if v is not None))
            cont, name, watch = container, container.name, (container,)
        else:
            spec = os.fsdecode(os.fspath(container))
            kw = dict(load)
            a = None if os.path.exists(spec) else _container.parse_analytic(spec)
            if a is not None:
                if any(v is not None for v in kw.values()):
                    raise ValueError("voxel_size, grid, inside and iso need a mesh or .vdb "
                                     "container, not '%s'" % spec)
                cont = _container._analytic(a, spec)
            else:
                if kw.get("voxel_size") is None:
                    v = _meta_float(md.get("voxel_size"))
                    if v is not None and v > 0:
                        kw["voxel_size"] = v
                if kw.get("inside") is None and md.get("inside") in _lib.INSIDE_MODES:
                    kw["inside"] = md["inside"]
                if kw.get("iso") is None and lib.vp_format_from_path(os.fsencode(spec)) == \
                        _lib.FORMATS["vdb"]:
                    v = _meta_float(md.get("iso"))
                    if v is not None:
                        kw["iso"] = v
                rmax = float(np.max(self.radii)) if len(self) else 0.0
                kw["particle_radius"] = rmax if rmax > 0 else 0.0
                kw["particle_count"] = len(self)
                kw["extra_depth"] = cp.margin  # the wall test reads the margin deeper
                cont = _container.Container.from_file(spec, threads=threads,
                                                      max_memory=max_memory, progress=progress,
                                                      **kw)
            name = spec
        rep = _lib.vp_check_report()
        _call.run(lambda ctx: lib.vp_check_particles(ctx, cont._ptr, ctypes.byref(c),
                                                     ctypes.byref(cp), ctypes.byref(rep)),
                  threads, max_memory, progress, watch)
        del keep
        bad = rep.overlapping_pairs > 0 or rep.outside > 0 or bool(rep.imprecise)
        return Report([
            ("container", name), ("margin", cp.margin), ("gap", cp.gap),
            ("fit", "inside" if cp.fit == 0 else "center"),
            ("shape", self.shape), ("count", rep.count),
            ("overlapping_pairs", rep.overlapping_pairs), ("max_overlap", rep.max_overlap),
            ("max_overlap_world", rep.max_overlap_world),
            ("overlap_tolerance", cp.overlap_tolerance),
            ("position_error", float(self.position_error or 0.0)),
            ("position_error_ratio", rep.position_error_ratio),
            ("imprecise", bool(rep.imprecise)), ("outside", rep.outside),
            ("max_outside", rep.max_outside), ("particle_volume", rep.particle_volume),
            ("container_volume", rep.container_volume), ("packing_fraction", rep.fraction),
            ("fraction", rep.fraction),
            ("contact_pairs", rep.contact_pairs), ("mean_contacts", rep.mean_contacts),
            ("contact_tolerance", cp.contact_tolerance), ("ok", not bad),
            ("seconds", rep.seconds)])

    # -- preview -----------------------------------------------------------

    def render(self, path=None, *, size=None, width=None, height=None, view="iso", eye=None,
               target=None, up=None, fov=None, colour=None, color=None, cut=None, ao=None,
               shadows=True, threads=None, max_memory=None, progress=None):
        """Ray-traces a preview (vdbpack render): spheres or the solids in
        their orientations, key light, shadows, ambient occlusion, framed
        automatically. Writes path (.png 8-bit sRGB, or .exr with R, G, B,
        A, Z and id) when given, and returns an Image (rgba, z, id arrays).

        size "WxH" or (W, H) (or width=, height=; default 960x540); view
        "iso", "front" or "top", or eye=(x, y, z) with target=(x, y, z)
        (and up); fov in degrees (30); colour "pass", "size", "id" or
        "contacts" (spheres: touching neighbours, as vdbpack render); cut
        "z:0" or ("z", 0.0) removes what lies beyond the plane; ao: ambient
        occlusion rays a pixel (8; 0..64); shadows (True)."""
        rp = _lib.vp_render_params()
        lib.vp_render_params_init(ctypes.byref(rp))
        if size is not None:
            if width is not None or height is not None:
                raise ValueError("give size or width/height, not both")
            if isinstance(size, str):
                m = re.fullmatch(r"(\d+)[xX](\d+)", size)
                if not m:
                    raise ValueError("size must be 'WxH' or (W, H), not %r" % (size,))
                width, height = int(m.group(1)), int(m.group(2))
            else:
                try:
                    width, height = size
                except (TypeError, ValueError):
                    raise ValueError("size must be 'WxH' or (W, H), not %r" % (size,)) from None
        if width is not None:
            rp.width = _arrays.whole(width, "width", 1, 16384)
        if height is not None:
            rp.height = _arrays.whole(height, "height", 1, 16384)
        if eye is not None or target is not None:
            if eye is None or target is None:
                raise ValueError("a camera needs both eye and target")
            rp.view = _lib.VIEWS["camera"]
            rp.eye[:] = _arrays.vec3(eye, "eye")
            rp.target[:] = _arrays.vec3(target, "target")
            if up is not None:
                rp.up[:] = _arrays.vec3(up, "up")
        else:
            rp.view = _arrays.choice(view, "view", {k: v for k, v in _lib.VIEWS.items()
                                                    if k != "camera"})
        if fov is not None:
            rp.fov_degrees = _arrays.number(fov, "fov")
        if colour is not None and color is not None:
            raise ValueError("give colour or color, not both")
        colour = colour if colour is not None else color
        if colour is not None:
            rp.colour = _arrays.choice(colour, "colour", _lib.COLOURS)
        if cut is not None:
            if isinstance(cut, str):
                m = re.fullmatch(r"([xyzXYZ]):(.+)", cut)
                v = _container._c_double(m.group(2)) if m else None
                if v is None:
                    raise ValueError("cut must be 'AXIS:VALUE' (x, y or z) or (axis, value), "
                                     "not %r" % (cut,))
                axis = m.group(1).lower()
            else:
                try:
                    axis, v = cut
                except (TypeError, ValueError):
                    raise ValueError("cut must be 'AXIS:VALUE' or (axis, value), not %r"
                                     % (cut,)) from None
                v = _arrays.number(v, "cut value")
            if axis not in ("x", "y", "z", 0, 1, 2):
                raise ValueError("cut's axis must be x, y or z, not %r" % (axis,))
            rp.cut_axis = "xyz".index(axis) if isinstance(axis, str) else axis
            rp.cut_value = v
        if ao is not None:
            rp.ao_samples = _arrays.whole(ao, "ao", 0, 64)
        rp.shadows = 1 if shadows else 0
        p = None
        if path is not None:
            p = _arrays.path(path)
            if not os.fsdecode(p).lower().endswith((".png", ".exr")):
                raise ValueError("render: '%s' must end in .png or .exr" % os.fsdecode(p))
        c, keep = self._c(need_mesh=True, what="to render this")
        img = ctypes.POINTER(_lib.vp_image)()
        try:
            def call(ctx):
                r = lib.vp_render(ctx, ctypes.byref(c), ctypes.byref(rp), ctypes.byref(img))
                if r == _lib.VP_OK and p is not None:
                    r = lib.vp_image_write(ctx, img, p)
                return r
            _call.run(call, threads, max_memory, progress)
            im = img.contents
            h, w = im.height, im.width
            rgba = np.ctypeslib.as_array(im.rgba, shape=(h * w * 4,)).copy().reshape(h, w, 4)
            z = np.ctypeslib.as_array(im.z, shape=(h * w,)).copy().reshape(h, w)
            ids = np.ctypeslib.as_array(im.id, shape=(h * w,)).copy().reshape(h, w)
        finally:
            lib.vp_image_destroy(img)
        del keep
        return Image(rgba, z, ids)


# keys the .vdb writer sets itself, from what it writes (a packing read from
# a file carries them in its metadata, and passing them on would keep them
# from being written afresh)
_WRITER_KEYS = ("position_precision", "position_error", "position_precision_requested")


def _meta_float(v):
    if isinstance(v, bool) or v is None:
        return None
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def _meta_array(meta):
    items = []
    keep = []
    for k, v in meta.items():
        if v is None:
            continue
        if not isinstance(k, str) or not k:
            raise TypeError("metadata keys must be non-empty str, not %r" % (k,))
        kb = _arrays.text(k, "metadata key")
        m = _lib.vp_meta()
        m.key = kb
        if isinstance(v, str):
            sb = _arrays.text(v, "metadata[%r]" % k)
            m.type, m.s = _lib.VP_META_STRING, sb
            keep.append(sb)
        elif isinstance(v, (bool, np.bool_)):
            sb = b"true" if v else b"false"
            m.type, m.s = _lib.VP_META_STRING, sb
        elif isinstance(v, numbers.Integral):
            if not -(1 << 63) <= int(v) < 1 << 63:
                raise ValueError("metadata[%r] does not fit in 64 bits" % k)
            m.type, m.i = _lib.VP_META_INT, int(v)
        elif isinstance(v, numbers.Real):
            m.type, m.d = _lib.VP_META_DOUBLE, float(v)
        else:
            raise TypeError("metadata[%r] must be a str, int or float, not %r" % (k, v))
        keep.append(kb)
        items.append(m)
    arr = (_lib.vp_meta * max(1, len(items)))(*items)
    return arr, len(items), items + keep + [arr]


# ---------------------------------------------------------------------------
# Reading


def _describe(path_bytes):
    """The metadata of a .vdb (vp_describe_file's JSON), or {}."""
    out = ctypes.c_void_p()
    try:
        _call.quick(lambda ctx: lib.vp_describe_file(ctx, path_bytes, 1, ctypes.byref(out)))
        text = ctypes.string_at(out.value).decode("utf-8", "replace")
    finally:
        if out.value:
            _lib.free(out)
    return json.loads(text).get("metadata", {})


def _ply_meta(path_bytes):
    """The `comment meta KEY VALUE` lines of a PLY header (values as text)."""
    meta = {}
    with open(path_bytes, "rb") as f:
        head = f.read(65536)
    end = head.find(b"end_header")
    for line in head[:end if end >= 0 else len(head)].split(b"\n"):
        w = line.rstrip(b"\r").split(b" ", 3)
        if len(w) >= 3 and w[0] == b"comment" and w[1] == b"meta":
            meta[w[2].decode("utf-8", "replace")] = (w[3] if len(w) > 3 else b"").decode(
                "utf-8", "replace")
    return meta


def _attach_meshes(packing, name, shape, meshes):
    """read() of a mixed set: the MeshShapes given, one per mesh shape in
    the order of its shapes (as the command line's --shape, with its
    warning for a name other than the recorded one)."""
    if shape is not None:
        raise ValueError("%s records its shapes (%s); shape=%r is for a .csv of one shape"
                         % (name, ";".join(packing.shapes), shape))
    if meshes is None:
        return
    want = [k for k, n in enumerate(packing.shapes) if n == "mesh" or n.startswith("mesh:")]
    if len(meshes) != len(want):
        if not want:
            raise ValueError("%s holds no mesh shape (%s): shape=MeshShape is for packings with "
                             "mesh shapes" % (name, ";".join(packing.shapes)))
        raise ValueError("%s holds %d mesh shape%s (%s): give %s as shape=[MeshShape, ...], in "
                         "the order of its shapes (%d given)"
                         % (name, len(want), "" if len(want) == 1 else "s",
                            ", ".join(packing.shapes[k] for k in want),
                            "it" if len(want) == 1 else "them", len(meshes)))
    for k, m in zip(want, meshes):
        recorded = packing.shapes[k][5:]
        if recorded and recorded != m.name:
            warnings.warn("%s: shape %d was the mesh shape '%s', not '%s'"
                          % (name, k, recorded, m.name))
        packing.mesh_shapes[k] = m
        packing.shapes[k] = "mesh:" + m.name


def read(path, format=None, shape=None, *, threads=None, max_memory=None,  # noqa: A002
         progress=None):
    """Reads a packing from a .vdb (its points grid), or a .ply or .csv as
    vdbpack writes them (by the extension, or format="vdb"|"ply"|"csv").
    Particles come back in id order. shape: the particle shape where the
    file does not record it: a name for a CSV of solids (which does not
    record the shape), or a MeshShape for a packing of a mesh shape (for
    check, render and .obj); for a packing of several shapes, a list of
    MeshShapes, one per mesh shape in the order of its shapes (as the
    command line's --shape, once per mesh shape). Returns a Packing whose
    metadata is the file's (.vdb, and .ply comments)."""
    p = _arrays.path(path)
    if format is None:
        fmt = lib.vp_format_from_path(p)
        if fmt not in (1, 2, 3):
            raise ValueError("cannot read '%s': give a .vdb, .ply or .csv (or format=)"
                             % os.fsdecode(p))
    else:
        fmt = _arrays.choice(format, "format", {k: v for k, v in _lib.FORMATS.items()
                                                if k != "obj"})
    mesh = None
    meshes = None  # shape=[MeshShape, ...]: a mixed set's mesh shapes
    if isinstance(shape, _container.MeshShape):
        mesh, shape = shape, None
    elif isinstance(shape, (list, tuple)):
        meshes, shape = list(shape), None
        for k, m in enumerate(meshes):
            if not isinstance(m, _container.MeshShape):
                raise TypeError("shape[%d] must be a vdbpack.MeshShape, not %r" % (k, m))
    elif shape is not None:
        if not isinstance(shape, str):
            raise TypeError("shape must be a name or a vdbpack.MeshShape, not %r" % (shape,))
        shape = _known_shape(shape, ", a vdbpack.MeshShape, or a list of them")[2]
    out = ctypes.POINTER(_lib.vp_particles)()
    needs = ctypes.c_int(0)
    try:
        _call.run(lambda ctx: lib.vp_import(ctx, p, fmt, ctypes.byref(out), ctypes.byref(needs)),
                  threads, max_memory, progress)
        packing = Packing._from_c(out, mesh)
    finally:
        lib.vp_particles_destroy(out)
    name = os.fsdecode(p)
    if packing.shape == "mixed":
        _attach_meshes(packing, name, shape, [mesh] if mesh is not None else meshes)
        mesh = shape = None
    elif meshes is not None:
        if len(meshes) != 1 or packing.shape != "mesh":
            raise ValueError("%s holds one shape (%s): shape=[MeshShape, ...] is for packings "
                             "of several shapes" % (name, packing.shape))
        mesh = meshes[0]
    if mesh is not None and packing.shape != "mesh":
        raise ValueError("%s holds %ss, not particles of a mesh shape: shape=MeshShape is for "
                         "those" % (name, packing.shape))
    if shape is not None:
        if fmt != _lib.FORMATS["csv"] and shape != packing.shape:
            raise ValueError("%s records its shape (%s); shape=%r is for a .csv"
                             % (name, packing.shape, shape))
        if shape == "sphere" and packing.orient is not None:
            raise ValueError("%s has orientations (qx..qw), which spheres do not carry: give the "
                             "solid's shape" % name)
        packing.shape = shape
        if shape != "sphere" and packing.orient is None:
            packing.orient = np.tile(np.array([0.0, 0.0, 0.0, 1.0]), (len(packing), 1))
    elif needs.value:
        raise ValueError("%s has orientations but does not record the particle shape: give "
                         "shape=NAME" % name)
    if packing.shape == "mesh" and mesh is not None:
        packing.mesh_shape = mesh
    if fmt == _lib.FORMATS["vdb"]:
        packing.metadata = _describe(p)
    elif fmt == _lib.FORMATS["ply"]:
        packing.metadata = _ply_meta(p)
    md = packing.metadata
    if packing.shape == "mesh" and mesh is not None and md.get("shape_file") and \
            md["shape_file"] != mesh.name:
        warnings.warn("%s was packed with the mesh shape '%s', not '%s'"
                      % (name, md["shape_file"], mesh.name))
    packing.method = md.get("method") if isinstance(md.get("method"), str) else None
    cv = _meta_float(md.get("container_volume"))
    loaded = packing.shape != "mixed" or all(
        m is not None for n, m in zip(packing.shapes, packing.mesh_shapes)
        if n == "mesh" or n.startswith("mesh:"))
    if cv and cv > 0 and (packing.shape != "mesh" or mesh is not None) and loaded:
        packing.container_volume = cv
        packing.fraction = packing.volume() / cv
    return packing
