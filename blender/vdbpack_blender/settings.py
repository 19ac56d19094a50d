# SPDX-License-Identifier: Apache-2.0
"""The panel's settings, stored on the scene as bpy.context.scene.vdbpack:
the original application's (method, lattice, shape, passes with count,
radius, retries and grow) and today's (fit, seed, voxel size, threads,
distributions, group names), and the last run's report."""
import bpy
from bpy.props import (BoolProperty, CollectionProperty, EnumProperty, FloatProperty,
                       IntProperty, PointerProperty, StringProperty)

from . import methods

SHAPE_ITEMS = [
    ("sphere", "Sphere", "Spheres (instanced as a UV sphere)", 'MESH_UVSPHERE', 0),
    ("tetrahedron", "Tetrahedron", "Regular tetrahedra", 'MESH_CONE', 1),
    ("cube", "Cube", "Cubes", 'MESH_CUBE', 2),
    ("octahedron", "Octahedron", "Regular octahedra", 'MESH_ICOSPHERE', 3),
    ("dodecahedron", "Dodecahedron", "Regular dodecahedra", 'MESH_ICOSPHERE', 4),
    ("icosahedron", "Icosahedron", "Regular icosahedra", 'MESH_ICOSPHERE', 5),
    ("truncated-tetrahedron", "Truncated Tetrahedron", "Archimedean solid: truncated tetrahedron", 'MESH_ICOSPHERE', 7),
    ("cuboctahedron", "Cuboctahedron", "Archimedean solid: cuboctahedron", 'MESH_ICOSPHERE', 8),
    ("truncated-cube", "Truncated Cube", "Archimedean solid: truncated cube", 'MESH_ICOSPHERE', 9),
    ("truncated-octahedron", "Truncated Octahedron", "Archimedean solid: truncated octahedron", 'MESH_ICOSPHERE', 10),
    ("rhombicuboctahedron", "Rhombicuboctahedron", "Archimedean solid: rhombicuboctahedron", 'MESH_ICOSPHERE', 11),
    ("truncated-cuboctahedron", "Truncated Cuboctahedron", "Archimedean solid: truncated cuboctahedron", 'MESH_ICOSPHERE', 12),
    ("snub-cube", "Snub Cube", "Archimedean solid: snub cube", 'MESH_ICOSPHERE', 13),
    ("icosidodecahedron", "Icosidodecahedron", "Archimedean solid: icosidodecahedron", 'MESH_ICOSPHERE', 14),
    ("truncated-dodecahedron", "Truncated Dodecahedron", "Archimedean solid: truncated dodecahedron", 'MESH_ICOSPHERE', 15),
    ("truncated-icosahedron", "Truncated Icosahedron", "Archimedean solid: truncated icosahedron", 'MESH_ICOSPHERE', 16),
    ("rhombicosidodecahedron", "Rhombicosidodecahedron", "Archimedean solid: rhombicosidodecahedron", 'MESH_ICOSPHERE', 17),
    ("truncated-icosidodecahedron", "Truncated Icosidodecahedron", "Archimedean solid: truncated icosidodecahedron", 'MESH_ICOSPHERE', 18),
    ("snub-dodecahedron", "Snub Dodecahedron", "Archimedean solid: snub dodecahedron", 'MESH_ICOSPHERE', 19),
    ("superball", "Superball", "Superballs |x|^2p + |y|^2p + |z|^2p <= 1 of the exponent p "
     "below: 0.5 an octahedron, 1 a sphere, larger p ever more like a cube", 'MESH_UVSPHERE', 20),
    # OBJECT keeps number 6 (saved .blend files store the numbers)
    ("OBJECT", "Mesh Object", "Any closed mesh object of the scene as the particle (Random "
     "method)", 'OBJECT_DATA', 6),
]
LATTICE_ITEMS = [
    ("default", "Default", "fcc for spheres, the densest lattice for solids"),
    ("sc", "Simple Cubic", "Simple cubic (spheres)"),
    ("bcc", "Body-Centred Cubic", "Body-centred cubic (spheres)"),
    ("fcc", "Face-Centred Cubic", "Face-centred cubic (spheres)"),
    ("hcp", "Hexagonal Close", "Hexagonal close packed (spheres)"),
    ("densest", "Densest", "The shape's densest known lattice packing"),
]


_METHOD_ITEMS = [(m.name, m.label, m.description, i) for i, m in enumerate(methods.METHODS)]


def _poll_mesh(self, obj):
    return obj.type == 'MESH'


class VDBPACK_PG_pass(bpy.types.PropertyGroup):
    """One pass of the Random method (the command line's --pass)."""
    maximal: BoolProperty(name="Max", default=False,
                          description="Place until no more fit (with a distribution: until "
                                      "none of its smallest radius fits)")
    count: IntProperty(name="Count", default=100, min=1, soft_max=1000000,
                       description="Particles to place in this pass")
    radius: FloatProperty(name="Radius", default=0.05, min=1e-6, soft_max=10, precision=4,
                          unit='LENGTH', description="Bounding-sphere radius of the particles")
    distribution: StringProperty(
        name="Distribution", default="",
        description="Instead of the radius: uniform:A:B, lognormal:MEAN:SD or list:R1:R2:...")
    retries: IntProperty(name="Retries", default=0, min=0, max=1000000000,
                         description="Failed tries in a row that end the pass (0: 5000)")
    grow: BoolProperty(name="Grow", default=False,
                       description="Grow the pass's particles until they touch")
    name: StringProperty(name="Name", default="",
                         description="The pass's group name (default pass1, pass2, ...)")


class VDBPACK_PG_settings(bpy.types.PropertyGroup):
    method: EnumProperty(name="Method", items=_METHOD_ITEMS, default="lattice",
                         description="How the particles are placed")
    lattice: EnumProperty(name="Lattice", items=LATTICE_ITEMS, default="default")
    shape: EnumProperty(name="Shape", items=SHAPE_ITEMS, default="sphere")
    superball_exponent: FloatProperty(
        name="Exponent", default=2.0, min=0.5, max=1000.0, soft_max=10.0, precision=3,
        description="The superball's exponent p (0.5 to 1000: convex superballs)")
    shape_object: PointerProperty(name="Particle Object", type=bpy.types.Object, poll=_poll_mesh,
                                  description="The closed mesh each particle is a copy of")
    fit: EnumProperty(name="Fit", default="inside", items=[
        ("inside", "Inside", "Particles wholly inside the container"),
        ("center", "Centre", "Only the particles' centres inside")])
    size_by: EnumProperty(name="Size", default="RADIUS", items=[
        ("RADIUS", "Radius", "Particles of this radius"),
        ("COUNT", "Count", "About this many particles")])
    radius: FloatProperty(name="Radius", default=0.05, min=1e-6, soft_max=10, precision=4,
                          unit='LENGTH', description="Particle (bounding-sphere) radius")
    distribution: StringProperty(
        name="Distribution", default="",
        description="Instead of the radius: uniform:A:B, lognormal:MEAN:SD or list:R1:R2:...")
    count: IntProperty(name="Count", default=1000, min=1, soft_max=1000000,
                       description="Number of particles")
    use_target_fraction: BoolProperty(name="Target Fraction", default=False,
                                      description="Scale the radii to fill this fraction")
    target_fraction: FloatProperty(name="Fraction", default=0.55, min=0.01, max=0.74,
                                   description="Volume fraction the particles should fill")
    orient: EnumProperty(name="Orientation", default="random", items=[
        ("random", "Random", "Random orientations"),
        ("fixed", "Fixed", "All particles as the unit shape")])
    passes: CollectionProperty(type=VDBPACK_PG_pass)
    active_pass: IntProperty(name="Active Pass", default=0)
    seed: IntProperty(name="Seed", default=1, min=0, description="Random seed")
    voxel_size: FloatProperty(name="Voxel Size", default=0.0, min=0.0, precision=4,
                              unit='LENGTH',
                              description="Level-set voxel size of the container (0: automatic)")
    threads: IntProperty(name="Threads", default=0, min=0, max=256,
                         description="Worker threads (0: all cores); the result does not depend "
                                     "on it")
    check: BoolProperty(name="Check", default=True,
                        description="Check overlaps and particles outside after packing")
    # the last run, for the panel
    report: StringProperty(name="Report", default="")
    report_ok: BoolProperty(default=True)


def as_dict(s):
    """The settings as plain data for methods.pack_options."""
    d = {k: getattr(s, k) for k in (
        "method", "lattice", "shape", "superball_exponent", "fit", "size_by", "radius", "distribution", "count",
        "use_target_fraction", "target_fraction", "orient", "seed", "threads")}
    d["passes"] = [{k: getattr(p, k) for k in ("maximal", "count", "radius", "distribution",
                                              "retries", "grow", "name")} for p in s.passes]
    return d


classes = (VDBPACK_PG_pass, VDBPACK_PG_settings)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.vdbpack = PointerProperty(type=VDBPACK_PG_settings)


def unregister():
    del bpy.types.Scene.vdbpack
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
