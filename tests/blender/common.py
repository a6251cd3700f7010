"""Shared by the Blender tests (run inside `blender -b --factory-startup --python X.py -- ARGS`).

The add-on is enabled from the repository without installing it: the repository's blender/ folder
is put on sys.path and veil_blender.register() is called, as Blender's add-on manager would
(docs/blender.md, "From the repository"). The Python module `veil` comes from PYTHONPATH (python/)
and finds libveil through VEIL_LIBRARY; the driver (run.sh) sets both."""
import math
import os
import sys

import bpy

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "blender"))
import veil_blender  # noqa: E402

veil_blender.register()

FAILURES = []


def args():
    return sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        FAILURES.append(what)


def finish():
    """Exit 1 when a check failed (Blender's own exit status is 0 after a script)."""
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES), flush=True)
        sys.stdout.flush()
        os._exit(1)
    print("all checks passed", flush=True)
    sys.stdout.flush()
    os._exit(0)


def write_sphere_vdb(path, n=32, voxel=0.1):
    """A smooth sphere of n^3 voxels of `voxel` m: density (1 + cos(pi r / R)) / 2 inside radius
    R = 0.45 n voxels of the box's centre, 0 outside (a raised cosine: smooth at the rim), grid
    'density', fog volume, written with pyopenvdb."""
    import numpy as np
    import pyopenvdb as vdb
    c = (n - 1) / 2.0
    i = np.arange(n, dtype=np.float64) - c
    r = np.sqrt(i[:, None, None] ** 2 + i[None, :, None] ** 2 + i[None, None, :] ** 2)
    big_r = 0.45 * n
    rho = np.where(r < big_r, 0.5 * (1.0 + np.cos(np.pi * r / big_r)), 0.0).astype(np.float32)
    g = vdb.FloatGrid(0.0)
    g.copyFromArray(rho)
    g.name = "density"
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.transform = vdb.createLinearTransform(voxel)
    vdb.write(path, grids=[g])


def build_scene(vdb_path, width=64, height=48, volume_name="Smoke"):
    """The factory scene less its cube: its camera (made a vertical sensor fit with a lens shift) and
    1000 W point light, a Volume object reading vdb_path (a 3.2 m sphere at 0.1 m voxels) centred near
    the origin, turned and scaled so that its matrix is not trivial; engine veil at draft quality,
    width x height."""
    sc = bpy.context.scene
    cube = bpy.data.objects.get("Cube")
    if cube is not None:
        bpy.data.objects.remove(cube, do_unlink=True)
    vol = bpy.data.volumes.new(volume_name)
    vol.filepath = vdb_path
    ob = bpy.data.objects.new(volume_name, vol)
    sc.collection.objects.link(ob)
    ob.rotation_euler = (0.0, 0.0, math.radians(30.0))
    ob.scale = (1.0, 1.0, 1.1)
    ob.location = (-1.2, -1.9, -1.7)
    cd = sc.camera.data  # a vertical fit on a landscape image (fitted side != larger side) and a lens shift
    cd.sensor_fit, cd.shift_x, cd.shift_y = 'VERTICAL', 0.04, -0.03
    sc.render.engine = "VEIL"
    sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = width, height, 100
    vs = sc.veil
    vs.quality = 'DRAFT'
    vs.sigma_s = (2.0, 2.2, 2.5)
    vs.sigma_a = (0.05, 0.05, 0.05)
    vs.phase_g = 0.3
    sc.view_layers[0].use_pass_z = True
    return ob
