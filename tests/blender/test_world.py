"""The world as veil's environment light (issue 26): exported, and seen alike by Cycles and veil.

A world whose Background's Color comes from an Environment Texture (a 32 x 16 OpenEXR map written
here, every texel a different colour, read with Closest interpolation) at strength 2 exports as
{"type": "environment", "file": the map, "intensity": 2, "up": "z"}; a plain colour as its colour
times strength; a black world as no light. Then the camera's view of the world alone (the Volume moved
behind the camera): Cycles renders it (one sample a pixel is exact here: a camera ray's world lookup
has no noise, and a 0.01 px pixel filter puts the ray at the pixel's centre) and veil renders the
exported scene (T = 1 everywhere: the map along each ray). They must agree pixel for pixel except
where a pixel's centre lies within the filter's 0.01 px of a texel edge: a texel spans about 8 pixels
here, so at most 2 x 0.01 / 8 of a row or column, 0.5 % of the pixels, may take the neighbouring
texel; 1 % is allowed. An axis swapped, a mirrored azimuth, a map upside down or a rotation off by a
quarter turn changes most pixels.

    blender -b --factory-startup --python tests/blender/test_world.py -- WORKDIR
"""
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402

import veil  # noqa: E402
from veil_blender import export  # noqa: E402

work = common.args()[0]
os.makedirs(work, exist_ok=True)
W, H = 32, 16
j, i = np.mgrid[0:H, 0:W]
texels = np.stack([(i + 1) / W, (j + 1) / H, ((5 * i + 3 * j) % 7 + 1) / 7.0], -1).astype(np.float32)
map_path = os.path.join(work, "map.exr")
import OpenImageIO as oiio  # noqa: E402
buf = oiio.ImageBuf(oiio.ImageSpec(W, H, 3, oiio.FLOAT))
buf.set_pixels(oiio.ROI(), texels)
check(buf.write(map_path), "wrote the map %s" % map_path)

vdb_path = os.path.join(work, "sphere.vdb")
common.write_sphere_vdb(vdb_path, n=8)
vol = common.build_scene(vdb_path)
sc = bpy.context.scene
cam = sc.camera
vol.location = cam.location + (cam.location - vol.location).normalized() * 5.0  # behind the camera
cam.data.lens = 10.0  # a wide view: many texels
bpy.data.objects.remove(bpy.data.objects["Light"], do_unlink=True)  # the world alone lights (and no warning)
world = bpy.data.worlds.new("map")
world.use_nodes = True
sc.world = world
nt = world.node_tree
bg = nt.nodes["Background"]
bg.inputs["Strength"].default_value = 2.0

# a colour, then black
bg.inputs["Color"].default_value = (0.2, 0.3, 0.4, 1.0)
data, _ = export.export_scene(bpy.context.evaluated_depsgraph_get())
env = [x for x in data["lights"] if x["type"] == "environment"]
check(len(env) == 1 and env[0].get("up") == "z" and np.allclose(env[0]["color"], [0.4, 0.6, 0.8]) and
      "background" not in data, "a world colour exports as an environment light of colour x strength: %s" % env)
bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
data, _ = export.export_scene(bpy.context.evaluated_depsgraph_get())
check(not [x for x in data["lights"] if x["type"] == "environment"] and data["background"]["color"] == [0, 0, 0],
      "a black world exports as no light and a black background")

tex = nt.nodes.new("ShaderNodeTexEnvironment")
tex.image = bpy.data.images.load(map_path)
tex.image.colorspace_settings.name = "Non-Color"
tex.interpolation = "Closest"
nt.links.new(tex.outputs["Color"], bg.inputs["Color"])
warnings = []
data, warnings = export.export_scene(bpy.context.evaluated_depsgraph_get())
env = [x for x in data["lights"] if x["type"] == "environment"]
check(len(env) == 1 and env[0] == {"type": "environment", "file": map_path, "intensity": 2.0, "up": "z"} and
      not warnings, "the Environment Texture exports as the map: %s (warnings %s)" % (env, warnings))

# Cycles' view of the world
sc.render.engine = "CYCLES"
sc.cycles.samples = 1
sc.cycles.use_denoising = False
sc.cycles.device = "CPU"
sc.cycles.filter_width = 0.01
sc.view_settings.view_transform = "Standard"
sc.render.film_transparent = False
im = sc.render.image_settings
im.file_format, im.color_depth, im.exr_codec = "OPEN_EXR", "32", "ZIP"
out = os.path.join(work, "cycles.exr")
sc.render.filepath = out
bpy.ops.render.render(write_still=True)
cyc = oiio.ImageBuf(out).get_pixels(oiio.FLOAT)[..., :3]
rgba = veil.render(data, aovs=False)["rgba"][..., :3]
check(cyc.shape == rgba.shape, "sizes: Cycles %s, veil %s" % (cyc.shape, rgba.shape))
if cyc.shape == rgba.shape:
    same = np.all(np.abs(cyc - rgba) <= 1e-5 * np.abs(cyc) + 1e-7, axis=-1)
    distinct = len({tuple(p) for p in rgba.reshape(-1, 3).round(5)})
    check(distinct >= 30, "the view sees %d texels (a test needs many)" % distinct)
    check(same.mean() >= 0.99, "veil sees the world as Cycles does in %.2f %% of the pixels (>= 99 %%)"
          % (100 * same.mean()))
common.finish()
