# SPDX-License-Identifier: Apache-2.0
"""Blender's side of a packing: meshes out of objects as arrays, and the
particle object with its attributes and Geometry Nodes instancer back in.
Runs in Blender's main thread only."""
import bpy
import numpy as np

RESERVED = {"position", "pscale", "id", "orient", "rotation", "group"}
SHAPE_COLLECTION = "vdbpack shapes"
SPHERE_SEGMENTS, SPHERE_RINGS = 32, 16


class MeshError(Exception):
    """The active object cannot be a container (the message says why)."""


def mesh_arrays(context, obj, world=True):
    """The evaluated mesh of obj (modifiers applied) as float64 vertices
    (N, 3), in world space when `world`, and int32 triangles (M, 3)."""
    if obj is None:
        raise MeshError("no active object: select the mesh to fill")
    if obj.get("vdbpack_source") is not None:
        raise MeshError("'%s' is a particle object made by vdbpack: select its container "
                        "('%s') to fill it again" % (obj.name, obj["vdbpack_source"]))
    if obj.type != 'MESH':
        raise MeshError("'%s' is a %s, not a mesh: select a mesh object to fill (convert "
                        "curves, text and metaballs with Object > Convert > Mesh)"
                        % (obj.name, obj.type.lower()))
    ev = obj.evaluated_get(context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    try:
        me.calc_loop_triangles()
        n, m = len(me.vertices), len(me.loop_triangles)
        v = np.empty(3 * n, np.float32)
        me.vertices.foreach_get("co", v)
        t = np.empty(3 * m, np.int32)
        me.loop_triangles.foreach_get("vertices", t)
    finally:
        ev.to_mesh_clear()
    if m == 0:
        raise MeshError("'%s' has no faces (%d vertices): a container must enclose a volume"
                        % (obj.name, n))
    v = v.reshape(-1, 3).astype(np.float64)
    if world:
        mw = np.array(obj.matrix_world, np.float64)
        v = v @ mw[:3, :3].T + mw[:3, 3]
    return v, t.reshape(-1, 3)


# -- the result --------------------------------------------------------------


def euler_xyz(orient):
    """Blender's XYZ Euler angles (the Instance on Points Rotation input of
    Blender 3.x) of unit quaternions (x, y, z, w)."""
    x, y, z, w = orient.T
    return np.stack([np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y)),
                     np.arcsin(np.clip(2 * (w * y - z * x), -1, 1)),
                     np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))], axis=1)


def group_attribute(name):
    return "group_" + name if name in RESERVED else name


def results_of(source):
    return [o for o in bpy.data.objects if o.get("vdbpack_source") == source]


def remove_results(source):
    """Deletes earlier particle objects of this container (and their data)."""
    for o in results_of(source):
        me = o.data if o.type == 'MESH' else None
        groups = [m.node_group for m in o.modifiers if m.type == 'NODES' and m.node_group]
        bpy.data.objects.remove(o)
        if me is not None and me.users == 0:
            bpy.data.meshes.remove(me)
        for g in groups:
            if g.users == 0:
                bpy.data.node_groups.remove(g)


def _shape_collection(scene):
    coll = bpy.data.collections.get(SHAPE_COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(SHAPE_COLLECTION)
    if coll.name not in scene.collection.children:
        scene.collection.children.link(coll)
    return coll


def shape_object(scene, name, vertices, faces):
    """An object holding the unit particle (what pscale 1 and the identity
    orient mean), hidden, in the collection "vdbpack shapes"; an existing
    one of that name gets the new mesh."""
    me = bpy.data.meshes.new(name)
    me.from_pydata(vertices.tolist(), [], faces)
    me.update()
    obj = bpy.data.objects.get(name)
    if obj is not None and obj.type == 'MESH':
        old = obj.data
        obj.data = me
        if old.users == 0:
            bpy.data.meshes.remove(old)
    else:
        obj = bpy.data.objects.new(name, me)
    coll = _shape_collection(scene)
    if obj.name not in coll.objects:
        coll.objects.link(obj)
    obj.hide_render = True
    try:
        obj.hide_set(True)
    except RuntimeError:  # not in the view layer
        pass
    return obj


def _output(node, name):
    """The enabled output of that name: Blender 3.x's Named Attribute has
    one "Attribute" output per data type, all but one of them hidden."""
    return [s for s in node.outputs if s.name == name and s.enabled][0]


def instancer(name, shape_obj):
    """Geometry Nodes: the points become instances of shape_obj (a UV
    sphere of radius 1 when None), scaled by pscale and turned by
    rotation."""
    ng = bpy.data.node_groups.new(name, 'GeometryNodeTree')
    if hasattr(ng, "interface"):  # Blender 4.0 and later (untested here)
        ng.interface.new_socket("Geometry", in_out='INPUT', socket_type='NodeSocketGeometry')
        ng.interface.new_socket("Geometry", in_out='OUTPUT', socket_type='NodeSocketGeometry')
    else:
        ng.inputs.new('NodeSocketGeometry', "Geometry")
        ng.outputs.new('NodeSocketGeometry', "Geometry")
    nodes, links = ng.nodes, ng.links
    gin = nodes.new('NodeGroupInput')
    gin.location = (-600, 0)
    gout = nodes.new('NodeGroupOutput')
    gout.location = (300, 0)
    iop = nodes.new('GeometryNodeInstanceOnPoints')
    iop.location = (0, 0)
    links.new(gin.outputs["Geometry"], iop.inputs["Points"])
    if shape_obj is None:
        src = nodes.new('GeometryNodeMeshUVSphere')
        src.inputs["Segments"].default_value = SPHERE_SEGMENTS
        src.inputs["Rings"].default_value = SPHERE_RINGS
        src.inputs["Radius"].default_value = 1.0
        links.new(src.outputs["Mesh"], iop.inputs["Instance"])
    else:
        src = nodes.new('GeometryNodeObjectInfo')
        src.transform_space = 'ORIGINAL'
        src.inputs["Object"].default_value = shape_obj
        links.new(src.outputs["Geometry"], iop.inputs["Instance"])
    src.location = (-300, -150)
    scale = nodes.new('GeometryNodeInputNamedAttribute')
    scale.data_type = 'FLOAT'
    scale.inputs["Name"].default_value = "pscale"
    scale.location = (-300, -350)
    links.new(_output(scale, "Attribute"), iop.inputs["Scale"])
    if shape_obj is not None:
        rot = nodes.new('GeometryNodeInputNamedAttribute')
        rot.data_type = 'FLOAT_VECTOR'
        rot.inputs["Name"].default_value = "rotation"
        rot.location = (-300, -500)
        links.new(_output(rot, "Attribute"), iop.inputs["Rotation"])
    links.new(iop.outputs["Instances"], gout.inputs["Geometry"])
    return ng


def _attr(me, name, kind, values, field="value"):
    a = me.attributes.new(name, kind, 'POINT')
    a.data.foreach_set(field, np.ascontiguousarray(values).ravel())
    return a


def build_result(context, source, packing, unit_shape, shape_label, extra=None):
    """The particle object for `packing`: a mesh of loose vertices (one per
    particle, in world space) with the point attributes pscale, id, orient
    (x, y, z, w), rotation (XYZ Euler), group and one boolean per group,
    and a Geometry Nodes modifier instancing the unit shape. Replaces the
    earlier result of the same source; returns the object."""
    scene = context.scene
    n = len(packing)
    me = bpy.data.meshes.new(source + " particles")
    me.vertices.add(n)
    me.vertices.foreach_set("co", packing.positions.astype(np.float32).ravel())
    _attr(me, "pscale", 'FLOAT', packing.radii.astype(np.float32))
    _attr(me, "id", 'INT', np.asarray(packing.ids, np.int32))
    groups = np.asarray(packing.groups, np.int32)
    _attr(me, "group", 'INT', groups)
    if packing.orient is not None:
        q = packing.orient.astype(np.float64)
        _attr(me, "orient", 'FLOAT_COLOR', q.astype(np.float32), "color")
        _attr(me, "rotation", 'FLOAT_VECTOR', euler_xyz(q).astype(np.float32), "vector")
    for g, gname in enumerate(packing.group_names):
        _attr(me, group_attribute(gname), 'BOOLEAN', groups == g)
    me.update()

    shape_obj = None
    if unit_shape is not None:
        shape_obj = shape_object(scene, "vdbpack shape " + shape_label, *unit_shape)

    remove_results(source)
    obj = bpy.data.objects.new(source + " particles", me)
    obj["vdbpack_source"] = source
    obj["vdbpack_shape"] = packing.shape
    obj["vdbpack_shape_label"] = shape_label
    obj["vdbpack_groups"] = ",".join(packing.group_names)
    if packing.method:
        obj["vdbpack_method"] = packing.method
    for k, v in (extra or {}).items():
        obj[k] = v
    src = bpy.data.objects.get(source)
    colls = src.users_collection if src is not None and src.users_collection else ()
    (colls[0] if colls else scene.collection).objects.link(obj)
    mod = obj.modifiers.new("vdbpack instances", 'NODES')
    mod.node_group = instancer("vdbpack " + shape_label, shape_obj)
    return obj


# -- reading a particle object back ------------------------------------------


def packing_of(vp, obj):
    """A vdbpack.Packing from a particle object made by the add-on (or any
    mesh of loose vertices with pscale, and orient for solids), in world
    space."""
    if obj is None or obj.type != 'MESH':
        raise MeshError("select a particle object (a mesh of vertices made by vdbpack)")
    me = obj.data
    n = len(me.vertices)
    if n == 0:
        raise MeshError("'%s' has no vertices to export" % obj.name)
    if "pscale" not in me.attributes:
        raise MeshError("'%s' has no pscale attribute: it is not a particle object" % obj.name)
    co = np.empty(3 * n, np.float32)
    me.vertices.foreach_get("co", co)
    mw = np.array(obj.matrix_world, np.float64)
    p = co.reshape(-1, 3).astype(np.float64) @ mw[:3, :3].T + mw[:3, 3]
    scale = float(np.cbrt(abs(np.linalg.det(mw[:3, :3]))))

    def get(name, width, field, dtype):
        a = me.attributes[name]
        out = np.empty(width * n, dtype)
        a.data.foreach_get(field, out)
        return out.reshape(-1, width) if width > 1 else out
    radii = get("pscale", 1, "value", np.float32).astype(np.float64) * scale
    shape = obj.get("vdbpack_shape", "sphere")
    orient = None
    if "orient" in me.attributes and shape != "sphere":
        orient = get("orient", 4, "color", np.float32).astype(np.float64)
        orient /= np.linalg.norm(orient, axis=1)[:, None]
        # the object's own rotation turns every particle too
        w, x, y, z = obj.matrix_world.to_quaternion().normalized()
        if abs(w) < 1 - 1e-12:
            qx, qy, qz, qw = orient.T
            orient = np.stack([w * qx + x * qw + y * qz - z * qy,
                               w * qy - x * qz + y * qw + z * qx,
                               w * qz + x * qy - y * qx + z * qw,
                               w * qw - x * qx - y * qy - z * qz], axis=1)
    groups = get("group", 1, "value", np.int32) if "group" in me.attributes else \
        np.zeros(n, np.int32)
    names = [g for g in obj.get("vdbpack_groups", "").split(",") if g] or ["pass1"]
    if groups.max(initial=0) >= len(names):
        names += ["pass%d" % (k + 1) for k in range(len(names), int(groups.max()) + 1)]
    return vp.Packing(p, radii, orient, groups, names, shape)
