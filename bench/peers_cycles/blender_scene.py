"""Inside Blender 3.4 (bpy): a veil scene with one vdb source as a Cycles scene, rendered once.

    blender -b --factory-startup --python bench/peers_cycles/blender_scene.py -- SCENE.json SPP SEED OUT.exr [sky]

With `sky` the world is the scene's background colour (strength 1: radiance W m^-2 sr^-1, constant in
every direction) and lights the medium, as `veil reference --background lights` has it; a scene's light
of type "environment" becomes the world (world_environment); otherwise black.

The lights, camera, black world and unbiased settings are bench/fog_truth/blender_setup.py's (its
calibrations: Power = 4 pi I, Strength = E, vertical sensor fit, 0.01 px filter). The medium: the vdb
imported with its own index-to-world transform, turned into veil's axes (blender (x, y, z) = veil
(x, -z, y): +90 degrees about x) and moved back half a voxel (Blender's voxel centres are at i + 1/2), its `density` grid (times density_scale) read at full precision, and
Volume Scatter (sigma_s rho, HG g) plus Volume Absorption (sigma_a rho): grey media only. Cycles marches
heterogeneous volumes in steps of one voxel (step rate 1, the scene's and the volume's) with at most
4096 steps a ray."""
import json
import math
import os
import sys

import bpy
from mathutils import Vector

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "fog_truth"))
import blender_setup as bs  # noqa: E402


def attr_grid(src):
    return src.get("grid", "density")


def s_lights(scene_path):
    with open(scene_path) as f:
        return json.load(f).get("lights", [])


def world_environment(sc, env, base):
    """veil's environment light as the world: a constant colour, or its lat-long map as an Environment
    Texture read with Closest interpolation (veil's map is piecewise constant, scene/environment.h, whose
    axes are Blender's equirectangular ones once veil's are turned into Blender's), strength = intensity;
    radiance W m^-2 sr^-1 in both."""
    assert not env.get("rotation_deg"), "rotation: not mapped here"
    nt = sc.world.node_tree
    bg = nt.nodes["Background"]
    k = env.get("intensity", 1.0)
    tint = env.get("color", [1.0, 1.0, 1.0])
    bg.inputs["Strength"].default_value = k
    if "file" not in env:
        bg.inputs["Color"].default_value = tuple(tint) + (1.0,)
        return
    assert tint == [1.0, 1.0, 1.0], "a tinted map: not mapped here"
    tex = nt.nodes.new("ShaderNodeTexEnvironment")
    path = env["file"] if os.path.isabs(env["file"]) else os.path.join(base, env["file"])
    tex.image = bpy.data.images.load(path)
    tex.image.colorspace_settings.name = "Non-Color"  # linear radiance as it is
    tex.interpolation = "Closest"
    tex.projection = "EQUIRECTANGULAR"
    nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
    sc.world.cycles.sampling_method = "MANUAL"
    sc.world.cycles.sample_map_resolution = max(tex.image.size[0], 64)


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    scene_path, spp, seed, out = argv[:4]
    sky = len(argv) > 4 and argv[4] == "sky"
    env = [x for x in s_lights(scene_path) if x["type"] == "environment"]
    with open(scene_path) as f:
        s = json.load(f)
    med = s["medium"]
    (src,) = [x for x in med["sources"] if x["type"] == "vdb"]
    ss, sa = med["sigma_s"][0], med["sigma_a"][0]
    assert med["sigma_s"] == [ss] * 3 and med["sigma_a"] == [sa] * 3, "grey media only"
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    bs.black_world(sc)
    if sky:
        bg = sc.world.node_tree.nodes["Background"]
        bg.inputs["Color"].default_value = tuple(s.get("background", {}).get("color", [0.0, 0.0, 0.0])) + (1.0,)
        bg.inputs["Strength"].default_value = 1.0
    if env:
        world_environment(sc, env[0], os.path.dirname(scene_path))
    bs.add_lights(sc, [x for x in s["lights"] if x["type"] != "environment"])
    bs.add_camera(sc, s["camera"])
    path = src["file"] if os.path.isabs(src["file"]) else os.path.join(os.path.dirname(scene_path), src["file"])
    bpy.ops.object.volume_import(filepath=path, align="WORLD", location=(0.0, 0.0, 0.0))
    ob = bpy.context.active_object
    ob.rotation_euler = (math.pi / 2, 0.0, 0.0)
    # Blender's voxel i spans [i, i + 1] of index space (its centre at i + 1/2); veil's and OpenVDB's
    # centre is at i: moved back half a voxel through the grid's transform (measured on the smoke at
    # 256 spp: 4x4-block error 12.2 % -> 9.3 %, its noise; mean bias +0.76 % -> 0.0 %)
    ob.data.grids.load()
    grid = ob.data.grids[attr_grid(src)]
    bpy.context.view_layer.update()
    half = grid.matrix_object.to_3x3() @ Vector((-0.5, -0.5, -0.5))
    ob.location = ob.matrix_world.to_3x3() @ half
    ob.data.render.precision = "FULL"
    ob.data.render.space = "OBJECT"
    ob.data.render.step_size = 0.0  # the grid's own voxel
    m, nt, scat, absb = bs.grey_medium("medium", med["phase"]["g"])
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = attr_grid(src)
    scale = src.get("density_scale", 1.0)
    for k, node in ((ss * scale, scat), (sa * scale, absb)):
        mul = nt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = k
        nt.links.new(attr.outputs["Fac"], mul.inputs[0])
        nt.links.new(mul.outputs[0], node.inputs["Density"])
    ob.data.materials.append(m)
    bs.unbiased(sc, s["camera"]["width"], s["camera"]["height"], int(spp), int(seed), 256, out)
    sc.cycles.volume_step_rate = 1.0
    sc.cycles.volume_max_steps = 4096
    bpy.ops.render.render(write_still=True)


main()
