"""Blender Cycles (all orders) of bench/cache_box's homogeneous box: the
independent ruler for `veil reference` at strong forward scattering.

    blender -b --factory-startup --python box_cycles.py -- SCENE.json SAMPLES OUT.exr

SCENE.json is the veil scene run.py writes (one exponential fog box with
falloff 0, one sun, black background). Calibration as in bench/fog_truth
(truth.py, checked by its calibrate.py): blender (X, Y, Z) = veil (x, -z,
y); sensor fit VERTICAL with veil's vertical field of view; a sun's
Strength = irradiance E, angle 0; Volume Scatter (density sigma_s,
anisotropy g: HG) plus Volume Absorption (density sigma_a) on a cube of the
fog's bounds; pixel filter 0.01 px; no clamping, no adaptive sampling, no
denoising; 1024 bounces of every kind. Writes a multilayer EXR with
Combined, VolumeDir (order 1) and VolumeInd (orders >= 2).
"""
import json
import math
import sys

import bpy
from mathutils import Vector


def bl(v):
    """veil (x, y, z) -> blender (x, -z, y)"""
    return (v[0], -v[2], v[1])


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

    light = s["lights"][0]
    E = light["irradiance"]
    ld = bpy.data.lights.new("sun", "SUN")
    ld.energy = max(E)
    ld.color = tuple(v / max(E) for v in E)
    ld.angle = 0.0
    ld.cycles.max_bounces = 1024
    ob = bpy.data.objects.new("sun", ld)
    ob.rotation_euler = Vector(bl(light["direction"])).normalized().to_track_quat("-Z", "Y").to_euler()
    sc.collection.objects.link(ob)

    cam = s["camera"]
    cd = bpy.data.cameras.new("cam")
    cd.sensor_fit = "VERTICAL"
    cd.angle_y = math.radians(cam["fov_y_deg"])
    cd.clip_start = 0.01
    cd.clip_end = 1e4
    co = bpy.data.objects.new("cam", cd)
    co.location = bl(cam["position"])
    co.rotation_euler = (Vector(bl(cam["look_at"])) - Vector(bl(cam["position"]))).to_track_quat("-Z", "Y").to_euler()
    sc.collection.objects.link(co)
    sc.camera = co

    w = bpy.data.worlds.new("black")
    w.use_nodes = True
    w.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sc.world = w
    r = sc.render
    r.engine = "CYCLES"
    r.resolution_x, r.resolution_y, r.resolution_percentage = cam["width"], cam["height"], 100
    r.threads_mode = "FIXED"
    r.threads = 2
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = samples
    cy.seed = 1
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.max_bounces = cy.diffuse_bounces = cy.volume_bounces = cy.transparent_max_bounces = 1024
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.filter_width = 0.01
    sc.view_settings.view_transform = "Standard"
    vl = sc.view_layers[0]
    vl.cycles.use_pass_volume_direct = vl.cycles.use_pass_volume_indirect = True
    im = r.image_settings
    im.file_format = "OPEN_EXR_MULTILAYER"
    im.color_depth = "32"
    r.filepath = out
    bpy.ops.render.render(write_still=True)


main()
