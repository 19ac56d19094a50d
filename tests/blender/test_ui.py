# SPDX-License-Identifier: Apache-2.0
"""The Fill operator as the panel's button runs it: modal, in a Blender
with its user interface (under a virtual X server: tests/blender/run_ui.sh,
ctest blender_ui), driven by Blender's own event loop and timers.

    xvfb-run -a blender --factory-startup --enable-event-simulate --python test_ui.py

Run 1 fills the startup file's cube through bpy.ops.vdbpack.fill(
'INVOKE_DEFAULT') in the 3D view's context: the operator must return
RUNNING_MODAL at once, the status bar must show the stage and percentage
while the job runs (WorkSpace.status_text_set is watched), and the result
must be the particles vdbpack.pack gives for the same mesh and settings.
Run 2 starts a longer job and presses Esc (Window.event_simulate): the
operator must end CANCELLED, with no object, mesh or node group made and
run 1's result unchanged.

Blender quits from a timer, which leaves its exit status 0 whatever
happened, so the outcome goes to the file named by $VP_UI_RESULT ("ok"
or the failures), which run_ui.sh reads."""
import os
import sys
import tempfile
import time
import traceback

import addon_utils
import bpy
import numpy as np

SRC = os.environ["VP_SRC"]
sys.path.insert(0, os.path.join(SRC, "blender"))
import vdbpack  # noqa: E402  (PYTHONPATH: the build's module)

RESULT = os.environ.get("VP_UI_RESULT") or os.path.join(tempfile.gettempdir(), "vp_ui_result")
IMAGES = os.environ.get("VP_BLENDER_IMAGES", "")
# in run_ui.sh's temporary home, which it removes (quit.blend goes here too)
TMP = tempfile.mkdtemp(prefix="vp-blender-ui-", dir=os.environ.get("VP_UI_TMP"))
LIMIT = 240.0  # seconds for the whole test
FAILS = []
CHECKS = [0]
STATUS = []  # (time, text) of every status_text_set call
T0 = time.perf_counter()


def check(cond, what):
    CHECKS[0] += 1
    if not cond:
        FAILS.append(what)
        print("FAIL:", what, flush=True)
    return cond


def finish():
    text = "ok %d checks" % CHECKS[0] if not FAILS and CHECKS[0] else \
        "failed %d of %d checks: %s" % (len(FAILS), CHECKS[0], "; ".join(FAILS))
    print("UI test: %s (%.1f s)" % (text, time.perf_counter() - T0), flush=True)
    with open(RESULT, "w") as f:
        f.write(text + "\n")
    bpy.ops.wm.quit_blender()


# the status bar's text, as the operator sets it (a Python method of
# bpy.types.WorkSpace over status_text_set_internal)
_status_text_set = bpy.types.WorkSpace.status_text_set


def _watch_status(self, text):
    STATUS.append((time.perf_counter(), text))
    return _status_text_set(self, text)


bpy.types.WorkSpace.status_text_set = _watch_status


def view3d():
    """The window, and the 3D view's area and main region, for a context
    override: what pressing the panel's button would give the operator."""
    win = bpy.context.window_manager.windows[0]
    area = [a for a in win.screen.areas if a.type == 'VIEW_3D'][0]
    region = [r for r in area.regions if r.type == 'WINDOW'][0]
    return win, area, region


def results(source):
    return [o for o in bpy.data.objects if o.get("vdbpack_source") == source]


def positions(obj):
    co = np.empty(3 * len(obj.data.vertices), np.float32)
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def world_obj(obj, path):
    """obj's world-space mesh as an OBJ, for vdbpack.pack (the cube's
    corners are +-1: exact in float32)."""
    me = obj.evaluated_get(bpy.context.evaluated_depsgraph_get()).to_mesh()
    me.calc_loop_triangles()
    M = np.array(obj.matrix_world, np.float64)
    with open(path, "w") as f:
        for v in me.vertices:
            w = M[:3, :3] @ np.array(v.co, np.float64) + M[:3, 3]
            f.write("v %r %r %r\n" % tuple(float(x) for x in w))
        for t in me.loop_triangles:
            f.write("f %d %d %d\n" % tuple(i + 1 for i in t.vertices))
    return path


def invoke():
    win, area, region = view3d()
    cube = bpy.data.objects["Cube"]
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region,
                                   active_object=cube, object=cube):
        return bpy.ops.vdbpack.fill('INVOKE_DEFAULT')


class Test:
    """The steps, one per timer call; each returns the seconds to the next
    call, or None when the test is over."""

    def __init__(self):
        self.step = self.settle
        self.counts = None
        self.ticks = []

    def __call__(self):
        try:
            if time.perf_counter() - T0 > LIMIT:
                check(False, "the test took longer than %.0f s (in step %s)"
                      % (LIMIT, self.step.__name__))
                finish()
                return None
            nxt = self.step()
            if nxt is None:
                finish()
            return nxt
        except Exception:
            traceback.print_exc()
            check(False, "exception in %s" % self.step.__name__)
            finish()
            return None

    def settle(self):
        """Waits for the interface to be idle: right after start-up Blender
        redraws for some seconds, and with Mesa's software OpenGL on a busy
        machine each redraw takes up to a second, during which no timer
        (and no modal operator) runs. Idle: five timer calls in a row
        0.1 s apart (at most 60 s)."""
        if not self.ticks:
            # what the run will show, drawn once before it (Mesa compiles
            # its shaders on first use, a second or more here): the
            # sidebar, a status-bar text
            win, area, _region = view3d()
            area.spaces[0].show_region_ui = True
            win.workspace.status_text_set("vdbpack: warming up 0%")
            # the add-on now, so that its sidebar tab is drawn before the
            # click that shows it (click_tab)
            addon_utils.enable("vdbpack_blender", default_set=True)
        elif len(self.ticks) == 10:
            view3d()[0].workspace.status_text_set(None)
        self.ticks.append(time.perf_counter())
        gaps = np.diff(self.ticks[-6:])
        if len(self.ticks) < 15 or (gaps.max() > 0.2 and self.ticks[-1] - T0 < 60):
            return 0.1
        print("UI: idle after %.1f s" % (self.ticks[-1] - T0), flush=True)
        self.step = self.click_tab
        return self.click_tab()

    def click_tab(self):
        """Shows the vdbpack tab of the sidebar, for the screenshots (the
        docs' pictures of the panel; nothing checks it): Blender 3.4 has no
        Python way to pick a sidebar tab (4.1's
        Region.active_panel_category), so a click where the factory
        settings draw it, the fourth tab below Item, Tool and View, 168
        pixels below the region's top."""
        win, area, _region = view3d()
        ui = next(r for r in area.regions if r.type == 'UI')
        x, y = ui.x + ui.width - 9, ui.y + ui.height - 168
        win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
        win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)
        self.step = self.start
        return 1.0

    def start(self):
        check(not bpy.app.background, "Blender runs in the background: no UI to test")
        win, area, region = view3d()
        print("UI: window %dx%d, GPU %s" % (win.width, win.height, _gpu()), flush=True)
        cube = bpy.data.objects.get("Cube")
        if not check(cube is not None and hasattr(bpy.context.scene, "vdbpack"),
                     "no startup cube or the add-on did not register"):
            return None
        bpy.context.view_layer.objects.active = cube
        s = bpy.context.scene.vdbpack
        s.method, s.shape, s.seed, s.fit = "rsa", "cube", 3, "inside"
        # one packing thread: the other core draws the interface (with
        # software OpenGL every redraw is CPU work; docs/blender.md, limits)
        s.threads = 1
        s.passes.clear()
        for count, radius in ((200, 0.12), (160000, 0.0095)):
            p = s.passes.add()
            p.count, p.radius = count, radius
        self.expected = vdbpack.pack(world_obj(cube, os.path.join(TMP, "cube.obj")),
                                     method="rsa", shape="cube", seed=3,
                                     passes=[{"count": 200, "radius": 0.12},
                                             {"count": 160000, "radius": 0.0095}])
        STATUS.clear()
        self.t_invoke = time.perf_counter()
        r = invoke()
        check(r == {'RUNNING_MODAL'}, "run 1: invoke returned %s, not RUNNING_MODAL" % r)
        check(not results("Cube"), "run 1: a result exists before the job ran")
        self.step = self.wait_run1
        return 0.05

    def wait_run1(self):
        res = results("Cube")
        if not res:
            if len(STATUS) == 3 and IMAGES:  # the status bar mid-run, for the eye
                _screenshot(os.path.join(IMAGES, "blender-ui-running.png"))
            return 0.1
        t = time.perf_counter() - self.t_invoke
        progress = [x for _, x in STATUS if x and "Esc to cancel" in x]
        check(len(progress) >= 2, "run 1: %d progress texts in the status bar (%s)"
              % (len(progress), progress[:3]))
        check(STATUS and STATUS[-1][1] is None, "run 1: the status bar was not cleared")
        stages = {x.split()[1] for x in progress}
        check(bool(stages & {"rsa", "voxelizing", "container", "check"}),
              "run 1: the status bar named no stage: %s" % sorted(stages))
        s = bpy.context.scene.vdbpack
        check(s.report.startswith("%d particles" % len(self.expected)) and s.report_ok,
              "run 1: report %r" % s.report)
        check(np.array_equal(positions(res[0]), self.expected.positions.astype(np.float32)),
              "run 1: the particles are not vdbpack.pack's")
        print("UI run 1: %d particles in %.1f s, %d status texts, e.g. %r"
              % (len(res[0].data.vertices), t, len(progress), progress[len(progress) // 2]),
              flush=True)
        self.first = positions(res[0]).copy()
        self.step = self.shot_result
        return 1.0

    def shot_result(self):
        """The panel with run 1's report and the result, for the docs."""
        if IMAGES:
            _screenshot(os.path.join(IMAGES, "blender-ui-result.png"))
        # run 2: a job of many seconds, cancelled with Esc
        s = bpy.context.scene.vdbpack
        s.passes.clear()
        p = s.passes.add()
        p.maximal, p.radius = True, 0.008  # cubes until none fits: minutes
        s.check = False
        s.voxel_size = 0.05  # a short voxelization, a long rsa stage to press Esc in
        self.counts = (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.node_groups))
        STATUS.clear()
        self.t_invoke = time.perf_counter()
        r = invoke()
        check(r == {'RUNNING_MODAL'}, "run 2: invoke returned %s" % r)
        self.step = self.press_esc
        return 0.1

    def press_esc(self):
        progress = [x for _, x in STATUS if x and "Esc to cancel" in x]
        if not any(" rsa " in x for x in progress):
            s = bpy.context.scene.vdbpack
            if s.report and not s.report.startswith("%d particles" % len(self.expected)):
                check(False, "run 2 ended before Esc could be pressed: %r" % s.report)
                return None
            return 0.1
        win, _area, _region = view3d()
        self.pressed = progress[-1]
        self.t_esc = time.perf_counter()
        win.event_simulate(type='ESC', value='PRESS')
        win.event_simulate(type='ESC', value='RELEASE')
        self.step = self.wait_cancel
        return 0.1

    def wait_cancel(self):
        s = bpy.context.scene.vdbpack
        if not s.report.startswith("cancelled"):
            return 0.1
        t = time.perf_counter() - self.t_esc
        check(t < 20, "run 2: cancelling took %.1f s" % t)
        check(any(x == "vdbpack: cancelling..." for _, x in STATUS),
              "run 2: Esc did not reach the operator (no 'cancelling...')")
        check(STATUS and STATUS[-1][1] is None, "run 2: the status bar was not cleared")
        now = (len(bpy.data.objects), len(bpy.data.meshes), len(bpy.data.node_groups))
        check(now == self.counts, "run 2: objects, meshes, node groups %s before, %s after"
              % (self.counts, now))
        res = results("Cube")
        check(len(res) == 1 and np.array_equal(positions(res[0]), self.first),
              "run 2: run 1's result is gone or changed")
        print("UI run 2: Esc at %r, %s; ended %.2f s later" % (self.pressed, s.report, t),
              flush=True)
        return None


def _gpu():
    try:
        import gpu
        return "%s, OpenGL %s" % (gpu.platform.renderer_get(), gpu.platform.version_get())
    except Exception as e:  # noqa: BLE001 -- for the log only
        return "unknown (%s)" % e


def _screenshot(path):
    win, area, region = view3d()
    try:
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
            bpy.ops.screen.screenshot(filepath=path)
        print("UI: screenshot %s" % path, flush=True)
    except Exception as e:  # noqa: BLE001 -- a picture for the eye, not a check
        print("UI: no screenshot (%s)" % e, flush=True)


bpy.context.preferences.filepaths.temporary_directory = TMP  # quit.blend goes here
bpy.context.preferences.view.show_splash = False  # (shown after this script: not at all)
bpy.app.timers.register(Test(), first_interval=0.5)
