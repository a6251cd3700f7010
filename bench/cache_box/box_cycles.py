"""Blender Cycles (all orders) of bench/cache_box's homogeneous box: the
independent ruler for `veil reference` at strong forward scattering.

    blender -b --factory-startup --python box_cycles.py -- SCENE.json SAMPLES OUT.exr

SCENE.json is the veil scene run.py writes (one exponential fog box with
falloff 0, one sun, black background). The lights,
camera, world and Cycles' settings are bench/fog_truth/blender_setup.py's
(truth.py's calibration, checked by its calibrate.py); so is the fog
(fog_material: Volume Scatter plus Volume Absorption on a box of its
bounds); 1024 bounces of every kind. Writes a multilayer EXR with
Combined, VolumeDir (order 1) and VolumeInd (orders >= 2).
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "fog_truth"))
import blender_setup  # noqa: E402


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    if len(argv) != 3:
        sys.exit("usage: blender -b --factory-startup --python box_cycles.py -- SCENE.json SAMPLES OUT.exr")
    with open(argv[0]) as f:
        s = json.load(f)
    samples, out = int(argv[1]), argv[2]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    med = s["medium"]
    fog = med["sources"][0]
    case = {"g": med["phase"].get("g", 0.0), "sigma_s": med["sigma_s"], "sigma_a": med["sigma_a"], "fog": fog}
    blender_setup.box("fog", fog["bounds"][0], fog["bounds"][1], blender_setup.fog_material(case))

    blender_setup.add_lights(sc, s["lights"])
    cam = s["camera"]
    blender_setup.add_camera(sc, cam)
    blender_setup.black_world(sc)
    blender_setup.unbiased(sc, cam["width"], cam["height"], samples, 1, 1024, out)
    bpy.ops.render.render(write_still=True)


main()
