#!/usr/bin/env python3
"""A cumulus-like cloud as a VDB that veil and Blender read alike (issue 24: Cycles on a cloud).

    /usr/bin/python3 bench/peers_cycles/cloud.py OUT.vdb

A float grid `density` of 112 x 64 x 56 voxels of 5 cm (5.6 x 3.2 x 2.8 m), made deterministically
(numpy's seeded generator) as data/scenes/cloud.json's medium is: a flat base and three towers of
Gaussian puffs, each puff amplitude a exp(-r^2 / (2 s^2)) cut at 3 s, summed and clamped to 1.
Voxels within 3 of the box's faces stay 0 (no density at the box's faces: Blender and veil agree on
the box then, docs/peers.md). Written with pyopenvdb (Debian python3-openvdb), background 0,
values below 1e-4 pruned to the background."""
import sys

import numpy as np
import pyopenvdb as vdb

DIMS = (112, 64, 56)
VOXEL = 0.05
# (count, seed, box lo, box hi (m, in the cloud's frame: x right, y up, z towards the camera),
#  radius range, amplitude range) -- the towers of data/scenes/cloud.json, scaled into the box
GROUPS = [(260, 11, (-2.2, 0.0, -1.0), (2.2, 0.5, 1.0), (0.15, 0.4), (0.3, 0.9)),
          (160, 12, (-1.6, 0.4, -0.7), (-0.2, 1.4, 0.7), (0.15, 0.45), (0.3, 1.0)),
          (130, 13, (0.0, 0.4, -0.6), (1.3, 1.9, 0.6), (0.15, 0.45), (0.3, 1.0)),
          (60, 14, (1.3, 0.3, -0.5), (2.1, 1.0, 0.5), (0.12, 0.35), (0.3, 0.9))]
ORIGIN = (-2.8, -0.45, -1.4)  # world position of voxel (0, 0, 0)'s centre


def density():
    idx = [np.arange(n) * VOXEL + o for n, o in zip(DIMS, ORIGIN)]
    X, Y, Z = np.meshgrid(*idx, indexing="ij")
    rho = np.zeros(DIMS, dtype=np.float64)
    for count, seed, lo, hi, rad, amp in GROUPS:
        g = np.random.default_rng(seed)
        c = g.uniform(lo, hi, size=(count, 3))
        s = g.uniform(*rad, size=count) / 2.0  # radius ~ 2 sigma
        a = g.uniform(*amp, size=count)
        for (cx, cy, cz), si, ai in zip(c, s, a):
            box = [slice(max(0, int((cc - 3 * si - o) / VOXEL)), min(n, int((cc + 3 * si - o) / VOXEL) + 2))
                   for cc, o, n in zip((cx, cy, cz), ORIGIN, DIMS)]
            r2 = (X[tuple(box)] - cx) ** 2 + (Y[tuple(box)] - cy) ** 2 + (Z[tuple(box)] - cz) ** 2
            rho[tuple(box)] += ai * np.exp(-r2 / (2 * si * si)) * (r2 < 9 * si * si)
    rho = np.minimum(rho, 1.0)
    rho[:3], rho[-3:], rho[:, :3], rho[:, -3:], rho[:, :, :3], rho[:, :, -3:] = 0, 0, 0, 0, 0, 0
    return rho.astype(np.float32)


def main():
    out = sys.argv[1]
    rho = density()
    grid = vdb.FloatGrid(0.0)
    grid.copyFromArray(rho, tolerance=1e-4)
    grid.name = "density"
    grid.gridClass = vdb.GridClass.FOG_VOLUME
    grid.transform = vdb.createLinearTransform(
        [[VOXEL, 0, 0, 0], [0, VOXEL, 0, 0], [0, 0, VOXEL, 0], [ORIGIN[0], ORIGIN[1], ORIGIN[2], 1]])
    vdb.write(out, grids=[grid])
    print("cloud.py: %s: %d active voxels, max %.3f, mean of the nonzero %.3f" % (
        out, grid.activeVoxelCount(), rho.max(), rho[rho > 0].mean()))


if __name__ == "__main__":
    main()
