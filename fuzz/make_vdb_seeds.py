# SPDX-License-Identifier: Apache-2.0
"""Writes the seed corpus of fuzz_vdb into the directory given: small .vdb
files of every kind the loaders meet (a level set, half-float storage, an
unnamed grid, a fog volume, a vector grid, two grids of one name, no grids).
A points grid is added by scripts/fuzz.sh with vdbpack itself (pyopenvdb
cannot write points)."""
import os
import sys

import numpy as np
import pyopenvdb as vdb

out = sys.argv[1]
os.makedirs(out, exist_ok=True)


def sphere(name, half=False):
    g = vdb.createLevelSetSphere(radius=0.5, voxelSize=0.25, halfWidth=1.5)
    g.name = name
    g.saveFloatAsHalf = half
    return g


fog = vdb.FloatGrid()
fog.name = "density"
fog.gridClass = vdb.GridClass.FOG_VOLUME
fog.copyFromArray(np.ones((2, 2, 2), dtype="float32"))
vec = vdb.Vec3SGrid()
vec.name = "vel"
vec.copyFromArray(np.ones((2, 2, 2, 3), dtype="float32"))

vdb.write(os.path.join(out, "levelset.vdb"), grids=[sphere("surface")])
vdb.write(os.path.join(out, "half.vdb"), grids=[sphere("surface", half=True)])
vdb.write(os.path.join(out, "unnamed.vdb"), grids=[sphere("")])
vdb.write(os.path.join(out, "mixed.vdb"), grids=[fog, vec, sphere("ls")])
vdb.write(os.path.join(out, "same_name.vdb"), grids=[sphere("a"), sphere("a")])
vdb.write(os.path.join(out, "empty.vdb"), grids=[])
for f in sorted(os.listdir(out)):
    print("seed %-16s %6d bytes" % (f, os.path.getsize(os.path.join(out, f))))
