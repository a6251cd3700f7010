"""The exporter's mapping checked against Blender itself, without rendering (test (4) of issue 25's
Blender part, and the sequence, light and transform rules of docs/blender.md):

- camera: Camera.view_frame(scene=...) gives the frame's corners in camera space, sensor fit and
  lens shift included. Each corner, taken to world space by the camera's matrix, must project
  through the exported veil camera (position, look_at, up; fov_deg along the sensor_fit axis;
  shift in units of the fitted side's extent, as docs/scene-format.md and scene/camera.c define
  them; the model below is written from that text, not from the exporter) onto the same corner
  of veil's image. (test_render.py checks that veil renders the frame so.) Fits AUTO,
  HORIZONTAL, VERTICAL; landscape, portrait and square; shifts 0 and non-zero; a rolled camera.
- VDB sequences: the exported '####' pattern and frame_offset name, for scene frames 10..14, the
  file Blender itself loads there (VolumeGrids.frame_filepath).
- lights: a sun with no rotation shines straight down, a spot turned 90 deg about X along +Y;
  watts -> W/sr by 1/(4 pi); spot size/blend -> cone angles.
- volume transform: the object's world matrix composed with half a voxel (Blender's voxel
  centres), or the world matrix alone with the option off.

    blender -b --factory-startup --python tests/blender/test_mapping.py -- WORKDIR
"""
import math
import os

import sys

import bpy
from mathutils import Euler, Matrix, Vector

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check

from veil_blender import export  # noqa: E402  (common put it on sys.path)

work = common.args()[0]
os.makedirs(work, exist_ok=True)
sc = bpy.context.scene
cam_ob = sc.camera

# --- the camera ---------------------------------------------------------------------------------
# Tolerance: view_frame and the matrices are single precision (2^-24 relative, ~6e-8); the corners
# pass through a few products and a division, each a few ulps: 1e-5 in normalised image units
# (1/100 000 of the frame) is far above that and far below any real error (a wrong shift unit is
# >= 0.03 here, a wrong fov axis >= 0.1).
TOL = 1e-5


def veil_corners(cam):
    """The four frame corners of veil's camera dict as (x, y) at unit depth, from veil's definition:
    fov_deg along the sensor_fit axis ('auto': the larger image side), shift as fractions of the
    fitted side's extent, x right, y up."""
    w, h = cam['width'], cam['height']
    fit = cam.get('sensor_fit', 'vertical')
    if fit == 'auto':
        fit = 'horizontal' if w >= h else 'vertical'
    t = math.tan(math.radians(cam['fov_deg']) / 2.0)
    hx, hy = (t, t * h / w) if fit == 'horizontal' else (t * w / h, t)
    sx, sy = cam.get('shift', [0.0, 0.0])
    cx, cy = sx * 2.0 * t, sy * 2.0 * t  # 2t: the fitted side's extent at unit depth
    return {(i, j): (cx + i * hx, cy + j * hy) for i in (-1, 1) for j in (-1, 1)}


def project(cam, p):
    """World point p through veil's camera: (x/z, y/z) on the unit-depth plane."""
    pos, f = Vector(cam['position']), (Vector(cam['look_at']) - Vector(cam['position'])).normalized()
    r = f.cross(Vector(cam['up'])).normalized()
    u = r.cross(f)
    d = p - pos
    z = d.dot(f)
    return d.dot(r) / z, d.dot(u) / z


cases = 0
for fit in ('AUTO', 'HORIZONTAL', 'VERTICAL'):
    for (w, h) in ((64, 48), (48, 64), (50, 50), (1920, 817)):
        for shift in ((0.0, 0.0), (0.1, -0.2), (-0.35, 0.27)):
            for lens, (sw, sh) in ((50.0, (36.0, 24.0)), (18.0, (23.5, 15.6))):
                cd = cam_ob.data
                cd.sensor_fit, cd.lens, cd.sensor_width, cd.sensor_height = fit, lens, sw, sh
                cd.shift_x, cd.shift_y = shift
                sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = w, h, 100
                cam_ob.rotation_euler = Euler((math.radians(70), math.radians(12), math.radians(40)))
                bpy.context.view_layer.update()
                cam = export.export_camera(sc, cam_ob, w, h, [])
                frame = [Vector(v) for v in cd.view_frame(scene=sc)]  # camera space, z < 0
                want = veil_corners(cam)
                worst = 0.0
                mid = sum(frame, Vector()) / 4.0  # a shifted frame may lie wholly on one side of the axis
                for c in frame:
                    i, j = (1 if c.x > mid.x else -1), (1 if c.y > mid.y else -1)
                    got = project(cam, cam_ob.matrix_world @ c)
                    worst = max(worst, abs(got[0] - want[(i, j)][0]), abs(got[1] - want[(i, j)][1]))
                    # and the engine's own frame (Depth pass) agrees with Blender's corner at z = -1
                    lft, rgt, bot, top = export.camera_frame(cam, w, h)
                    ex = (rgt if i > 0 else lft, top if j > 0 else bot)
                    worst = max(worst, abs(ex[0] - c.x / -c.z), abs(ex[1] - c.y / -c.z))
                cases += 1
                if worst > TOL:
                    check(False, "camera %s %dx%d shift %s lens %g: frame off by %.3g (tolerance %g)"
                          % (fit, w, h, shift, lens, worst, TOL))
check(not common.FAILURES, "camera frame = Blender's view_frame in %d cases (fits, aspects, shifts, lenses)" % cases)
cd = cam_ob.data
cd.shift_x = cd.shift_y = 0.0
cd.clip_start, cd.clip_end = 0.25, 80.0
cam = export.export_camera(sc, cam_ob, 64, 48, [])
check(cam['clip'] == [0.25, 80.0], "camera clip = [clip_start, clip_end]: %s" % cam['clip'])
check('shift' not in cam, "no shift key when Blender's shift is 0")
sc.render.resolution_x, sc.render.resolution_y, sc.render.resolution_percentage = 1000, 501, 33
check(export.render_size(sc) == (330, 165), "render size = resolution x percentage, rounded down as Blender does: %s"
      % (export.render_size(sc),))

# --- VDB sequences ------------------------------------------------------------------------------
seq_dir = os.path.join(work, "seq")
os.makedirs(seq_dir, exist_ok=True)
for k in range(1, 4):
    common.write_sphere_vdb(os.path.join(seq_dir, "smoke_%04d.vdb" % k), n=8)
vol = bpy.data.volumes.new("seq")
vol.filepath = os.path.join(seq_dir, "smoke_0001.vdb")
vol.is_sequence = True
vol.frame_duration = 3
ob = bpy.data.objects.new("seq", vol)
sc.collection.objects.link(ob)
for start, offset in ((10, 0), (10, 1), (12, -1)):
    vol.frame_start, vol.frame_offset = start, offset
    ok = True
    # the scene frames Blender shows (CLIP mode: f - start + 1 in 1..3) whose file exists (number
    # f - start + 1 + offset in 1..3)
    for f in [f for f in range(start, start + 3) if 1 <= f - start + 1 + offset <= 3]:
        sc.frame_set(f)
        dg = bpy.context.evaluated_depsgraph_get()
        ev = ob.evaluated_get(dg)
        ev.data.grids.load()
        blender_file = os.path.basename(ev.data.grids.frame_filepath)
        data, _ = export.export_scene(dg, sequences_as_pattern=True)
        (src,) = [s for s in data['medium']['sources'] if 'seq' in s['file']]
        veil_file = os.path.basename(src['file']).replace("####", "%04d" % (f + src.get('frame_offset', 0)))
        if veil_file != blender_file:
            ok = False
            print("  frame %d: Blender reads %s, veil turntable would read %s" % (f, blender_file, veil_file))
    check(ok and src['file'].endswith("smoke_####.vdb"),
          "sequence frame_start %d frame_offset %d: '####' + frame_offset %d names Blender's file at every frame"
          % (start, offset, src.get('frame_offset', 0)))
    data, _ = export.export_scene(dg, sequences_as_pattern=False)
    (src,) = [s for s in data['medium']['sources'] if 'seq' in s['file']]
    check(os.path.basename(src['file']) == blender_file, "engine export: the current frame's own file (%s)" % blender_file)
sc.frame_set(vol.frame_start - 1)  # before the sequence (CLIP): nothing to render, nothing to export
dg = bpy.context.evaluated_depsgraph_get()
data, _ = export.export_scene(dg)
check(not [s for s in data['medium']['sources'] if 'seq' in s['file']], "a clipped sequence outside its frames: no source")
try:
    export.export_scene(dg, sequences_as_pattern=True)
    check(False, "exporting a sequence's pattern outside its frames is refused")
except export.ExportError as e:
    check("no file at the current frame" in str(e), "exporting a sequence's pattern outside its frames is refused: %s" % e)
bpy.data.objects.remove(ob, do_unlink=True)
sc.frame_set(1)

# --- lights -------------------------------------------------------------------------------------
for o in list(bpy.data.objects):
    if o.type == 'LIGHT':
        bpy.data.objects.remove(o, do_unlink=True)


def light(kind, rot, **kw):
    ld = bpy.data.lights.new(kind, kind)
    for k, v in kw.items():
        setattr(ld, k, v)
    o = bpy.data.objects.new(kind, ld)
    o.location = (1.0, 2.0, 3.0)
    o.rotation_euler = rot
    sc.collection.objects.link(o)


light('SUN', (0.0, 0.0, 0.0), energy=3.0, color=(1.0, 0.5, 0.25))
light('POINT', (0.0, 0.0, 0.0), energy=100.0, color=(1.0, 0.5, 0.25))
light('SPOT', (math.radians(90), 0.0, 0.0), energy=40.0, spot_size=math.radians(60), spot_blend=0.2)
light('AREA', (0.0, 0.0, 0.0), energy=10.0)
data, warnings = export.export_scene(bpy.context.evaluated_depsgraph_get())
lights = {l['type']: l for l in data['lights']}


def close(a, b, tol=1e-6):
    return all(abs(x - y) <= tol * max(1.0, abs(y)) for x, y in zip(a, b))


check(close(lights['directional']['direction'], [0, 0, -1]) and close(lights['directional']['irradiance'], [3, 1.5, 0.75]),
      "sun: unrotated shines down (-Z), irradiance = strength x colour W/m^2: %s" % lights['directional'])
k = 100.0 / (4.0 * math.pi)
check(close(lights['point']['intensity'], [k, k / 2, k / 4]) and close(lights['point']['position'], [1, 2, 3]),
      "point: intensity = watts / (4 pi) x colour W/sr: %s" % lights['point']['intensity'])
spot = lights['spot']
co = math.cos(math.radians(30))
check(close(spot['direction'], [0, 1, 0]) and abs(spot['outer_angle_deg'] - 30) < 1e-4
      and abs(math.cos(math.radians(spot['inner_angle_deg'])) - (co + (1 - co) * 0.2)) < 1e-6,
      "spot: turned 90 deg about X shines along +Y, outer = size/2, cos(inner) = cos(outer) + (1 - cos(outer)) blend: %s"
      % spot)
check(len([x for x in data['lights'] if x['type'] != 'environment']) == 3 and any("area" in w for w in warnings), "area light skipped with a warning: %s"
      % [w for w in warnings if "area" in w])

# --- the volume's transform ---------------------------------------------------------------------
path = os.path.join(work, "sphere8.vdb")
common.write_sphere_vdb(path, n=8, voxel=0.1)
ob = common.build_scene(path)
ob.name = "Smoke"
bpy.context.view_layer.update()
for on in (True, False):
    sc.veil.blender_voxel_centres = on
    data, _ = export.export_scene(bpy.context.evaluated_depsgraph_get())
    (src,) = data['medium']['sources']
    t = Matrix(src['transform'])
    want = ob.matrix_world @ (Matrix.Translation((0.05, 0.05, 0.05)) if on else Matrix.Identity(4))
    err = max(abs(t[i][j] - want[i][j]) for i in range(4) for j in range(4))
    check(err < 1e-6 and src['file'] == path and src['grid'] == 'density',
          "volume transform = matrix_world%s (max difference %.2g)" % (" x half a voxel" if on else "", err))

# --- motion blur: Blender's shutter and the volume's velocity -------------------------------------
# Render > Motion Blur on, shutter 0.5 of a frame centred on it: veil's camera.shutter [-0.25, 0.25], fps
# the scene's; the Volume's Velocity panel (grid 'velocity', per frame, scale 2) as the source's velocity.
# A file with the vector grid, then one without (a warning, no velocity), then START: [0, 0.5].
import numpy as np  # noqa: E402
import pyopenvdb as vdb  # noqa: E402
vpath = os.path.join(work, "moving.vdb")
dens = vdb.FloatGrid()
dens.name = "density"
dens.copyFromArray(np.ones((4, 4, 4), dtype=np.float32))
vel = vdb.Vec3SGrid()
vel.name = "velocity"
vel.copyFromArray(np.ones((4, 4, 4, 3), dtype=np.float32))
vdb.write(vpath, grids=[dens, vel])
ob.data.filepath = vpath
ob.data.grids.load()
ob.data.velocity_unit, ob.data.velocity_scale = 'FRAME', 2.0
sc.render.use_motion_blur, sc.render.motion_blur_shutter = True, 0.5
sc.render.fps, sc.render.fps_base = 30, 1.001
sc.cycles.motion_blur_position = 'CENTER'
bpy.context.view_layer.update()
data, warnings = export.export_scene(bpy.context.evaluated_depsgraph_get())
(src,) = data['medium']['sources']
check(src.get('velocity') == {'grid': 'velocity', 'unit': 'frame', 'scale': 2.0} and
      data['camera'].get('shutter') == [-0.25, 0.25] and data.get('fps') == sc.render.fps / sc.render.fps_base,
      "motion blur: shutter %s, fps %s, velocity %s" % (data['camera'].get('shutter'), data.get('fps'), src.get('velocity')))
sc.cycles.motion_blur_position = 'START'
data, _ = export.export_scene(bpy.context.evaluated_depsgraph_get())
check(data['camera'].get('shutter') == [0.0, 0.5], "motion blur from the frame's start: %s" % data['camera'].get('shutter'))
ob.data.filepath = path  # the sphere: no velocity grid
ob.data.grids.load()
bpy.context.view_layer.update()
data, warnings = export.export_scene(bpy.context.evaluated_depsgraph_get())
(src,) = data['medium']['sources']
check('velocity' not in src and any("no velocity grid" in w for w in warnings),
      "no velocity grid: none exported, with a warning (%s)" % [w for w in warnings if "velocity" in w])
sc.render.use_motion_blur = False
data, _ = export.export_scene(bpy.context.evaluated_depsgraph_get())
check('shutter' not in data['camera'] and 'fps' not in data, "motion blur off: no shutter")
common.finish()
