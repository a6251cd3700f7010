"""The add-on's overhead measure (not a test): the shared smoke (../shared/data/smoke.vdb) as a Blender
scene equal to bench/regress.py's "smoke dense" scene (camera, sun, point light, medium), rendered
with F12 into an EXR, or exported for `veil render`. measure_overhead.sh runs it.

    blender -b --factory-startup --python bench/blender/smoke_overhead.py -- SMOKE.vdb OUTDIR render|export WxH
"""
import math
import os
import sys

import bpy
from mathutils import Vector

# the tests' helpers: the add-on enabled from the repository (tests/blender/common.py)
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))),
                                "tests", "blender"))
import common  # noqa: E402

vdb, out, mode, size = common.args()[:4]
width, height = (int(v) for v in size.split("x"))
os.makedirs(out, exist_ok=True)
sc = bpy.context.scene
for ob in list(sc.objects):  # the factory cube, camera and light
    bpy.data.objects.remove(ob, do_unlink=True)
sc.world = None  # black background
vol = bpy.data.volumes.new("smoke")
vol.filepath = vdb
sc.collection.objects.link(bpy.data.objects.new("smoke", vol))
cd = bpy.data.cameras.new("cam")
cd.sensor_fit, cd.sensor_height = 'VERTICAL', 24.0
cd.lens = 12.0 / math.tan(math.radians(45.0) / 2)  # a 45 deg vertical field of view
cd.clip_start, cd.clip_end = 0.1, 1000.0
cam = bpy.data.objects.new("cam", cd)
cam.location = (26.0, 45.0, 150.0)
cam.rotation_euler = (Vector((26.0, 52.0, 26.0)) - cam.location).to_track_quat('-Z', 'Y').to_euler()
sc.collection.objects.link(cam)
sc.camera = cam
sun = bpy.data.lights.new("sun", 'SUN')
sun.energy, sun.color, sun.angle = 2.6, (1.0, 2.5 / 2.6, 2.3 / 2.6), 0.0
so = bpy.data.objects.new("sun", sun)
so.rotation_euler = Vector((0.45, -0.7, -0.55)).to_track_quat('-Z', 'Y').to_euler()
sc.collection.objects.link(so)
pt = bpy.data.lights.new("point", 'POINT')
pt.energy, pt.color, pt.shadow_soft_size = 4 * math.pi * 900.0, (1.0, 500 / 900, 200 / 900), 0.0
po = bpy.data.objects.new("point", pt)
po.location = (26.0, 30.0, 26.0)
sc.collection.objects.link(po)
sc.render.engine = "VEIL"
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = width, height, 100
vs = sc.veil
vs.sigma_s, vs.sigma_a, vs.phase_g, vs.representation, vs.quality = (0.093,) * 3, (0.007,) * 3, 0.3, 'DENSE', 'DEFAULT'
if mode == "export":
    bpy.ops.veil.export_scene(filepath=os.path.join(out, "smoke.json"), write_script=False)
else:
    im = sc.render.image_settings
    im.file_format, im.color_depth, im.exr_codec = 'OPEN_EXR', '32', 'ZIP'
    sc.render.filepath = os.path.join(out, "blender.exr")
    bpy.ops.render.render(write_still=True)
common.finish()
