# SPDX-License-Identifier: Apache-2.0
"""The add-on as a user installs it: the zip through Preferences > Add-ons >
Install (bpy.ops.preferences.addon_install) into an empty user folder, in a
Blender started without PYTHONPATH. Until the module folder is set in the
add-on's preferences, Fill reports how to set it; then it fills a cube.
Run by tests/blender/run.sh install."""
import os
import sys

import addon_utils
import bpy

zip_path, module_dir = sys.argv[sys.argv.index("--") + 1:][:2]
fails = []


def check(cond, what):
    if not cond:
        fails.append(what)
        print("FAIL:", what)


try:
    import vdbpack  # noqa: F401
    check(False, "vdbpack is importable before the preferences name it (PYTHONPATH leaked)")
except ImportError:
    pass
bpy.ops.preferences.addon_install(filepath=zip_path)
bpy.ops.preferences.addon_enable(module="vdbpack_blender")
installed = [m.__file__ for m in addon_utils.modules() if m.__name__ == "vdbpack_blender"]
check(installed and installed[0].startswith(os.environ["BLENDER_USER_SCRIPTS"]),
      "installed at %s" % installed)
check(hasattr(bpy.context.scene, "vdbpack"), "scene.vdbpack after enabling")
bpy.ops.mesh.primitive_cube_add(size=2)
s = bpy.context.scene.vdbpack
s.method, s.size_by, s.radius = "lattice", "RADIUS", 0.1
try:
    bpy.ops.vdbpack.fill()
    check(False, "fill without the module succeeded")
except RuntimeError as e:
    check("add-on's preferences" in str(e), "no module: %s" % e)
    print("without the module:", str(e).strip())
prefs = bpy.context.preferences.addons["vdbpack_blender"].preferences
prefs.module_dir = module_dir
r = bpy.ops.vdbpack.fill()
check(r == {'FINISHED'}, "fill with the module folder set: %s" % r)
print("with the module folder set:", s.report)
check(s.report.startswith("1000 particles") or "particles" in s.report, "report %r" % s.report)
print("%d failed" % len(fails))
sys.exit(1 if fails else 0)
