# SPDX-License-Identifier: Apache-2.0
"""The operators: fill the active mesh (modal, in a background thread,
Esc cancels), import a packing file, export a particle object to .vdb,
and the pass list's buttons. Every failure becomes a Blender report with
the library's one-line message."""
import os

import bpy
from bpy.props import FloatProperty, IntProperty, StringProperty, EnumProperty
from bpy_extras.io_utils import ExportHelper, ImportHelper

from . import engine, methods, scene, settings


def _prefs(context):
    addon = context.preferences.addons.get(__package__)
    return addon.preferences if addon is not None else None


def vdbpack_module(context):
    p = _prefs(context)
    return engine.load_vdbpack(p.module_dir if p else "", p.library if p else "")


def _user_error(e):
    """The one-line message of an error the user can act on (the library's,
    a file's, a wrong setting's); None for a bug, which goes up."""
    vp = engine._MODULE
    if isinstance(e, (engine.SetupError, scene.MeshError, ValueError, TypeError, OSError,
                      MemoryError)) or (vp is not None and isinstance(e, vp.Error)):
        return str(e) or type(e).__name__
    return None


def _fmt_report(job):
    p = job.packing
    parts = ["%d particles" % len(p), "fraction %.4f" % p.fraction, "%.2f s" % job.seconds]
    ok = True
    if job.check is not None:
        c = job.check
        ok = bool(c.ok)
        parts.append("checked: %s" % ("no overlaps, none outside" if ok else
                                      "%d overlapping pairs, %d outside"
                                      % (c.overlapping_pairs, c.outside)))
    return ", ".join(parts), ok


class VDBPACK_OT_fill(bpy.types.Operator):
    """Fill the active mesh object with particles (the panel's settings)"""
    bl_idname = "vdbpack.fill"
    bl_label = "Fill with Particles"
    bl_options = {'REGISTER', 'UNDO'}

    cancel_at: FloatProperty(
        name="Cancel At", default=-1.0, options={'HIDDEN', 'SKIP_SAVE'},
        description="Cancel once progress reaches this fraction (scripts and tests; "
                    "negative: never)")
    cancel_stage: StringProperty(
        name="Cancel Stage", default="", options={'HIDDEN', 'SKIP_SAVE'},
        description="With Cancel At: only in this stage of the job (\"rsa\", \"voxelizing\", ...)")

    _timer = None
    _job = None

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def _prepare(self, context):
        """The job for the active object, or None after reporting why not."""
        s = context.scene.vdbpack
        obj = context.active_object
        try:
            vp = vdbpack_module(context)
            d = settings.as_dict(s)
            method, kw = methods.pack_options(d)
            if method not in methods.available(vp):
                raise ValueError("this vdbpack (%s) has no method '%s'" % (vp.version(), method))
            v, t = scene.mesh_arrays(context, obj)
            shape_mesh = None
            if d["shape"] == "OBJECT":
                so = s.shape_object
                if so is None:
                    raise ValueError("choose the particle's mesh object (Shape: Mesh Object)")
                if so == obj:
                    raise ValueError("the particle object cannot be the container itself")
                sv, st = scene.mesh_arrays(context, so, world=False)
                shape_mesh = (sv, st, so.name)
        except (engine.SetupError, scene.MeshError, ValueError) as e:
            self._fail(context, str(e))
            return None
        return engine.Job(vp, v, t, obj.name, method, kw, shape=methods.shape_text(d),
                          shape_mesh=shape_mesh, voxel_size=methods.decimal(s.voxel_size),
                          check=s.check,
                          cancel_at=self.cancel_at if self.cancel_at >= 0 else None,
                          cancel_stage=self.cancel_stage)

    def _fail(self, context, message):
        context.scene.vdbpack.report = message
        context.scene.vdbpack.report_ok = False
        self.report({'ERROR'}, "vdbpack: " + message)

    def _finish(self, context, job):
        s = context.scene.vdbpack
        if job.cancelled:
            s.report = "cancelled (%s, %.0f%%) after %.1f s: nothing made" % (
                job.stage, 100 * job.fraction, job.seconds)
            s.report_ok = True
            self.report({'WARNING'}, "vdbpack: cancelled")
            return {'CANCELLED'}
        if job.error is not None:
            self._fail(context, job.error)
            return {'CANCELLED'}
        p = job.packing
        label = p.shape if p.shape != "mesh" else job.shape_mesh[2]
        obj = scene.build_result(context, job.name, p, job.unit_shape, label,
                                 {"vdbpack_fraction": float(p.fraction),
                                  "vdbpack_seconds": float(job.seconds)})
        text, ok = _fmt_report(job)
        s.report, s.report_ok = text, ok
        self.report({'INFO'} if ok else {'WARNING'}, "vdbpack: " + text)
        for o in context.view_layer.objects:
            o.select_set(False)
        obj.select_set(True)
        return {'FINISHED'}

    def execute(self, context):
        # from scripts: the same job, waited for here
        job = self._prepare(context)
        if job is None:
            return {'CANCELLED'}
        wm = context.window_manager
        wm.progress_begin(0, 100)
        try:
            job.run()
        finally:
            wm.progress_end()
        return self._finish(context, job)

    def invoke(self, context, event):
        job = self._prepare(context)
        if job is None:
            return {'CANCELLED'}
        self._job = job
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.modal_handler_add(self)
        wm.progress_begin(0, 100)
        job.start()
        return {'RUNNING_MODAL'}

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        if context.workspace is not None:
            context.workspace.status_text_set(None)

    def modal(self, context, event):
        job = self._job
        if event.type == 'ESC' and event.value == 'PRESS':
            job.cancel()
            if context.workspace is not None:
                context.workspace.status_text_set("vdbpack: cancelling...")
            return {'RUNNING_MODAL'}
        if event.type != 'TIMER':
            return {'PASS_THROUGH'}
        if not job.done:
            context.window_manager.progress_update(int(100 * job.fraction))
            if context.workspace is not None:
                context.workspace.status_text_set("vdbpack: %s %d%%  (Esc to cancel)"
                                                  % (job.stage, 100 * job.fraction))
            return {'PASS_THROUGH'}
        job.join()
        self._end(context)
        result = self._finish(context, job)
        for area in context.screen.areas if context.screen else ():
            area.tag_redraw()
        return result

    def cancel(self, context):  # Blender ends the operator (file load, quit)
        if self._job is not None:
            self._job.cancel()
            self._job.join()
            self._end(context)


def _shape_items():
    return [(k, n, d) for k, n, d, _i, _j in settings.SHAPE_ITEMS if k != "OBJECT"]


class VDBPACK_OT_import_packing(bpy.types.Operator, ImportHelper):
    """Import a vdbpack packing (.vdb points, .ply or .csv) as a particle object"""
    bl_idname = "vdbpack.import_packing"
    bl_label = "Import vdbpack Packing"
    bl_options = {'REGISTER', 'UNDO'}

    filename_ext = ".vdb"
    filter_glob: StringProperty(default="*.vdb;*.ply;*.csv", options={'HIDDEN'})
    shape: EnumProperty(name="Shape (CSV)", items=_shape_items(), default="sphere",
                        description="The particle shape of a .csv with orientations (a CSV "
                                    "does not record it)")
    superball_exponent: FloatProperty(name="Exponent (CSV)", default=2.0, min=0.5, max=1000.0,
                                      soft_max=10.0, precision=3,
                                      description="Shape (CSV) Superball: its exponent p")

    def execute(self, context):
        path = self.filepath
        try:
            vp = vdbpack_module(context)
            try:
                packing = vp.read(path)
            except ValueError as e:
                if "shape=" not in str(e) or not path.lower().endswith(".csv"):
                    raise
                packing = vp.read(path, shape=methods.shape_text(
                    {"shape": self.shape, "superball_exponent": self.superball_exponent}))
            unit, shown, label = None, packing, packing.shape
            if packing.shape == "mesh":
                # the file names its mesh shape but does not hold it
                label = str(packing.metadata.get("shape_file", "mesh"))
                self.report({'WARNING'}, "vdbpack: %s holds particles of the mesh shape '%s', "
                            "shown as their bounding spheres" % (os.path.basename(path), label))
                shown = vp.Packing(packing.positions, packing.radii, None, packing.groups,
                                   packing.group_names, "sphere")
                shown.method = packing.method
            else:
                unit = engine.unit_shape(vp, packing)
            obj = scene.build_result(context, os.path.basename(path), shown, unit, label,
                                     {"vdbpack_file": path})
        except Exception as e:
            message = _user_error(e)
            if message is None:
                raise
            self.report({'ERROR'}, "vdbpack: " + message)
            return {'CANCELLED'}
        self.report({'INFO'}, "vdbpack: %d particles from %s" % (len(packing),
                                                                  os.path.basename(path)))
        context.view_layer.objects.active = obj
        return {'FINISHED'}


class VDBPACK_OT_export_packing(bpy.types.Operator, ExportHelper):
    """Export the active particle object as OpenVDB points (P, pscale, orient, id, groups)"""
    bl_idname = "vdbpack.export_packing"
    bl_label = "Export vdbpack Packing"

    filename_ext = ".vdb"
    filter_glob: StringProperty(default="*.vdb;*.ply;*.csv", options={'HIDDEN'})

    @classmethod
    def poll(cls, context):
        o = context.active_object
        return o is not None and o.type == 'MESH'

    def execute(self, context):
        obj = context.active_object
        try:
            vp = vdbpack_module(context)
            packing = scene.packing_of(vp, obj)
            packing.write(self.filepath, metadata={"blender_object": obj.name})
        except Exception as e:
            message = _user_error(e)
            if message is None:
                raise
            self.report({'ERROR'}, "vdbpack: " + message)
            return {'CANCELLED'}
        self.report({'INFO'}, "vdbpack: wrote %d particles to %s"
                    % (len(packing), os.path.basename(self.filepath)))
        return {'FINISHED'}


class VDBPACK_OT_pass_add(bpy.types.Operator):
    """Add a pass (Random method)"""
    bl_idname = "vdbpack.pass_add"
    bl_label = "Add Pass"
    bl_options = {'REGISTER', 'UNDO'}

    def execute(self, context):
        s = context.scene.vdbpack
        p = s.passes.add()
        if len(s.passes) > 1:  # the next pass: smaller particles filling the gaps
            prev = s.passes[len(s.passes) - 2]
            p.radius = prev.radius / 2
            p.count = prev.count * 4
        s.active_pass = len(s.passes) - 1
        return {'FINISHED'}


class VDBPACK_OT_pass_remove(bpy.types.Operator):
    """Remove the selected pass"""
    bl_idname = "vdbpack.pass_remove"
    bl_label = "Remove Pass"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return len(context.scene.vdbpack.passes) > 0

    def execute(self, context):
        s = context.scene.vdbpack
        s.passes.remove(s.active_pass)
        s.active_pass = min(s.active_pass, len(s.passes) - 1)
        return {'FINISHED'}


class VDBPACK_OT_pass_move(bpy.types.Operator):
    """Move the selected pass up or down (passes run in order)"""
    bl_idname = "vdbpack.pass_move"
    bl_label = "Move Pass"
    bl_options = {'REGISTER', 'UNDO'}

    direction: IntProperty(default=-1)

    def execute(self, context):
        s = context.scene.vdbpack
        i, j = s.active_pass, s.active_pass + self.direction
        if 0 <= i < len(s.passes) and 0 <= j < len(s.passes):
            s.passes.move(i, j)
            s.active_pass = j
        return {'FINISHED'}


def menu_import(self, context):
    self.layout.operator(VDBPACK_OT_import_packing.bl_idname,
                         text="vdbpack Packing (.vdb, .ply, .csv)")


def menu_export(self, context):
    self.layout.operator(VDBPACK_OT_export_packing.bl_idname, text="vdbpack Packing (.vdb)")


classes = (VDBPACK_OT_fill, VDBPACK_OT_import_packing, VDBPACK_OT_export_packing,
           VDBPACK_OT_pass_add, VDBPACK_OT_pass_remove, VDBPACK_OT_pass_move)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_import.append(menu_import)
    bpy.types.TOPBAR_MT_file_export.append(menu_export)


def unregister():
    bpy.types.TOPBAR_MT_file_export.remove(menu_export)
    bpy.types.TOPBAR_MT_file_import.remove(menu_import)
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
