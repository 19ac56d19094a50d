#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Reference for bench_lattice_sphere.sh, independent of vdbpack: FCC spheres
of radius r on a lattice with a random offset and random rotation, count the
centres with |x| <= R - r (sphere wholly inside sphere:R), best of N trials.
Prints JSON {count, fraction, seconds, trials, mean_fraction}."""
import json
import math
import sys
import time

import numpy as np

R, r, N = float(sys.argv[1]), float(sys.argv[2]), int(sys.argv[3])
seed = int(sys.argv[4]) if len(sys.argv) > 4 else 12345
t0 = time.time()
rng = np.random.default_rng(seed)
a = 2 * math.sqrt(2) * r  # cubic FCC constant, nearest neighbours at 2r
basis = np.array([[0, 0, 0], [0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) * a
prim = np.array([[0.5, 0.5, 0], [0.5, 0, 0.5], [0, 0.5, 0.5]]) * a  # primitive vectors
lim = R - r
reach = lim + np.linalg.norm(prim.sum(axis=0)) + a
m = int(math.ceil(reach / a)) + 1
g = np.arange(-m, m + 1) * a
cells = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
pts = (cells[:, None, :] + basis[None, :, :]).reshape(-1, 3)
pts = pts[np.linalg.norm(pts, axis=1) <= reach].astype(np.float64)
lim2 = lim * lim * (1 + 1e-12)


def rand_rot():
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


best, tot = 0, 0
for _ in range(N):
    off = rng.random(3) @ prim
    q = (pts + off) @ rand_rot().T
    c = int(np.count_nonzero(np.einsum("ij,ij->i", q, q) <= lim2))
    tot += c
    best = max(best, c)
frac = best * (r / R) ** 3
print(json.dumps({"count": best, "fraction": frac, "mean_fraction": tot / N * (r / R) ** 3,
                  "trials": N, "seconds": time.time() - t0}))
