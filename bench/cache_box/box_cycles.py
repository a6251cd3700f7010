"""Blender Cycles (all orders) of bench/cache_box's homogeneous box: the
independent ruler for `veil reference` at strong forward scattering.

    blender -b --factory-startup --python box_cycles.py -- SCENE.json SAMPLES OUT.exr

SCENE.json is the veil scene run.py writes (one exponential fog box with
falloff 0, one sun, black background). The lights,
camera, world and Cycles' settings are bench/fog_truth/blender_setup.py's
(truth.py's calibration, checked by its calibrate.py); the medium is
Volume Scatter (density sigma_s, anisotropy g: HG) plus Volume Absorption
(density sigma_a) on a cube of the fog's bounds; 1024 bounces of every
kind. Writes a multilayer EXR with
Combined, VolumeDir (order 1) and VolumeInd (orders >= 2).
"""
import json
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "fog_truth"))
import blender_setup  # noqa: E402
from blender_setup import bl  # noqa: E402


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
    lo, hi = bl(fog["bounds"][0]), bl(fog["bounds"][1])
    mn = [min(lo[i], hi[i]) for i in range(3)]
    mx = [max(lo[i], hi[i]) for i in range(3)]
    bpy.ops.mesh.primitive_cube_add(size=2.0, location=[(mn[i] + mx[i]) / 2 for i in range(3)])
    cube = bpy.context.active_object
    cube.scale = [(mx[i] - mn[i]) / 2 for i in range(3)]
    m = bpy.data.materials.new("fog")
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    o = nt.nodes.new("ShaderNodeOutputMaterial")
    scat = nt.nodes.new("ShaderNodeVolumeScatter")
    absb = nt.nodes.new("ShaderNodeVolumeAbsorption")
    add = nt.nodes.new("ShaderNodeAddShader")
    rho = fog["density"]
    scat.inputs["Color"].default_value = (1, 1, 1, 1)
    scat.inputs["Density"].default_value = med["sigma_s"][0] * rho
    scat.inputs["Anisotropy"].default_value = med["phase"].get("g", 0.0)
    absb.inputs["Color"].default_value = (0, 0, 0, 1)
    absb.inputs["Density"].default_value = med["sigma_a"][0] * rho
    nt.links.new(scat.outputs[0], add.inputs[0])
    nt.links.new(absb.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], o.inputs["Volume"])
    cube.data.materials.append(m)

    blender_setup.add_lights(sc, s["lights"])
    cam = s["camera"]
    blender_setup.add_camera(sc, cam)
    blender_setup.black_world(sc)
    blender_setup.unbiased(sc, cam["width"], cam["height"], samples, 1, 1024, out)
    bpy.ops.render.render(write_still=True)


main()
