"""The add-on's light units against Cycles itself: the irradiance each exported light gives (veil's
model: point and spot I / r^2 times the cosine of incidence, the spot weighted by veil_spot_falloff,
core/shared.glsl.h, and for Cycles' spot by the cosine off its axis too; sun: irradiance times the
cosine) equals what Cycles 3.4 renders on a white
diffuse patch under the same Blender light (E = pi L: a Lambertian albedo-1 surface).

Cases: a point light; a spot on its axis, inside its blend band and beyond its cone; a sun tilted by
30 degrees. The patch is 1 cm across, 2 m from the light: across it the irradiance varies by less
than 2e-5 (1/r^2 and the cosine, to second order in 0.005/2), and a point or sun light's direct
contribution carries no sampling noise (one light sample sees the whole light), so Cycles' pixel mean
is E / pi to float32 rounding (1e-7) and pixel-filter jitter (the 2e-5 variation). The tolerance,
1e-3 relative (and 1e-4 of the on-axis value where veil's answer is 0), leaves room for that and
would fail a conversion off by any factor that matters (a 4 pi, a pi, a cosine) or a blend band
mapped at the wrong angle (the band case sits where the smoothstep's slope is steepest: 0.1 deg of
error moves it by more than 1e-3).

    blender -b --factory-startup --python tests/blender/test_lights.py -- WORKDIR
"""
import math
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402
from common import check  # noqa: E402
from veil_blender import export  # noqa: E402

work = common.args()[0]
os.makedirs(work, exist_ok=True)
D = 2.0  # the light's height above the patch (m)


def spot_falloff(cos_t, cos_inner, cos_outer):
    """veil_spot_falloff (core/shared.glsl.h), in double."""
    if cos_t >= cos_inner:
        return 1.0
    if cos_t <= cos_outer:
        return 0.0
    t = (cos_t - cos_outer) / (cos_inner - cos_outer)
    return t * t * (3.0 - 2.0 * t)


def cycles_irradiance(light_type, setup, x):
    """Cycles' irradiance on a 1 cm white diffuse patch at (x, 0, 0) facing +z."""
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = 'CYCLES'
    sc.cycles.samples = 16
    sc.cycles.use_denoising = False
    sc.cycles.device = 'CPU'
    sc.render.resolution_x = sc.render.resolution_y = 8
    sc.view_settings.view_transform = 'Standard'
    w = bpy.data.worlds.new("black")
    w.color = (0.0, 0.0, 0.0)
    sc.world = w
    bpy.ops.mesh.primitive_plane_add(size=0.02, location=(x, 0.0, 0.0))
    mat = bpy.data.materials.new("white")
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["Specular"].default_value = 0.0
    bsdf.inputs["Roughness"].default_value = 1.0
    bpy.context.object.data.materials.append(mat)
    ld = bpy.data.lights.new("light", light_type)
    ld.shadow_soft_size = 0.0
    setup(ld)
    lo = bpy.data.objects.new("light", ld)
    lo.location = (0.0, 0.0, D)
    if light_type == 'SUN':
        lo.rotation_euler = (math.radians(30.0), 0.0, 0.0)
    sc.collection.objects.link(lo)
    cd = bpy.data.cameras.new("cam")
    cd.type = 'ORTHO'
    cd.ortho_scale = 0.01  # the patch fills the view
    co = bpy.data.objects.new("cam", cd)
    co.location = (x, 0.0, 1.0)
    sc.collection.objects.link(co)
    sc.camera = co
    path = os.path.join(work, "lights_%s.exr" % light_type.lower())
    sc.render.filepath = path
    sc.render.image_settings.file_format = 'OPEN_EXR'
    sc.render.image_settings.color_depth = '32'
    bpy.context.view_layer.update()
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(path)
    px = np.array(img.pixels[:], dtype=np.float64).reshape(-1, 4)
    bpy.data.images.remove(img)
    exported = export.export_light(lo, lo.matrix_world, [])
    return math.pi * px[:, 0].mean(), exported


def veil_irradiance(light, x):
    """What veil's light model gives at the patch (x, 0, 0), normal +z."""
    if light['type'] == 'directional':
        d = np.array(light['direction'], dtype=np.float64)
        return light['irradiance'][0] * max(0.0, -d[2] / np.linalg.norm(d))
    to = np.array([x, 0.0, 0.0]) - np.array(light['position'])
    r = np.linalg.norm(to)
    e = light['intensity'][0] / (r * r) * (-to[2] / r)
    if light['type'] == 'spot':
        axis = np.array(light['direction']) / np.linalg.norm(light['direction'])
        e *= spot_falloff(float(np.dot(to / r, axis)), math.cos(math.radians(light['inner_angle_deg'])),
                          math.cos(math.radians(light['outer_angle_deg'])))
    return e


def spot(ld):
    ld.energy = 100.0
    ld.spot_size = math.radians(40.0)
    ld.spot_blend = 0.5


outer = math.radians(20.0)
co = math.cos(outer)
ci = co + (1.0 - co) * 0.5  # the band's inner edge for blend 0.5 (what Blender documents as the blend)
mid = math.acos(0.5 * (co + ci))  # halfway through the band in cos theta: the smoothstep's steepest point
cases = [
    ("point", 'POINT', lambda ld: setattr(ld, 'energy', 100.0), 0.0),
    ("spot on its axis", 'SPOT', spot, 0.0),
    ("spot in its blend band", 'SPOT', spot, D * math.tan(mid)),
    ("spot beyond its cone", 'SPOT', spot, D * math.tan(outer + math.radians(2.0))),
    ("sun at 30 deg", 'SUN', lambda ld: setattr(ld, 'energy', 3.0), 0.0),
]
on_axis = None
for name, kind, setup, x in cases:
    e_cycles, light = cycles_irradiance(kind, setup, x)
    e_veil = veil_irradiance(light, x)
    if kind == 'SPOT':
        # Cycles 3.4's spot is weighted by the cosine of the angle off its axis as well (its attenuation
        # starts from dot(direction, axis)); veil's spot is not: inside a 40 deg cone the two differ by
        # at most 1 - cos 20 deg = 6 % (docs/blender.md, "Lights"). Measured here, so a Blender release
        # that changes it fails this test.
        e_veil *= math.cos(math.atan2(x, D))
    if name == "spot on its axis":
        on_axis = e_veil
    tol = 1e-3 * abs(e_veil) if e_veil != 0.0 else 1e-4 * (on_axis or 1.0)
    check(abs(e_cycles - e_veil) <= tol, "%s: Cycles E = %.6g W/m^2, veil's exported light %.6g (|diff| %.3g, "
          "tolerance %.3g)" % (name, e_cycles, e_veil, abs(e_cycles - e_veil), tol))
common.finish()
