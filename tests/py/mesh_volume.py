#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Enclosed volume of an OBJ mesh (divergence theorem over fan-triangulated
faces), computed independently of vdbpack.  Prints the absolute volume."""
import sys

import numpy as np


def obj_volume(path):
    verts, tris = [], []
    with open(path, "r", errors="replace") as f:
        for line in f:
            if line.startswith("v "):
                verts.append([float(x) for x in line.split()[1:4]])
            elif line.startswith("f "):
                idx = []
                for tok in line.split()[1:]:
                    i = int(tok.split("/")[0])
                    idx.append(i - 1 if i > 0 else len(verts) + i)
                for k in range(1, len(idx) - 1):
                    tris.append((idx[0], idx[k], idx[k + 1]))
    V = np.array(verts, dtype=np.float64)
    T = np.array(tris, dtype=np.int64)
    a, b, c = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    return abs(float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum()) / 6.0)


if __name__ == "__main__":
    print("%.10g" % obj_volume(sys.argv[1]))
