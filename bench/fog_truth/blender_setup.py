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


def box(name, lo, hi, material):
    """A box from veil corners lo, hi with `material`, its scale applied (densities in m^-1)."""
    a, b = bl(lo), bl(hi)
    mn = [min(a[i], b[i]) for i in range(3)]
    mx = [max(a[i], b[i]) for i in range(3)]
    centre = [(mn[i] + mx[i]) / 2 for i in range(3)]
    size = [(mx[i] - mn[i]) for i in range(3)]
    bpy.ops.mesh.primitive_cube_add(size=1.0, location=centre)
    ob = bpy.context.active_object
    ob.name = name
    ob.scale = size
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)  # object scale 1: densities in m^-1
    ob.data.materials.append(material)
    return ob


def grey_medium(name, g):
    """A material whose volume is Volume Scatter (white, HG g) plus Volume Absorption (black):
    (material, its node tree, the scatter node, the absorption node), their Density left to the caller."""
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    scat = nt.nodes.new("ShaderNodeVolumeScatter")
    absb = nt.nodes.new("ShaderNodeVolumeAbsorption")
    add = nt.nodes.new("ShaderNodeAddShader")
    scat.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    scat.inputs["Anisotropy"].default_value = g
    absb.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    nt.links.new(scat.outputs[0], add.inputs[0])
    nt.links.new(absb.outputs[0], add.inputs[1])
    nt.links.new(add.outputs[0], out.inputs["Volume"])
    return m, nt, scat, absb


def fog_material(c):
    """The fog of case dict c (g, sigma_s, sigma_a grey; fog: density, falloff b): Volume Scatter plus
    Volume Absorption, rho = density exp(-b y) from the world position (constant: Cycles' homogeneous
    path)."""
    m, nt, scat, absb = grey_medium("fog", c["g"])
    ss, sa = c["sigma_s"][0], c["sigma_a"][0]
    assert c["sigma_s"] == [ss] * 3 and c["sigma_a"] == [sa] * 3, "grey media only"
    rho0, b = c["fog"]["density"], c["fog"]["falloff"]
    if b == 0.0:  # constant density: Cycles' homogeneous path (exact distance sampling)
        scat.inputs["Density"].default_value = ss * rho0
        absb.inputs["Density"].default_value = sa * rho0
    else:  # rho = rho0 exp(-b y), y = blender Z of the world position
        geo = nt.nodes.new("ShaderNodeNewGeometry")
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        mul = nt.nodes.new("ShaderNodeMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = -b
        ex = nt.nodes.new("ShaderNodeMath")
        ex.operation = "EXPONENT"
        ks = nt.nodes.new("ShaderNodeMath")
        ks.operation = "MULTIPLY"
        ks.inputs[1].default_value = ss * rho0
        ka = nt.nodes.new("ShaderNodeMath")
        ka.operation = "MULTIPLY"
        ka.inputs[1].default_value = sa * rho0
        nt.links.new(geo.outputs["Position"], sep.inputs[0])
        nt.links.new(sep.outputs["Z"], mul.inputs[0])
        nt.links.new(mul.outputs[0], ex.inputs[0])
        nt.links.new(ex.outputs[0], ks.inputs[0])
        nt.links.new(ex.outputs[0], ka.inputs[0])
        nt.links.new(ks.outputs[0], scat.inputs["Density"])
        nt.links.new(ka.outputs[0], absb.inputs["Density"])
        # procedural density: Cycles marches with 1/10 of the box's mean size
        # times this rate (and the scene's rate): 0.1 * 87 m * 0.06 = 0.52 m (b dt = 0.1: the jittered
        # march's optical depth has a variance far below the noise)
        m.cycles.volume_step_rate = 0.06
    return m
