"""What the Blender Cycles truth scripts share (truth.py here, and
bench/cache_box/box_cycles.py): veil's lights, camera and a black world
in Blender, and Cycles set to render without bias. Imported inside
Blender (bpy); the calibration is truth.py's and is checked by
calibrate.py:
- coordinates: blender (X, Y, Z) = veil (x, -z, y);
- point light: Power = 4 pi I, radius 0; sun: Strength = irradiance E,
  angle 0;
- camera: sensor fit VERTICAL, veil's vertical field of view, looking at
  look_at with blender's +Z (veil's +y) up;
- no clamping, no light threshold, no adaptive sampling, no denoising,
  pixel filter 0.01 px (one ray through each pixel's centre region).
"""
import math

import bpy
from mathutils import Vector


def bl(v):
    """veil (x, y, z) -> blender (x, -z, y)"""
    return (v[0], -v[2], v[1])


def add_lights(sc, lights):
    """veil's point and directional lights (scene JSON dicts) in the scene sc."""
    for i, l in enumerate(lights):
        if l["type"] == "point":
            I = l["intensity"]
            peak = max(I)
            ld = bpy.data.lights.new("lamp%d" % i, "POINT")
            ld.energy = 4.0 * math.pi * peak  # W; Cycles: I = P / (4 pi) W/sr
            ld.color = tuple(v / peak for v in I)
            ld.shadow_soft_size = 0.0
            ob = bpy.data.objects.new("lamp%d" % i, ld)
            ob.location = bl(l["position"])
        else:
            E = l["irradiance"]
            peak = max(E)
            ld = bpy.data.lights.new("sun%d" % i, "SUN")
            ld.energy = peak  # W/m^2
            ld.color = tuple(v / peak for v in E)
            ld.angle = 0.0
            ob = bpy.data.objects.new("sun%d" % i, ld)
            ob.rotation_euler = Vector(bl(l["direction"])).to_track_quat("-Z", "Y").to_euler()
        ld.cycles.max_bounces = 1024
        sc.collection.objects.link(ob)


def add_camera(sc, cam):
    """veil's camera (a scene JSON dict) as sc's camera."""
    cd = bpy.data.cameras.new("cam")
    cd.sensor_fit = "VERTICAL"
    cd.angle_y = math.radians(cam["fov_y_deg"])
    cd.clip_start = 0.01
    cd.clip_end = 1e4
    co = bpy.data.objects.new("cam", cd)
    co.location = bl(cam["position"])
    d = Vector(bl(cam["look_at"])) - Vector(bl(cam["position"]))
    co.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()  # 'Y' keeps blender's +Z (veil's +y) up
    sc.collection.objects.link(co)
    sc.camera = co


def black_world(sc):
    world = bpy.data.worlds.new("black")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sc.world = world


def unbiased(sc, width, height, samples, seed, bounces, out):
    """Cycles on the CPU (2 threads) at width x height, `bounces` of every kind, nothing clamped,
    into the multilayer EXR `out` (32-bit float) with the volume passes."""
    r = sc.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    r.pixel_aspect_x = r.pixel_aspect_y = 1.0
    r.film_transparent = False
    r.use_persistent_data = False
    r.threads_mode = "FIXED"
    r.threads = 2
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = samples
    cy.seed = seed
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.max_bounces = cy.diffuse_bounces = cy.volume_bounces = bounces
    cy.glossy_bounces = cy.transmission_bounces = cy.transparent_max_bounces = bounces
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.filter_width = 0.01
    sc.view_settings.view_transform = "Standard"
    vl = sc.view_layers[0]
    vl.use_pass_combined = True
    vl.cycles.use_pass_volume_direct = vl.cycles.use_pass_volume_indirect = True
    im = r.image_settings
    im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"
    im.exr_codec = "ZIP"
    r.filepath = out
