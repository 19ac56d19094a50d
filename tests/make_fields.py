# SPDX-License-Identifier: Apache-2.0
"""Writes the test fields of tests/sh_fields.sh with OpenVDB's own Python
module (pyopenvdb), never by hand: float grids over the box [-0.5, 0.5]^3
(grown by a voxel), a level-set sphere for masks, and bad inputs.

    make_fields.py DIR
"""
import os
import sys

import numpy as np
import pyopenvdb as vdb

out = sys.argv[1]
H = 0.05          # voxel of the fields
N = 11            # voxel centres at -N*H .. N*H: [-0.575, 0.575] with the voxels


def grid(values, name, lo=-N, background=0.0, h=H):
    g = vdb.FloatGrid(background)
    g.transform = vdb.createLinearTransform(voxelSize=h)
    g.copyFromArray(np.ascontiguousarray(values, dtype=np.float32), ijk=(lo, lo, lo),
                    tolerance=0.0)
    g.name = name
    return g


def along_x(fn, n=N, h=H):
    """A (2n+1)^3 array holding fn(x) at the voxel centres, x = i * h."""
    x = np.arange(-n, n + 1) * h
    a = np.empty((2 * n + 1,) * 3, dtype=np.float32)
    a[:] = fn(x)[:, None, None]   # copyFromArray: array index [i, j, k] = (x, y, z)
    return a


def write(name, grids):
    vdb.write(os.path.join(out, name), grids=grids)


# radius x 1 at x = -0.5 down to x 0.5 at x = 0.5 (linear, so trilinear
# sampling is exact), and the same as absolute radii of 0.03 .. 0.015
write("halve.vdb", [grid(along_x(lambda x: 1.0 - 0.5 * (x + 0.5)), "radius", background=-1.0)])
write("halve_abs.vdb", [grid(along_x(lambda x: 0.03 * (1.0 - 0.5 * (x + 0.5))), "radius",
                             background=-1.0)])
# number density 1 at x = -0.5 rising to 3 at x = 0.5
write("density.vdb", [grid(along_x(lambda x: 1.0 + 2.0 * (x + 0.5)), "density", background=-1.0)])
# two grids in one file: the second picked by name
write("two.vdb", [grid(along_x(lambda x: 0 * x + 2.0), "first"),
                  grid(along_x(lambda x: 1.0 - 0.5 * (x + 0.5)), "second", background=-1.0)])
# a level-set sphere of radius 0.25 at the origin, bands of 5 voxels
ls = vdb.createLevelSetSphere(radius=0.25, center=(0, 0, 0), voxelSize=0.01, halfWidth=5.0)
ls.name = "ball"
write("ball.vdb", [ls])

# bad inputs
nan = grid(along_x(lambda x: 1.0 + 0 * x), "radius")
nan.getAccessor().setValueOn((-8, -7, -6), float("nan"))  # (copyFromArray drops NaN)
write("nan.vdb", [nan])
write("negative.vdb", [grid(along_x(lambda x: x), "radius", background=5.0)])
write("zero.vdb", [grid(along_x(lambda x: 0 * x), "radius", background=5.0)])
write("small.vdb", [grid(along_x(lambda x: 1.0 + 0 * x, n=5), "radius", lo=-5)])  # [-0.275, 0.275]
write("neg_density.vdb", [grid(along_x(lambda x: x), "density", background=5.0)])
v = vdb.Vec3SGrid()
v.transform = vdb.createLinearTransform(voxelSize=H)
v.copyFromArray(np.ones((4, 4, 4, 3), dtype=np.float32))
v.name = "velocity"
write("vec3.vdb", [v])
with open(os.path.join(out, "corrupt.vdb"), "wb") as f:
    f.write(open(os.path.join(out, "halve.vdb"), "rb").read()[:200])
