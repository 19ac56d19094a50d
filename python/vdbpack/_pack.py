# SPDX-License-Identifier: Apache-2.0
"""vdbpack.pack: the command line's `vdbpack pack` options as keyword
arguments, with its defaults and its checks (src/cli/pack.c:
parse_pack, check_method_options), so that the same options give the same
particles."""
import ctypes
import math
import os
import re

import numpy as np

from . import _arrays
from . import _call
from . import _container
from . import _errors
from . import _lib
from ._container import Container, MeshShape
from ._lib import lib
from . import _packing
from ._packing import Packing, Report, shape_name

FLT_MIN = 1.1754943508222875e-38
FLT_MAX = 3.4028234663852886e+38

METHODS = ("lattice", "rsa", "relax", "jam")
# the options of each method; the others are common to all of them
_BY_METHOD = {
    "lattice": ("radius", "count", "lattice", "offsets", "rotate", "rotations", "margin", "gap"),
    "rsa": ("radius", "count", "passes", "retries", "grow", "orient", "overlap",
            "radius_field", "radius_field_mode", "density_field", "target_fraction", "margin",
            "gap"),
    "relax": ("radius", "count", "target_fraction", "tolerance", "max_sweeps", "radius_field",
              "radius_field_mode", "margin", "gap"),
    "jam": ("radius", "count", "target_fraction", "tolerance", "radius_field",
            "radius_field_mode", "margin", "gap"),
}
_COMMON = ("shape", "fit", "seed", "threads", "max_memory", "progress", "mask")
# rsa count=N without radius: the radius at which N fill this fraction (the
# command line's --target-fraction default for rsa)
RSA_COUNT_FRACTION = 0.3
_FIELD_MODES = {"scale": 0, "absolute": 1}
_LOAD = ("voxel_size", "inside", "iso", "grid")
_ALL = set(_COMMON) | set(_LOAD) | {k for v in _BY_METHOD.values() for k in v} | {"allow_open"}
_GROUP_NAME = re.compile(r"^(?!__)[A-Za-z0-9_]{1,31}$")


def _size_dist(value, opt):
    """A radius or a distribution ("uniform:A:B", "lognormal:MEAN:SD",
    "list:R1:R2:...") as a vp_size_dist, parsed by the library as the
    command line parses its text (same checks, same messages)."""
    if isinstance(value, str):
        text = value
    elif isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError("%s must be a number or a distribution such as 'uniform:0.01:0.02', "
                        "not %r" % (opt, value))
    else:
        text = repr(float(value))  # shortest text that strtod reads back to the same double
    d = _lib.vp_size_dist()
    b = _arrays.text(text, opt)
    try:
        _call.quick(lambda ctx: lib.vp_size_dist_parse(ctx, b, ctypes.byref(d)))
    except _errors.InvalidArgumentError as e:
        raise _errors.InvalidArgumentError("%s: %s" % (opt, e.message), e.code) from None
    return d


def _dist_text(d):
    buf = ctypes.create_string_buffer(256)
    lib.vp_size_dist_format(ctypes.byref(d), buf, 256)
    return buf.value.decode()


# the fields of a pass (the command line's --pass)
_PASS_FIELDS = ("count", "radius", "retries", "grow", "name", "shape")


def _parse_pass_text(text):
    """'count=N|max,radius=R[,retries=K][,grow][,name=G][,shape=S]' as a
    dict."""
    out = {}
    for tok in text.split(","):
        if not tok:
            raise ValueError("pass '%s': empty field (a stray comma)" % text)
        key, eq, val = tok.partition("=")
        if key not in _PASS_FIELDS:
            raise ValueError("pass '%s': unknown field '%s' (%s)"
                             % (text, key, ", ".join(_PASS_FIELDS)))
        if key in out:
            raise ValueError("pass '%s': %s is given twice" % (text, key))
        if key == "grow":
            if eq:
                raise ValueError("pass '%s': grow takes no value" % text)
            out[key] = True
        elif key == "count":
            if val == "max":
                out[key] = "max"
            elif re.fullmatch(r"[0-9]+", val or ""):
                out[key] = int(val)
            else:
                raise ValueError("pass '%s': count must be a whole number > 0 or 'max', not '%s'"
                                 % (text, val))
        elif key == "retries":
            if not re.fullmatch(r"[0-9]+", val or ""):
                raise ValueError("pass '%s': retries must be a whole number in 1..1e9, not '%s'"
                                 % (text, val))
            out[key] = int(val)
        elif key == "shape":
            if not val:
                raise ValueError("pass '%s': shape needs a value (a shape name, superball:P or "
                                 "a closed mesh file)" % text)
            out[key] = val
        else:
            if not eq:
                raise ValueError("pass '%s': %s needs a value" % (text, key))
            out[key] = val
    return out


def _pass_shape(value, where, ps):
    """A pass's own shape (the command line's --pass ...,shape=) into
    ps.own_shape and ps.shape: a built-in name or "superball:P" (parsed by
    the library); else a closed mesh file or a MeshShape, returned (the
    file is read later, once, by _load_pass_shapes), with ps.shape.mesh
    still NULL. Returns None for a built-in shape."""
    if isinstance(value, MeshShape):
        ps.own_shape, ps.shape.shape, ps.shape.param = 1, _lib.VP_SHAPE_MESH, 0.0
        return value
    if isinstance(value, os.PathLike):
        value = os.fsdecode(os.fspath(value))
    if not isinstance(value, str):
        raise TypeError("%s: shape must be a shape name, 'superball:P', a closed mesh file or a "
                        "vdbpack.MeshShape, not %r" % (where, value))
    if not value:
        raise ValueError("%s: shape needs a value (a shape name, superball:P or a closed mesh "
                         "file)" % where)
    try:
        s = _packing.parse_shape(value)
    except ValueError:
        raise ValueError("%s: shape '%s': a superball's exponent P must be a number in [0.5, "
                         "1000] (concave superballs, P < 0.5, are not offered)"
                         % (where, value)) from None
    ps.own_shape = 1
    if s is not None and s[0] != _lib.VP_SHAPE_MESH:  # ("mesh" is a file's name here)
        ps.shape.shape, ps.shape.param = s[0], s[1]
        return None
    ps.shape.shape, ps.shape.param = _lib.VP_SHAPE_MESH, 0.0
    return value


def _pass_shape_text(ps, spec):
    """A pass's own shape as the .vdb's passes metadata writes it (the file
    as given, or the MeshShape's name), or "" for a pass without one."""
    if not ps.own_shape:
        return ""
    if ps.shape.shape == _lib.VP_SHAPE_MESH:
        return spec.name if isinstance(spec, MeshShape) else spec
    return shape_name(ps.shape.shape, ps.shape.param)


def _load_pass_shapes(passes, specs, top_spec, top_mesh, threads, progress):
    """Reads the passes' mesh files, each once (a pass naming the file of
    shape= shares its mesh), and points the passes at them. Returns the
    MeshShapes by pass (None for the others), which must outlive the
    packing. Errors as the command line's: a name that is no shape and no
    file, a mesh that cannot be a particle shape (open, ...)."""
    loaded = {}
    if top_mesh is not None and isinstance(top_spec, (str, os.PathLike)):
        loaded[os.path.realpath(os.fsdecode(os.fspath(top_spec)))] = top_mesh
    out = []
    for k, spec in enumerate(specs):
        m = None
        if isinstance(spec, MeshShape):
            m = spec
        elif spec is not None:
            key = os.path.realpath(spec)
            m = loaded.get(key)
            if m is None:
                if not os.path.exists(spec):
                    raise ValueError("passes[%d]: shape '%s' is no shape name (%s) and no file"
                                     % (k, spec, _packing.SHAPE_HELP))
                try:
                    m = MeshShape.from_file(spec, threads=threads, progress=progress)
                except _errors.CancelledError:
                    raise
                except _errors.Error as e:
                    raise type(e)("passes[%d]: %s" % (k, e.message), e.code) from None
                loaded[key] = m
        if m is not None:
            passes[k].shape.mesh = m._ptr.value
        out.append(m)
    return out


def _rsa_pass(spec, k, retries):
    """One pass (a dict or the command line's text) as a vp_rsa_pass."""
    where = "passes[%d]" % k
    if isinstance(spec, str):
        spec = _parse_pass_text(spec)
    if not isinstance(spec, dict):
        raise TypeError("%s must be a dict (count=, radius=, retries=, grow=, name=, shape=) or "
                        "'count=N,radius=R,...', not %r" % (where, spec))
    for key in spec:
        if key not in _PASS_FIELDS:
            raise ValueError("%s: unknown field '%s' (%s)"
                             % (where, key, ", ".join(_PASS_FIELDS)))
    if spec.get("count") is None or spec.get("radius") is None:
        raise ValueError("%s needs count (a whole number > 0, or 'max') and radius" % where)
    ps = _lib.vp_rsa_pass()
    lib.vp_rsa_pass_init(ctypes.byref(ps))
    count = spec["count"]
    if count == "max":
        ps.maximal = 1
    else:
        if isinstance(count, str):
            raise ValueError("%s: count must be a whole number > 0 or 'max', not %r"
                             % (where, count))
        ps.count = _arrays.whole(count, where + " count", 1, (1 << 64) - 1)
    ps.radius = _size_dist(spec["radius"], where + " radius")
    r = spec.get("retries")
    if r is not None:
        ps.retries = _arrays.whole(r, where + " retries", 1, 1000000000)
    elif retries:
        ps.retries = retries
    grow = spec.get("grow", False)
    if not isinstance(grow, (bool, np.bool_)):
        raise TypeError("%s: grow must be True or False, not %r" % (where, grow))
    ps.grow = 1 if grow else 0
    name = spec.get("name")
    if name is not None:
        if not isinstance(name, str) or not _GROUP_NAME.match(name):
            raise ValueError("%s: name must be 1-31 letters, digits or _, not starting with __, "
                             "not %r" % (where, name))
        ps.name = name.encode()
    shape = spec.get("shape")
    mesh_spec = _pass_shape(shape, where, ps) if shape is not None else None
    return ps, mesh_spec


def _group(ps, k):
    return ps.name.decode() or "pass%d" % (k + 1)


def _builtin_shape(shape):
    """(vp_shape id, exponent) of a built-in shape given to pack() (a name
    or "superball:P", parsed by the library), or None for anything else."""
    if not isinstance(shape, str):
        return None
    s = _packing.parse_shape(shape)
    return None if s is None or s[0] == _lib.VP_SHAPE_MESH else s[:2]


def _resolve_shape(shape, threads, progress):
    """(vp_shape id, exponent, MeshShape or None) for shape=."""
    if isinstance(shape, MeshShape):
        return _lib.VP_SHAPE_MESH, 0.0, shape
    b = _builtin_shape(shape)
    if b is not None:
        return b[0], b[1], None
    if isinstance(shape, os.PathLike) or (isinstance(shape, str) and
                                          ("." in shape or "/" in shape)):
        return _lib.VP_SHAPE_MESH, 0.0, MeshShape.from_file(shape, threads=threads,
                                                             progress=progress)
    if isinstance(shape, str):
        raise ValueError("unknown shape '%s' (%s, a closed mesh file such as shape.obj, or a "
                         "vdbpack.MeshShape)" % (shape, _packing.SHAPE_HELP))
    raise TypeError("shape must be a name, a mesh file or a vdbpack.MeshShape, not %r" % (shape,))


def _pass_report_shape(ps, mesh, top_shape_text):
    """A pass's shape as the command line's --json names it: "cube",
    "superball:2", "mesh:NAME"; the passes without one of their own
    top_shape_text."""
    if not ps.own_shape:
        return top_shape_text
    if ps.shape.shape == _lib.VP_SHAPE_MESH:
        return "mesh:" + mesh.name
    return shape_name(ps.shape.shape, ps.shape.param)


def _call_text(container, method, options):
    args = [repr(container.name if isinstance(container, Container) else
                 os.fsdecode(os.fspath(container)))]
    args.append("method=%r" % method)
    for k, v in options.items():
        if k in ("threads", "progress"):
            continue
        if isinstance(v, MeshShape):
            v = v.name
        elif k == "passes" and isinstance(v, (list, tuple)):
            v = [{a: (b.name if isinstance(b, MeshShape) else b) for a, b in s.items()}
                 if isinstance(s, dict) else s for s in v]
        args.append("%s=%r" % (k, v))
    return "vdbpack.pack(%s)" % ", ".join(args)


def _prepare(method, options):
    """pack()'s options checked (as the command line's
    check_method_options) and turned into the method's parameter struct:
    a dict of the names pack() goes on with (params, keep: what params
    points to, given, fit, seed, shape_opt, shape_id, ...)."""
    if not isinstance(method, str) or method not in METHODS:
        raise ValueError("unknown method %r (lattice, rsa, relax, jam)" % (method,))
    for k in options:
        if k not in _ALL:
            raise TypeError("pack() got an unexpected keyword argument '%s'" % k)
    given = {k: v for k, v in options.items() if v is not None}
    if "allow_open" in given:
        _container.container_params(_lib.vp_container_params(), [], allow_open=True)
    for k in given:
        takers = [m for m in METHODS if k in _BY_METHOD[m]]
        if takers and method not in takers:
            raise ValueError("%s goes with method=%s (not method=%r)"
                             % (k, " or ".join("%r" % m for m in takers), method))
    threads = _call.check_threads(given.get("threads"))
    max_memory = _call.check_max_memory(given.get("max_memory"))
    progress = _call.check_progress(given.get("progress"))
    fit = _arrays.choice(given.get("fit", "inside"), "fit", _lib.FITS)
    seed = _arrays.whole(given.get("seed", 1), "seed", 0, (1 << 64) - 1)
    shape_opt = given.get("shape", "sphere")
    if not isinstance(shape_opt, (str, os.PathLike, MeshShape)):
        raise TypeError("shape must be a name, a mesh file or a vdbpack.MeshShape, not %r"
                        % (shape_opt,))

    # -- the method's options, checked as check_method_options does -------
    # a built-in name or "superball:P" as the library parses it (a bad
    # exponent fails here); anything else is a mesh file or a MeshShape
    builtin = _builtin_shape(shape_opt)
    shape_id, shape_param = builtin if builtin is not None else (None, 0.0)
    is_mesh = shape_id is None
    if is_mesh and method != "rsa":
        if isinstance(shape_opt, str) and "." not in shape_opt and "/" not in shape_opt:
            _resolve_shape(shape_opt, threads, progress)  # the unknown name's message
        raise ValueError("a mesh shape (%s) packs with method='rsa' in this version"
                         % (shape_opt.name if isinstance(shape_opt, MeshShape) else shape_opt,))
    if method in ("relax", "jam") and shape_id not in (None, 0):
        raise ValueError("method=%r packs spheres in this version (shape=%r needs "
                         "method='lattice' or 'rsa')" % (method, shape_opt))
    orient = given.get("orient")
    overlap = given.get("overlap")
    orient_given = orient is not None or overlap is not None
    if orient_given and shape_id == 0 and method != "rsa":
        raise ValueError("orient and overlap go with method='rsa' and a shape other than sphere")
    orient = -1 if orient is None else _arrays.choice(orient, "orient", _lib.ORIENTS)
    overlap = -1 if overlap is None else _arrays.choice(overlap, "overlap", _lib.OVERLAPS)
    if overlap == 1 and orient == 0:
        raise ValueError("overlap='bbox' needs orient='fixed' (the axis-aligned box of a "
                         "rotated solid does not bound it)")
    if overlap < 0:
        overlap = 0
    if orient < 0:
        orient = 1 if overlap == 1 else 0

    has_radius, has_count = "radius" in given, "count" in given
    # -- fields (docs/fields.md), as check_field_options
    rf_mode = 0
    if "radius_field_mode" in given:
        if "radius_field" not in given:
            raise ValueError("radius_field_mode goes with radius_field")
        rf_mode = _arrays.choice(given["radius_field_mode"], "radius_field_mode", _FIELD_MODES)
    if ("radius_field" in given or "density_field" in given) and shape_id != 0:
        raise ValueError("radius_field and density_field pack spheres in this version, not "
                         "shape=%r" % (shape_opt,))
    if "radius_field" in given and rf_mode == 1:
        if has_radius:
            raise ValueError("radius_field_mode='absolute': the field is the radius; leave out "
                             "radius (scale, the default, multiplies it)")
        if method == "rsa" and "target_fraction" in given:
            raise ValueError("radius_field_mode='absolute': the field is the radius; "
                             "target_fraction does not go with it")
        if method in ("rsa", "relax") and "passes" not in given:
            # the radius is the field's: a placeholder until it is read
            given["radius"] = 1.0
            has_radius = True
    mesh = None
    pass_shapes = pass_solid = False  # some pass has a shape of its own; one not a sphere
    pass_meshes = []                  # by pass: a mesh file or MeshShape to load, or None
    if method == "lattice":
        lp = _lib.vp_lattice_params()
        lib.vp_lattice_params_init(ctypes.byref(lp))
        lat = _arrays.choice(given["lattice"], "lattice", _lib.LATTICES) \
            if "lattice" in given else _lib.VP_LATTICE_DEFAULT
        if has_radius and has_count:
            raise ValueError("give either radius or count, not both")
        if not has_radius and not has_count:
            raise ValueError("give the particle size with radius=R or count=N")
        if has_radius:
            r = given["radius"]
            if isinstance(r, str) or isinstance(r, bool) or \
                    not isinstance(r, (int, float, np.integer, np.floating)):
                raise ValueError("radius must be a positive number for method='lattice', not %r"
                                 % (r,))
            r = float(r)
            if not r > 0 or not math.isfinite(r):
                raise ValueError("radius must be a positive number, not %r" % (given["radius"],))
            if not r >= FLT_MIN:
                raise ValueError("radius %r: a radius must be at least 1.2e-38 (radii are "
                                 "stored as float)" % (given["radius"],))
            if not r <= FLT_MAX:
                raise ValueError("radius %r: a radius must be at most 3.4e38 (radii are "
                                 "stored as float)" % (given["radius"],))
            lp.radius = r
        else:
            if given["count"] == "max":
                raise ValueError("count='max' goes with method='rsa'")
            lp.count = _arrays.whole(given["count"], "count", 1, (1 << 64) - 1)
        if shape_id == 0 and lat == _lib.VP_LATTICE_DENSEST:
            lat = _lib.VP_LATTICE_FCC
        if shape_id != 0 and lat not in (_lib.VP_LATTICE_DEFAULT, _lib.VP_LATTICE_DENSEST):
            raise ValueError("lattice=%r is for spheres; a %s packs on its densest lattice "
                             "(lattice='densest')" % (given["lattice"], shape_opt))
        lp.shape, lp.lattice, lp.fit, lp.seed = shape_id, lat, fit, seed
        lp.shape_param = shape_param
        if "offsets" in given:
            lp.offsets = _arrays.whole(given["offsets"], "offsets", 1, 1000000)
        if "rotations" in given:
            lp.rotations = _arrays.whole(given["rotations"], "rotations", 1, 100000)
            lp.rotate = 1
        if given.get("rotate"):
            lp.rotate = 1
        params, keep = lp, []
        label = [k for k, v in _lib.LATTICES.items() if v == (
            lat if lat else (_lib.VP_LATTICE_FCC if shape_id == 0 else _lib.VP_LATTICE_DENSEST))][0]
    elif method == "rsa":
        if "passes" in given and (has_radius or has_count):
            raise ValueError("give either passes or radius with count (one pass), not both")
        # count=N alone: N particles of the radius at which they fill
        # target_fraction (default 0.3), set once the container is known
        count_radius = has_count and not has_radius and "passes" not in given
        if "target_fraction" in given and not count_radius:
            raise ValueError("method='rsa' takes radius=R or target_fraction=F (which chooses "
                             "the radius for count=N), not both")
        if count_radius:
            if given["count"] == "max":
                raise ValueError("count='max' needs radius=R (the radius to fill with)")
            tf = RSA_COUNT_FRACTION
            if "target_fraction" in given:
                tf = _arrays.number(given["target_fraction"], "target_fraction")
                if not 0 < tf < 1:
                    raise ValueError("target_fraction must be a number in (0, 1), not %r" % tf)
            given["radius"] = 1.0  # a placeholder until the container's volume is known
            has_radius = True
        retries = 0
        if "retries" in given:
            retries = _arrays.whole(given["retries"], "retries", 1, 1000000000)
        if "passes" in given:
            if given.get("grow"):
                raise ValueError("with passes, ask for growth in the pass ({'count': N, "
                                 "'radius': R, 'grow': True})")
            specs = given["passes"]
            if isinstance(specs, (str, dict)):
                specs = [specs]
            try:
                specs = list(specs)
            except TypeError:
                raise TypeError("passes must be a list of passes, not %r" % (specs,)) from None
            if not 1 <= len(specs) <= _lib.VP_MAX_GROUPS:
                raise ValueError("passes must hold 1 to %d passes, not %d"
                                 % (_lib.VP_MAX_GROUPS, len(specs)))
        else:
            if not has_radius or not has_count:
                raise ValueError("method='rsa' needs passes=[{'count': N, 'radius': R}, ...] or "
                                 "radius=R with count=N (or count='max')")
            specs = [{"count": given["count"], "radius": given["radius"],
                      "grow": bool(given.get("grow", False))}]
            if not isinstance(given.get("grow", False), (bool, np.bool_)):
                raise TypeError("grow must be True or False, not %r" % (given["grow"],))
        passes = (_lib.vp_rsa_pass * len(specs))()
        for k, s in enumerate(specs):
            passes[k], ms = _rsa_pass(s, k, retries)
            pass_meshes.append(ms)
        pass_shapes = any(passes[k].own_shape for k in range(len(specs)))
        pass_solid = any(passes[k].own_shape and passes[k].shape.shape != _lib.VP_SHAPE_SPHERE
                         for k in range(len(specs)))
        if orient_given and shape_id == 0 and not pass_solid:
            raise ValueError("orient and overlap go with method='rsa' and a shape (or a pass's "
                             "shape) other than sphere")
        if pass_shapes and overlap == 1:
            raise ValueError("overlap='bbox' takes one shape; passes with a shape of their own "
                             "are tested exactly")
        if pass_shapes and ("radius_field" in given or "density_field" in given):
            raise ValueError("radius_field and density_field pack spheres in this version, not "
                             "passes with a shape of their own")
        for i in range(len(specs)):
            for k in range(i):
                if _group(passes[k], k) == _group(passes[i], i):
                    raise ValueError("passes %d and %d would both be group '%s'; give each pass "
                                     "its own name" % (k + 1, i + 1, _group(passes[i], i)))
        rp = _lib.vp_rsa_params()
        lib.vp_rsa_params_init(ctypes.byref(rp))
        rp.fit, rp.orient, rp.overlap, rp.seed = fit, orient, overlap, seed
        rp.shape_param = shape_param
        rp.passes = passes
        rp.npasses = len(specs)
        params, keep = rp, [passes]
    elif method == "jam":
        # as check_method_options and jam_params: the radii's shape (equal
        # spheres without radius), N from count or from target_fraction
        if not has_count and not has_radius:
            raise ValueError("method='jam' needs count=N, or radius=SIZE (with "
                             "target_fraction=F, default 0.64, for the number)")
        if has_count and "target_fraction" in given:
            raise ValueError("method='jam' takes count=N or target_fraction=F, not both")
        jp = _lib.vp_jam_params()
        lib.vp_jam_params_init(ctypes.byref(jp))
        jp.fit, jp.seed = fit, seed
        if has_count:
            if given["count"] == "max":
                raise ValueError("count='max' goes with method='rsa'")
            jp.count = _arrays.whole(given["count"], "count", 1, (1 << 64) - 1)
        if has_radius:
            jp.radius = _size_dist(given["radius"], "radius")
        else:
            jp.radius = _size_dist(1.0, "radius")
        if "target_fraction" in given:
            tf = _arrays.number(given["target_fraction"], "target_fraction")
            if not 0 < tf < 1:
                raise ValueError("target_fraction must be a number in (0, 1), not %r" % tf)
            jp.target_fraction = tf
        if "tolerance" in given:
            tol = _arrays.number(given["tolerance"], "tolerance")
            if not 0 < tol < 0.1:
                raise ValueError("tolerance must be a number in (0, 0.1), not %r" % tol)
            jp.tolerance = tol
        params, keep = jp, []
    else:
        if not has_radius or not has_count:
            raise ValueError("method='relax' needs radius (a number or a distribution) and "
                             "count=N")
        xp = _lib.vp_relax_params()
        lib.vp_relax_params_init(ctypes.byref(xp))
        xp.fit, xp.seed = fit, seed
        if given["count"] == "max":
            raise ValueError("count='max' goes with method='rsa'")
        xp.count = _arrays.whole(given["count"], "count", 1, (1 << 64) - 1)
        xp.radius = _size_dist(given["radius"], "radius")
        if "target_fraction" in given:
            tf = _arrays.number(given["target_fraction"], "target_fraction")
            if not 0 < tf < 1:
                raise ValueError("target_fraction must be a number in (0, 1), not %r" % tf)
            xp.target_fraction = tf
        if "tolerance" in given:
            tol = _arrays.number(given["tolerance"], "tolerance")
            if not 0 < tol < 0.1:
                raise ValueError("tolerance must be a number in (0, 0.1), not %r" % tol)
            xp.tolerance = tol
        if "max_sweeps" in given:
            xp.max_sweeps = _arrays.whole(given["max_sweeps"], "max_sweeps", 0, (1 << 31) - 1)
        params, keep = xp, []
    margin, gap = 0.0, 0.0
    for k in ("margin", "gap"):
        if k in given:
            v = _arrays.number(given[k], k)
            if not (v >= 0 and math.isfinite(v)):
                raise ValueError("%s must be a distance >= 0 (world units), not %r"
                                 % (k, given[k]))
            if k == "margin":
                margin = v
            else:
                gap = v
    if gap > 0 and method == "rsa" and (shape_id is None or any(m is not None for m in pass_meshes)):
        raise ValueError("gap is kept between spheres, solids and superballs in this version, "
                         "not a mesh shape (shape=%r or a pass's mesh; margin is)" % (shape_opt,))
    if gap > 0 and method == "lattice" and shape_id != 0:
        raise ValueError("gap spaces a lattice of spheres in this version, not shape=%r (rsa "
                         "keeps a gap between any convex shapes)" % (shape_opt,))
    params.margin, params.gap = margin, gap
    return locals()


def _unit_volume(params, mesh):
    """The volume of one particle of bounding radius 1 (as the command
    line's unit_volume)."""
    if mesh is not None:
        return lib.vp_mesh_shape_volume(mesh._ptr)
    return lib.vp_shape_unit_volume_param(params.shape, params.shape_param)


class _Field:
    """A field read from FILE.vdb[:GRID] (vp_field_load), freed with the
    object."""

    def __init__(self, spec, name):
        if not isinstance(spec, (str, os.PathLike)):
            raise TypeError("%s must be a file name FILE.vdb[:GRID], not %r" % (name, spec))
        self.text = os.fsdecode(os.fspath(spec))
        path, grid = _split_grid(self.text)
        self.ptr = ctypes.c_void_p()
        pb, gb = _arrays.path(path, name), grid.encode("utf-8") if grid is not None else None
        _call.quick(lambda ctx: lib.vp_field_load(ctx, pb, gb, ctypes.byref(self.ptr)))
        self.info = _lib.vp_field_info()
        lib.vp_field_get_info(self.ptr, ctypes.byref(self.info))

    def check(self, what, positive, cont):
        lo, hi = ctypes.c_double(), ctypes.c_double()
        t, w = self.text.encode("utf-8", "replace"), what.encode()
        _call.quick(lambda ctx: lib.vp_field_check(ctx, self.ptr, t, w, positive, cont._ptr,
                                                   ctypes.byref(lo), ctypes.byref(hi)))
        return lo.value, hi.value

    def __del__(self):
        if getattr(self, "ptr", None) is not None and self.ptr.value:
            lib.vp_field_destroy(self.ptr)
            self.ptr = None


def _split_grid(text):
    """FILE.vdb:GRID as (FILE.vdb, GRID) (after the last '.vdb:'), else
    (text, None), as the command line."""
    k = text.lower().rfind(".vdb:")
    if k < 0:
        return text, None
    if not text[k + 5:]:
        raise ValueError("%r: give the grid's name after the colon, or no colon" % (text,))
    return text[:k + 4], text[k + 5:]


def _field_band(method, cp, rf, rf_mode, target_fraction):
    """relax and jam with a radius field: the container's band for the
    radii it makes (field_band of the command line)."""
    fi = rf.info
    k = fi.max / fi.min if fi.min > 0 else 8.0
    k = min(max(k, 1.0), 8.0)
    if method == "relax" and not target_fraction > 0 and fi.max > 0:
        cp.particle_radius = cp.particle_radius * fi.max if rf_mode == 0 else fi.max
        return
    cp.particle_radius *= k
    cp.space_per_particle /= k * k * k


def _apply_mask(cont, mask, method, params, fit, load, threads, max_memory, progress):
    """mask=: the container less the mask's inside (vp_container_subtract,
    as the command line's apply_mask). mask: a Container, 'sphere:R',
    'box:X,Y,Z', a mesh file or FILE.vdb[:GRID]. Returns the masked
    Container (which keeps both alive), the mask's text and voxel."""
    cp = _lib.vp_container_params()
    lib.vp_container_params_init(ctypes.byref(cp))
    getattr(lib, "vp_container_params_for_" + method)(ctypes.byref(cp), ctypes.byref(params))
    r = cp.particle_radius
    if not r > 0 and cp.particle_count and cp.space_per_particle > 0:
        r = (cont.volume / (cp.particle_count * cp.space_per_particle)) ** (1.0 / 3.0)
    need = r if fit == 0 else 0.0
    if isinstance(mask, Container):
        m, text = mask, mask.name
    else:
        if not isinstance(mask, (str, os.PathLike)):
            raise TypeError("mask must be a Container, 'sphere:R', 'box:X,Y,Z' or a file name, "
                            "not %r" % (mask,))
        text = os.fsdecode(os.fspath(mask))
        a = None if os.path.exists(text) else _container.parse_analytic(text)
        if a is not None:
            m = _container._analytic(a, text)
        else:
            path, grid = _split_grid(text)
            if grid is not None:
                cp.grid_name = grid.encode("utf-8")
            cp.inside = _lib.INSIDE_MODES.get(load.get("inside", "auto"), 0)
            if cont.info["voxel_size"] > 0:
                cp.voxel_size = cont.info["voxel_size"]
            if cp.voxel_size == 0 and need > 0:
                cp.voxel_size = 1.05 * need / 3.0
            if cp.voxel_size > 0 and 3.0 * cp.voxel_size < 1.05 * need:
                cp.voxel_size = 1.05 * need / 3.0
            m = _container._load(_arrays.path(path, "mask"), cp, os.path.basename(path), None,
                                 threads, max_memory, progress)
    out = ctypes.c_void_p()
    try:
        _call.quick(lambda ctx: lib.vp_container_subtract(ctx, cont._ptr, m._ptr,
                                                          ctypes.byref(out)))
    except BaseException:
        lib.vp_container_destroy(out)
        raise
    masked = Container._wrap(out, cont.name, cont._inside, keep=(cont, m))
    if need > 0 and masked.info["interior_band"] < need:
        raise _errors.InvalidArgumentError(
            "mask %s: its level set holds distances only %g outside it, and the particles "
            "need %g; give a mask with a wider exterior band"
            % (text, masked.info["interior_band"], need), "VP_ERR_INVALID_ARGUMENT")
    return masked, text, m.info["voxel_size"]


def container_params(method="lattice", **options):
    """The level-set parameters that pack() gives a mesh or .vdb container
    file for this job (the library's vp_container_params_for_<method> over
    the job's parameters), as keywords for Container.from_mesh or
    Container.from_file: particle_radius, particle_count,
    space_per_particle (those that apply) and narrow_band. A mesh handed
    over in memory with them gives the particles its file would. Options as
    pack()'s (those for loading a file, progress and threads are ignored)."""
    j = _prepare(method, {k: v for k, v in options.items() if k not in _LOAD})
    params = j["params"]
    if method == "rsa" and j["shape_id"] is None:
        params.shape = _lib.VP_SHAPE_MESH
    cp = _lib.vp_container_params()
    lib.vp_container_params_init(ctypes.byref(cp))
    getattr(lib, "vp_container_params_for_" + method)(ctypes.byref(cp), ctypes.byref(params))
    out = {"narrow_band": bool(cp.narrow_band)}
    if cp.particle_radius > 0:
        out["particle_radius"] = cp.particle_radius
    if cp.particle_count:
        out["particle_count"] = cp.particle_count
    if cp.space_per_particle > 0:
        out["space_per_particle"] = cp.space_per_particle
    return out


def pack(container, method="lattice", **options):
    """Fills a container with particles; returns a Packing.

    container: a Container, or a path to a mesh or .vdb level set, or
    'box:X,Y,Z' / 'sphere:R' (centred at the origin; a file of that name
    wins), which pack() loads itself exactly as `vdbpack pack` does, so
    that the same options give the command line's particles.

    method: "lattice" (default), "rsa" (random sequential addition, in
    passes), "relax" (relaxation, spheres) or "jam" (spheres compressed
    to the jamming point: random close packing, docs/jam.md).

    Options (as `vdbpack pack --help`; None means not given):

    - all methods: shape ("sphere" default; for lattice and rsa also a
      platonic or Archimedean solid, vdbpack.SHAPES, or "superball:P",
      0.5 <= P <= 1000, as --shape takes them; for rsa a closed mesh file
      or a MeshShape), fit ("inside" default, or "center"), seed (1),
      threads (default all cores; results do not depend on it),
      max_memory (bytes or "8G"), progress (callable(fraction, stage);
      returning False cancels: CancelledError);
    - a container given as a path: voxel_size, inside ("auto", "closed",
      "winding"), iso, grid;
    - lattice: radius or count, lattice ("sc", "bcc", "fcc", "hcp",
      "densest"), offsets, rotate, rotations;
    - rsa: passes (a list of dicts with count (N or "max"), radius (a
      number or a distribution string), retries, grow, name, shape (the
      pass's own: a name, "superball:P", a closed mesh file or a MeshShape;
      passes of several shapes make a "mixed" Packing); or the command
      line's 'count=N,radius=R,grow,shape=cube' texts), or for one pass radius with
      count (N or "max") and grow, or count=N alone (the radius at which
      N fill target_fraction, default 0.3); retries; orient ("random",
      "fixed") and overlap ("exact", "bbox") for solids;
    - every method: margin and gap (world distances kept from the wall and
      between surfaces; rsa's gap not for mesh shapes, lattice's for
      spheres only);
    - relax: radius (a number or a distribution), count, target_fraction,
      tolerance, max_sweeps;
    - fields and masks (docs/fields.md): mask (all methods: a Container,
      'sphere:R', 'box:X,Y,Z', a mesh file or 'FILE.vdb[:GRID]');
      radius_field ('FILE.vdb[:GRID]') with radius_field_mode ('scale',
      the default, or 'absolute') for rsa, relax and jam; density_field
      for rsa;
    - jam: count=N, or radius with target_fraction (default 0.64) for the
      number; radius (a number or a distribution) sets the radii's shape,
      their scale is the jamming point's (without radius: equal spheres);
      tolerance (the largest overlap / (r_i + r_j) allowed, default 1e-6).
      The report adds mean_contacts, rattler_fraction, core_fraction, ...
    """
    j = _prepare(method, options)
    given, threads, max_memory, progress = j["given"], j["threads"], j["max_memory"], j["progress"]
    fit, seed, shape_opt, shape_id = j["fit"], j["seed"], j["shape_opt"], j["shape_id"]
    shape_param = j["shape_param"]
    params, keep, label = j["params"], j["keep"], j.get("label")
    has_radius, orient, overlap, mesh = j["has_radius"], j["orient"], j["overlap"], None

    # -- the particle shape first: a bad shape file fails before a long
    # voxelization (as the command line)
    pass_mesh_shapes = []
    if method == "rsa":
        sid, shape_param, mesh = _resolve_shape(shape_opt, threads, progress)
        params.shape, params.shape_param = sid, shape_param
        params.mesh = mesh._ptr.value if mesh is not None else None
        shape_id = sid
        # the passes' own mesh shapes, each file read once (kept alive by
        # pass_mesh_shapes until the packing holds them)
        pass_mesh_shapes = _load_pass_shapes(params.passes, j["pass_meshes"], shape_opt, mesh,
                                             threads, progress)

    # -- fields, before the container (a radius field sizes its band) -------
    rf = _Field(given["radius_field"], "radius_field") if "radius_field" in given else None
    df = _Field(given["density_field"], "density_field") if "density_field" in given else None
    rf_mode = j["rf_mode"]
    if rf is not None:
        params.radius_field, params.radius_field_mode = rf.ptr.value, rf_mode
        if rf_mode == 1:
            if not rf.info.max > 0:
                raise _errors.InvalidArgumentError(
                    "%s: the radius field has no positive value (largest %g); radii must be "
                    "positive" % (rf.text, rf.info.max), "VP_ERR_INVALID_ARGUMENT")
            if method == "rsa":
                for k in range(params.npasses):
                    params.passes[k].radius = _size_dist(rf.info.max, "radius")
            else:
                params.radius = _size_dist(rf.info.max, "radius")
    if df is not None:
        params.density_field = df.ptr.value

    # -- the container ------------------------------------------------------
    load = {k: given[k] for k in _LOAD if k in given}
    watch = ()
    if isinstance(container, Container):
        if load:
            raise ValueError("%s are for loading a container from a file: pass them to "
                             "Container.from_file, or give pack() the path"
                             % ", ".join(sorted(load)))
        cont, cname, watch = container, container.name, (container,)
    else:
        spec = os.fsdecode(os.fspath(container)) if not isinstance(container, str) else container
        if not spec:
            raise ValueError("no container given")
        a = None if os.path.exists(spec) else _container.parse_analytic(spec)
        if a is not None:
            if load:
                raise ValueError("voxel_size, grid, inside and iso need a mesh or .vdb "
                                 "container, not '%s'" % spec)
            cont = _container._analytic(a, spec)
        else:
            cp = _lib.vp_container_params()
            lib.vp_container_params_init(ctypes.byref(cp))
            ckeep = []
            _container.container_params(cp, ckeep, **load)
            if method == "lattice":
                lib.vp_container_params_for_lattice(ctypes.byref(cp), ctypes.byref(params))
            elif method == "rsa":
                lib.vp_container_params_for_rsa(ctypes.byref(cp), ctypes.byref(params))
                if j.get("count_radius"):  # the radius follows from the volume
                    cp.particle_radius = 0
                    cp.particle_count = params.passes[0].count
                    cp.space_per_particle = _unit_volume(params, mesh) / j["tf"]
            elif method == "jam":
                lib.vp_container_params_for_jam(ctypes.byref(cp), ctypes.byref(params))
            else:
                lib.vp_container_params_for_relax(ctypes.byref(cp), ctypes.byref(params))
            if rf is not None and method in ("relax", "jam"):
                _field_band(method, cp, rf, rf_mode, getattr(params, "target_fraction", 0))
            cont = _container._load(_arrays.path(spec), cp, os.path.basename(spec),
                                    load.get("inside", "auto"), threads, max_memory, progress)
        cname = os.path.basename(spec) if "/" in spec else spec
    mask_text, mask_voxel = None, 0.0
    if "mask" in given:
        cont, mask_text, mask_voxel = _apply_mask(cont, given["mask"], method, params, fit,
                                                  load, threads, max_memory, progress)
    rf_range = rf.check("radius field", 1, cont) if rf is not None else None
    if df is not None:
        df.check("density field", 0, cont)
    ci = cont._info

    if method == "rsa" and j.get("count_radius"):
        # as rsa_count_radius: N particles that fill tf of the container
        n = params.passes[0].count
        rc = math.cbrt(j["tf"] * ci["volume"] / (n * _unit_volume(params, mesh)))
        if not FLT_MIN <= rc <= FLT_MAX:
            raise ValueError("count %d in %s gives a radius of about %g, outside 1.2e-38..3.4e38 "
                             "(radii are stored as float)" % (n, cname, rc))
        if params.gap > 0 and not params.gap < rc:
            raise ValueError("gap %g must be smaller than the radius %g that count=%d gives"
                             % (params.gap, rc, n))
        params.passes[0].radius = _size_dist(rc, "radius")
    if method == "lattice" and params.count:
        f = lib.vp_lattice_fraction_param(params.shape, params.shape_param, params.lattice)
        rc = (ci["volume"] * f / (params.count * lib.vp_shape_unit_volume_param(
            params.shape, params.shape_param))) \
            ** (1.0 / 3.0) if ci["volume"] > 0 and f > 0 else 0.0
        if not rc >= FLT_MIN:
            raise ValueError("count %d in %s gives a radius of about %g, below 1.2e-38 (radii "
                             "are stored as float): ask for fewer particles"
                             % (params.count, cname, rc))
    if method == "jam" and params.count and has_radius:
        # as jam_count_check: N spheres of these radii must fit at all (the
        # jamming point then scales them; without radius any N does)
        v = params.count * 4.0 / 3.0 * math.pi * lib.vp_size_dist_mean_cube(
            ctypes.byref(params.radius))
        equal = lib.vp_size_dist_min(ctypes.byref(params.radius)) == \
            lib.vp_size_dist_max(ctypes.byref(params.radius))
        if not v <= (0.7405 if equal else 1.0) * ci["volume"]:
            raise _errors.NoFitError(
                "%d spheres of radius %s fill %.3g times the container's volume, more than "
                "%s; use fewer or smaller spheres (or leave out radius: jam then finds the "
                "radius)" % (params.count, _dist_text(params.radius), v / ci["volume"],
                             "equal spheres can fill (0.7405)" if equal else "it has"))

    # -- packing --------------------------------------------------------------
    out = ctypes.POINTER(_lib.vp_particles)()
    fn = {"lattice": lib.vp_pack_lattice, "rsa": lib.vp_pack_rsa, "relax": lib.vp_pack_relax,
          "jam": lib.vp_pack_jam}
    rep = {"lattice": _lib.vp_lattice_report, "rsa": _lib.vp_rsa_report,
           "relax": _lib.vp_relax_report, "jam": _lib.vp_jam_report}[method]()
    try:
        try:
            _call.run(lambda ctx: fn[method](ctx, cont._ptr, ctypes.byref(params),
                                             ctypes.byref(out), ctypes.byref(rep)),
                      threads, max_memory, progress, watch)
        except _errors.InvalidArgumentError as e:
            if not (isinstance(container, Container) and "interior band" in e.message):
                raise
            # a Container loaded without the job's particle size: say how to
            # load it (pack() sizes the band itself when given the path)
            raise _errors.InvalidArgumentError(
                "%s (load it with the largest particle radius: Container.from_file(..., "
                "particle_radius=R) or from_mesh(..., particle_radius=R), or give pack() the "
                "path)" % e.message, e.code) from None
        known = [m for m in [mesh] + pass_mesh_shapes if m is not None]
        packing = Packing._from_c(out, mesh, meshes={m._ptr.value: m for m in known})
        volume = lib.vp_particles_volume(out)
    finally:
        lib.vp_particles_destroy(out)
    del keep

    # -- report and metadata, as the command line's --json and .vdb --------
    shape_text = shape_name(shape_id, shape_param)  # "cube", "superball:2" (vp_shape_format)
    # the shape of the passes without their own, as the command line's
    # --json names it
    top_shape_text = "mesh:" + mesh.name if mesh is not None else shape_text
    if j["pass_shapes"]:
        # the shapes the passes made: "mixed" for several (as the command
        # line), else the one shape, whose mesh is then the result's
        shape_text = packing.shape
        mesh = packing.mesh_shape if packing.shape == "mesh" else None
    r = Report(method=method, shape=shape_text, fit="inside" if fit == 0 else "center",
               seed=seed, count=len(packing))
    if method == "lattice":
        if not rep.radius >= FLT_MIN:
            raise ValueError("count %d in %s gives a radius of %g, below 1.2e-38 (radii are "
                             "stored as float): ask for fewer particles"
                             % (params.count, cname, rep.radius))
        r.update(lattice=label, radius=rep.radius, lattice_fraction=rep.lattice_fraction,
                 offsets_tried=rep.offsets_tried, rotations_tried=rep.rotations_tried,
                 radius_iterations=rep.radius_iterations, offset=tuple(rep.offset),
                 rotation=tuple(rep.rotation), requested_count=params.count,
                 seconds=rep.seconds)
        max_radius = rep.radius
    else:
        max_radius = float(packing.radii.max()) if len(packing) else 0.0
    if method == "rsa":
        if shape_text != "sphere":
            r.update(orient="fixed" if orient == 1 else "random",
                     overlap="bbox" if overlap == 1 else "exact")
        r["passes"] = []
        for i in range(rep.npasses):
            pr = rep.passes[i]
            r["passes"].append(Report(
                shape=_pass_report_shape(params.passes[i], pass_mesh_shapes[i], top_shape_text),
                group=packing.group_names[i] if i < len(packing.group_names) else _group(
                    params.passes[i], i),
                radius=_dist_text(params.passes[i].radius), requested=pr.requested,
                maximal=bool(params.passes[i].maximal), placed=pr.placed,
                stop=_lib.RSA_STOPS[pr.stop] if 0 <= pr.stop < 3 else str(pr.stop),
                tries=pr.tries, pretested=pr.pretested, cell_budget_reached=bool(pr.budget_hit),
                grow=bool(params.passes[i].grow), grow_mean=pr.grow_mean, seconds=pr.seconds,
                retries=params.passes[i].retries or _lib.VP_RSA_DEFAULT_RETRIES))
        r["seconds"] = rep.seconds
    elif method == "relax":
        r.update(radius=_dist_text(params.radius), requested_count=params.count,
                 target_fraction=params.target_fraction, sweeps=rep.sweeps,
                 radius_scale=rep.radius_scale, initial_fraction=rep.initial_fraction,
                 max_overlap=rep.max_overlap, seconds=rep.seconds)
    elif method == "jam":
        # the command line's --json figures (print_json), and the rest of
        # vp_jam_report
        r.update(radius=_dist_text(params.radius), requested_count=params.count,
                 target_fraction=params.target_fraction if not params.count else None,
                 tolerance=params.tolerance, radius_scale=rep.radius_scale,
                 max_overlap=rep.max_overlap, mean_contacts=rep.mean_contacts,
                 rattler_fraction=rep.rattler_fraction, core_fraction=rep.core_fraction,
                 core_count=rep.core_count, core_volume=rep.core_volume,
                 minimizations=rep.minimizations, iterations=rep.iterations,
                 list_builds=rep.list_builds, seconds=rep.seconds)
    fraction = volume / ci["volume"] if ci["volume"] > 0 else 0.0
    r.update(max_radius=max_radius, particle_volume=volume, container_volume=ci["volume"],
             packing_fraction=fraction, container=cname, container_kind=ci["kind"],
             voxel_size=ci["voxel_size"], voxel_reason=ci["voxel_reason"])
    if mesh is not None:
        r.update(shape_file=mesh.name, shape_triangles=mesh.triangles)
    if packing.shape == "mixed":  # as the command line's --json: each shape and its count
        counts = np.bincount(packing.shape_index, minlength=len(packing.shapes))
        r["shapes"] = [Report(shape=name, count=int(counts[k]))
                       for k, name in enumerate(packing.shapes)]

    md = {
        "creator": "vdbpack " + _lib.VERSION,
        "command_line": _call_text(container, method, options),
        "seed": seed, "method": method, "shape": shape_text,
        "fit": "inside" if fit == 0 else "center", "container": cname,
        "particle_count": len(packing), "max_radius": max_radius,
        "container_volume": ci["volume"], "packing_fraction": fraction,
        "voxel_size": ci["voxel_size"],
    }
    if mesh is not None:
        md["shape_file"] = mesh.name
    if packing.shape == "mixed":
        md["shapes"] = ";".join(packing.shapes)
    if method != "lattice":
        # what `vdbpack check` holds the file to by default
        if params.margin > 0:
            md["margin"] = params.margin
        if params.gap > 0:
            md["gap"] = params.gap
        r.update(margin=params.margin, gap=params.gap)
    if method == "rsa" and j.get("count_radius"):
        md["target_fraction"] = j["tf"]
        r["target_fraction"] = j["tf"]
    if ci["kind"] == "mesh":
        md["inside"] = cont._inside or "auto"
    if "iso" in load:
        md["iso"] = float(load["iso"])
    # fields and masks, as the command line records them
    if mask_text is not None:
        md["mask"] = mask_text
        r["mask"] = mask_text
        if mask_voxel > 0:
            md["mask_voxel_size"] = mask_voxel
    if rf is not None:
        md.update(radius_field=rf.text, radius_field_mode="absolute" if rf_mode else "scale")
        r.update(radius_field=rf.text, radius_field_mode=md["radius_field_mode"],
                 radius_field_min=rf_range[0], radius_field_max=rf_range[1])
    if df is not None:
        md["density_field"] = df.text
        r["density_field"] = df.text
    if method == "lattice":
        md.update(lattice=label, radius=rep.radius)
    elif method == "rsa":
        md["passes"] = ";".join(
            "count=%s,radius=%s,retries=%d%s%s%s" % (
                "max" if ps.maximal else ps.count, _dist_text(ps.radius),
                ps.retries or _lib.VP_RSA_DEFAULT_RETRIES, ",grow" if ps.grow else "",
                ",name=" + ps.name.decode() if ps.name else "",
                ",shape=" + _pass_shape_text(ps, spec) if ps.own_shape else "")
            for ps, spec in zip(params.passes[:params.npasses], j["pass_meshes"]))
        if shape_text != "sphere":
            md["orient"] = "fixed" if orient == 1 else "random"
            md["overlap"] = "bbox" if overlap == 1 else "exact"
    elif method == "jam":
        md.update(radius=_dist_text(params.radius), radius_scale=rep.radius_scale,
                  max_overlap=rep.max_overlap, mean_contacts=rep.mean_contacts,
                  rattler_fraction=rep.rattler_fraction, core_fraction=rep.core_fraction)
    else:
        md.update(radius=_dist_text(params.radius), target_fraction=params.target_fraction,
                  radius_scale=rep.radius_scale, max_overlap=rep.max_overlap)
    packing.report = r
    packing.metadata = md
    packing.method = method
    packing.fraction = fraction
    packing.container_volume = ci["volume"]
    packing._full_precision = method != "lattice"
    return packing
