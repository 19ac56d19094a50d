# SPDX-License-Identifier: Apache-2.0
"""The sidebar panel (3D view, N, tab "vdbpack") and the pass list."""
import bpy

from . import engine, methods


class VDBPACK_UL_passes(bpy.types.UIList):
    """One row per pass: count (or max), radius (or distribution), retries,
    grow, name."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.label(text=item.name or "pass%d" % (index + 1))
        sub = row.row(align=True)
        sub.prop(item, "maximal", text="max", toggle=True)
        c = sub.row(align=True)
        c.active = not item.maximal
        c.prop(item, "count", text="")
        if item.distribution.strip():
            row.label(text=item.distribution)
        else:
            row.prop(item, "radius", text="r")
        row.prop(item, "grow", text="", icon='FULLSCREEN_ENTER')


class VDBPACK_PT_panel(bpy.types.Panel):
    bl_label = "vdbpack"
    bl_idname = "VDBPACK_PT_panel"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "vdbpack"

    def draw(self, context):
        s = context.scene.vdbpack
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        try:
            vp = engine.load_vdbpack(*_prefs_paths(context))
            have = methods.available(vp)
        except engine.SetupError as e:
            box = layout.box()
            box.alert = True
            box.label(text="vdbpack module not found", icon='ERROR')
            box.label(text="Set its folder in the add-on's preferences")
            have = ()
            del e
        m = methods.BY_NAME[s.method]
        layout.prop(s, "method")
        if have and s.method not in have:
            layout.label(text="This vdbpack has no '%s' method" % s.method, icon='ERROR')
        layout.prop(s, "shape")
        if s.shape == 'OBJECT':
            layout.prop(s, "shape_object")
        elif s.shape == 'superball':
            layout.prop(s, "superball_exponent")
        if "lattice" in m.shows:
            layout.prop(s, "lattice")
        if "size_by" in m.shows:
            layout.prop(s, "size_by", expand=True)
            layout.prop(s, "radius" if s.size_by == 'RADIUS' else "count")
        if "radius" in m.shows:
            col = layout.column()
            col.active = not s.distribution.strip()
            col.prop(s, "radius")
            layout.prop(s, "distribution")
            row = layout.row()
            # jam: Count or Target Fraction, not both (methods._jam)
            row.active = not (s.method == "jam" and s.use_target_fraction)
            row.prop(s, "count")
        if "target_fraction" in m.shows:
            row = layout.row(heading="Target Fraction")
            row.prop(s, "use_target_fraction", text="")
            sub = row.row()
            sub.active = s.use_target_fraction
            sub.prop(s, "target_fraction", text="")
        if "passes" in m.shows:
            layout.label(text="Passes (run in order):")
            row = layout.row()
            row.template_list("VDBPACK_UL_passes", "", s, "passes", s, "active_pass", rows=3)
            col = row.column(align=True)
            col.operator("vdbpack.pass_add", icon='ADD', text="")
            col.operator("vdbpack.pass_remove", icon='REMOVE', text="")
            col.separator()
            col.operator("vdbpack.pass_move", icon='TRIA_UP', text="").direction = -1
            col.operator("vdbpack.pass_move", icon='TRIA_DOWN', text="").direction = 1
            if 0 <= s.active_pass < len(s.passes):
                p = s.passes[s.active_pass]
                box = layout.box()
                box.use_property_split = True
                box.prop(p, "name")
                box.prop(p, "maximal")
                r = box.row()
                r.active = not p.maximal
                r.prop(p, "count")
                r = box.row()
                r.active = not p.distribution.strip()
                r.prop(p, "radius")
                box.prop(p, "distribution")
                box.prop(p, "retries")
                box.prop(p, "grow")
            elif not s.passes:
                layout.label(text="No passes: one pass of Radius and Count below")
                layout.prop(s, "radius")
                layout.prop(s, "count")
            if s.shape != 'sphere':
                layout.prop(s, "orient")
        layout.prop(s, "fit")
        layout.prop(s, "seed")
        layout.prop(s, "voxel_size")
        layout.prop(s, "threads")
        layout.prop(s, "check")
        row = layout.row()
        row.scale_y = 1.5
        obj = context.active_object
        row.enabled = obj is not None and obj.type == 'MESH'
        row.operator("vdbpack.fill", icon='PARTICLES')
        if s.report:
            box = layout.box()
            box.alert = not s.report_ok
            for i, part in enumerate(s.report.split(", ")):
                box.label(text=part, icon=('INFO' if s.report_ok else 'ERROR') if i == 0 else
                          'BLANK1')


def _prefs_paths(context):
    addon = context.preferences.addons.get(__package__)
    if addon is None:
        return "", ""
    return addon.preferences.module_dir, addon.preferences.library


classes = (VDBPACK_UL_passes, VDBPACK_PT_panel)


def register():
    for c in classes:
        bpy.utils.register_class(c)


def unregister():
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
