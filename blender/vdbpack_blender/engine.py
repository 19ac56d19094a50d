# SPDX-License-Identifier: Apache-2.0
"""The packing job, apart from Blender's data: finding the vdbpack module,
sizing the in-memory container for the job, and running loading, packing
and checking in a background thread with progress and cancellation.
Nothing here touches bpy, so the job may run outside Blender's main
thread; the operators copy the mesh out before and build objects after."""
import os
import sys
import threading
import time

import numpy as np

_MODULE = None


class SetupError(Exception):
    """The vdbpack module or its library cannot be loaded."""


def load_vdbpack(module_dir="", library=""):
    """The vdbpack Python module: as Python finds it (PYTHONPATH), else from
    module_dir (a folder holding vdbpack/, as build/python or
    PREFIX/lib/python3/dist-packages), with library as $VDBPACK_LIBRARY
    when given. SetupError with one line saying what to set."""
    global _MODULE
    if _MODULE is not None:
        return _MODULE
    if library:
        os.environ["VDBPACK_LIBRARY"] = library
    if module_dir and module_dir not in sys.path:
        sys.path.insert(0, module_dir)
    try:
        import vdbpack
    except ImportError as e:
        if module_dir and sys.path[0] == module_dir:
            sys.path.pop(0)
        raise SetupError("the vdbpack Python module cannot be loaded (%s): set its folder (e.g. "
                         "build/python) in the add-on's preferences, or start Blender with "
                         "PYTHONPATH naming it" % str(e).splitlines()[0]) from None
    _MODULE = vdbpack
    return vdbpack


# -- sizing the container ----------------------------------------------------


def container_sizing(vp, method, kw):
    """The level-set parameters (particle_radius, particle_count,
    space_per_particle, narrow_band) that vdbpack.pack() would give a mesh
    file for this job, as keywords for Container.from_mesh: the module's
    vdbpack.container_params, so that a mesh handed over in memory gives
    the particles its file would (tests/python/test_container_params.py)."""
    return vp.container_params(method, **kw)


# -- the unit shape -------------------------------------------------------


def unit_shape(vp, packing):
    """The packing's unit particle (circumradius 1, centroid at the origin:
    what pscale and orient place) as (vertices, faces), the library's own
    (Packing.shape_mesh: vp_shape_mesh, no file); None for spheres."""
    if packing.shape == "sphere":
        return None
    return packing.shape_mesh()


# -- the job -----------------------------------------------------------------


class Job:
    """Loads the container from arrays, packs, checks and gets the unit
    shape, in a thread (start) or in the caller's (run). Progress is read
    from .fraction and .stage; cancel() makes the library stop at its next
    progress report (CancelledError, nothing kept). Afterwards .packing,
    .container_info, .check, .shape_mesh, .seconds, or .error (a one-line
    message) and .cancelled."""

    def __init__(self, vp, vertices, triangles, name, method, options, shape="sphere",
                 shape_mesh=None, voxel_size=0.0, check=True, cancel_at=None, cancel_stage=""):
        self.vp = vp
        self.vertices = vertices
        self.triangles = triangles
        self.name = name
        self.method = method
        self.options = dict(options)
        self.shape = shape
        self.shape_mesh = shape_mesh   # (vertices, triangles, name) of a mesh particle
        self.voxel_size = voxel_size
        self.do_check = check
        self.cancel_at = cancel_at     # cancel once progress reaches this (tests, scripts)
        self.cancel_stage = cancel_stage  # ... in this stage ("rsa", "voxelizing"; "": any)
        self.fraction = 0.0
        self.stage = "starting"
        self.done = False
        self.cancelled = False
        self.error = None
        self.packing = None
        self.container_info = None
        self.check = None
        self.unit_shape = None
        self.seconds = 0.0
        self._stop = False
        self._thread = None

    def cancel(self):
        self._stop = True

    def _progress(self, fraction, stage):
        self.fraction, self.stage = float(fraction), stage
        if self.cancel_at is not None and fraction >= self.cancel_at and \
                self.cancel_stage in ("", stage):
            self._stop = True
        return not self._stop

    def start(self):
        self._thread = threading.Thread(target=self.run, name="vdbpack-blender", daemon=True)
        self._thread.start()

    def join(self, timeout=None):
        if self._thread is not None:
            self._thread.join(timeout)

    def run(self):
        vp = self.vp
        t0 = time.perf_counter()
        try:
            threads = self.options.get("threads")
            opts = dict(self.options)
            if self.shape_mesh is not None:
                v, t, n = self.shape_mesh
                self.stage = "shape"
                opts["shape"] = vp.MeshShape.from_mesh(v, t, name=n)
            else:
                opts["shape"] = self.shape
            sizing = container_sizing(vp, self.method, opts)
            load = dict(sizing, name=self.name, threads=threads, progress=self._progress)
            if self.voxel_size > 0:
                load["voxel_size"] = self.voxel_size
            self.stage = "container"
            container = vp.Container.from_mesh(self.vertices, self.triangles, **load)
            self.container_info = container.info
            packing = vp.pack(container, self.method, progress=self._progress, **opts)
            if self.do_check:
                self.stage = "check"
                self.check = packing.check(container, threads=threads, progress=self._progress)
            self.unit_shape = unit_shape(vp, packing)
            self.packing = packing
        except vp.CancelledError:
            self.cancelled = True
            self.error = "cancelled"
        except (vp.Error, ValueError, TypeError, MemoryError) as e:
            self.error = str(e) or type(e).__name__
        except Exception as e:  # a bug of the add-on: one line here, the traceback in the console
            import traceback
            traceback.print_exc()
            self.error = "internal error (%s: %s); the console has the details" % (
                type(e).__name__, e)
        finally:
            self.seconds = time.perf_counter() - t0
            self.done = True
