# SPDX-License-Identifier: Apache-2.0
"""vdbpack for Blender: fill a mesh with packed particles from the 3D
view's sidebar (tab "vdbpack"), built on the vdbpack Python module
(docs/blender.md). Settings: bpy.context.scene.vdbpack; operators
bpy.ops.vdbpack.fill(), import_packing(filepath=...), export_packing."""

bl_info = {
    "name": "vdbpack",
    "author": "the vdbpack authors",
    "version": (0, 2, 0),
    "blender": (3, 4, 0),
    "location": "View3D > Sidebar > vdbpack; File > Import/Export > vdbpack Packing",
    "description": "Fill meshes with non-overlapping particles (lattice, random, relaxed)",
    "doc_url": "https://github.com/vdbpack/vdbpack/blob/main/docs/blender.md",
    "category": "Object",
}

import bpy  # noqa: E402
from bpy.props import StringProperty  # noqa: E402

from . import operators, settings, ui  # noqa: E402


class VDBPACK_preferences(bpy.types.AddonPreferences):
    bl_idname = __package__

    module_dir: StringProperty(
        name="vdbpack Module Folder", subtype='DIR_PATH', default="",
        description="The folder holding the vdbpack Python module (build/python, or "
                    "PREFIX/lib/python3/dist-packages); empty: Blender's PYTHONPATH")
    library: StringProperty(
        name="Library", subtype='FILE_PATH', default="",
        description="libvdbpack.so to load ($VDBPACK_LIBRARY); empty: the one the module names")

    def draw(self, context):
        self.layout.prop(self, "module_dir")
        self.layout.prop(self, "library")
        from . import engine
        try:
            vp = engine.load_vdbpack(self.module_dir, self.library)
            self.layout.label(text="vdbpack %s: %s" % (vp.version(), vp.library_path()),
                              icon='CHECKMARK')
        except engine.SetupError as e:
            self.layout.label(text=str(e), icon='ERROR')


def register():
    bpy.utils.register_class(VDBPACK_preferences)
    settings.register()
    operators.register()
    ui.register()


def unregister():
    ui.unregister()
    operators.unregister()
    settings.unregister()
    bpy.utils.unregister_class(VDBPACK_preferences)
