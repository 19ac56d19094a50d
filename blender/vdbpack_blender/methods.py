# SPDX-License-Identifier: Apache-2.0
"""The packers the add-on offers, and how the panel's settings become the
keyword arguments of vdbpack.pack(). No bpy here: settings arrive as a
plain dict (settings.as_dict), so this file is tested and read on its own.

A new packer of the Python module is one entry of METHODS: its label,
which settings it shows and a function turning them into pack() keywords.
An entry whose name the loaded module does not list (vdbpack.METHODS) is
shown greyed out with the reason."""

import numpy as np

SOLIDS = ("tetrahedron", "cube", "octahedron", "dodecahedron", "icosahedron") + \
    ("truncated-tetrahedron", "cuboctahedron", "truncated-cube", "truncated-octahedron",
     "rhombicuboctahedron", "truncated-cuboctahedron", "snub-cube", "icosidodecahedron",
     "truncated-dodecahedron", "truncated-icosahedron", "rhombicosidodecahedron",
     "truncated-icosidodecahedron", "snub-dodecahedron")
SHAPES = ("sphere",) + SOLIDS + ("superball",)  # a superball's exponent is a setting of its own


def decimal(x):
    """A float property's value as the number typed: Blender keeps floats
    as float32 (0.09 is 0.0900000036), the command line reads 0.09 as a
    double; the shortest decimal that gives the same float32 is the one
    the user meant, and gives the command line's particles."""
    return float(np.format_float_positional(np.float32(x), unique=True, trim="-"))


def shape_text(s):
    """The shape as vdbpack.pack takes it: a name, or "superball:P" with
    the exponent typed (decimal); "OBJECT" stays as it is."""
    if s["shape"] == "superball":
        return "superball:%r" % decimal(s["superball_exponent"])
    return s["shape"]


def _radius(s):
    """A pass's or a method's radius: the distribution text when given."""
    d = s.get("distribution", "").strip()
    return d if d else decimal(s["radius"])


def _lattice(s):
    kw = {}
    if s["size_by"] == "COUNT":
        kw["count"] = int(s["count"])
    else:
        kw["radius"] = decimal(s["radius"])
    if s["lattice"] != "default":
        kw["lattice"] = s["lattice"]
    return kw


def _rsa(s):
    passes = []
    for p in s["passes"]:
        q = {"count": "max" if p["maximal"] else int(p["count"]), "radius": _radius(p)}
        if p["retries"]:
            q["retries"] = int(p["retries"])
        if p["grow"]:
            q["grow"] = True
        if p["name"].strip():
            q["name"] = p["name"].strip()
        passes.append(q)
    if not passes:  # no list: one pass of the method's own radius and count
        passes.append({"count": int(s["count"]), "radius": _radius(s)})
    kw = {"passes": passes}
    if s["shape"] != "sphere":
        kw["orient"] = s["orient"]
    return kw


def _relax(s):
    kw = {"radius": _radius(s), "count": int(s["count"])}
    if s["use_target_fraction"]:
        kw["target_fraction"] = decimal(s["target_fraction"])
    return kw


def _jam(s):
    """The number of spheres from Count, or with Target Fraction ticked from
    the fraction of the container (jam takes one or the other, not both);
    the radius (or distribution) sets the radii's shape and, with a target
    fraction, their size for the count; the jamming point scales them."""
    kw = {"radius": _radius(s)}
    if s["use_target_fraction"]:
        kw["target_fraction"] = decimal(s["target_fraction"])
    else:
        kw["count"] = int(s["count"])
    return kw


class Method:
    def __init__(self, name, label, description, shows, options, solids, mesh_shapes):
        self.name = name
        self.label = label
        self.description = description
        self.shows = shows            # settings the panel draws for this method
        self.options = options        # settings dict -> pack() keywords
        self.solids = solids          # packs the platonic solids
        self.mesh_shapes = mesh_shapes  # packs a mesh object as the particle


METHODS = [
    Method("lattice", "Lattice", "Spheres or solids on a lattice, best offset (and rotation)",
           ("lattice", "size_by"), _lattice, True, False),
    Method("rsa", "Random (RSA)", "Random sequential addition in passes, optionally grown",
           ("passes", "orient"), _rsa, True, True),
    Method("relax", "Relax", "Spheres relaxed apart to a target fraction",
           ("radius", "distribution", "count", "target_fraction"), _relax, False, False),
    Method("jam", "Jam", "Spheres compressed to the jamming point (random close packing)",
           ("radius", "distribution", "count", "target_fraction"), _jam, False, False),
]
BY_NAME = {m.name: m for m in METHODS}


def available(module):
    """Names of the methods the loaded vdbpack module packs."""
    return tuple(getattr(module, "METHODS", ("lattice", "rsa", "relax")))


def pack_options(s):
    """(method, keywords for vdbpack.pack without the container and the
    shape) from a settings dict; ValueError with a sentence for the user
    when the combination cannot pack."""
    m = BY_NAME.get(s["method"])
    if m is None:
        raise ValueError("unknown method '%s'" % s["method"])
    shape = s["shape"]
    if shape == "OBJECT" and not m.mesh_shapes:
        raise ValueError("a mesh object as the particle packs with the Random (RSA) method")
    if (shape in SOLIDS or shape == "superball") and not m.solids:
        raise ValueError("%s packs spheres only: choose Sphere, or the Lattice or Random "
                         "method for a %s" % (m.label, shape))
    kw = m.options(s)
    kw["fit"] = s["fit"]
    kw["seed"] = int(s["seed"])
    if int(s["threads"]):
        kw["threads"] = int(s["threads"])
    return m.name, kw
