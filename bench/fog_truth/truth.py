"""Path-traced truth for `veil fog`: Blender Cycles, all orders of scattering.

    blender -b --factory-startup --python truth.py -- CASE FOG SAMPLES SEED OUT.exr

CASE: night | day (scenes.py); FOG: 0 (the surfaces alone: the frame that
`veil fog` reads), 1 (the same scene inside the case's fog) or 2 (the fog
with black surfaces: they occlude and absorb but reflect nothing, so the
picture is the medium's own light from the lights, all orders -- what
veil's single scattering and volumetric estimate model; 1 minus 2 is the
light that involves the surfaces, what the frame and its spread model). Writes a
multilayer EXR (32-bit float) with the passes Combined, Depth (Z along the
view axis), DiffDir, DiffInd, DiffCol, VolumeDir, VolumeInd.

Calibration to veil (each checked by calibrate.py against a closed form):
- coordinates: blender (X, Y, Z) = veil (x, -z, y);
- camera: sensor fit VERTICAL, the same vertical field of view; pixel
  filter 0.01 px (one ray through each pixel's centre region, as veil's
  march and the frame's depth are per pixel centre);
- point light: Power = 4 pi I (Cycles gives a point lamp of power P the
  intensity P / (4 pi) W/sr), radius 0; sun: Strength = irradiance E
  (W/m^2), angle 0;
- medium: Volume Scatter (colour 1, density sigma_s rho, anisotropy g: HG)
  plus Volume Absorption (colour 0, density sigma_a rho), rho = density *
  exp(-falloff y) from the world position; the fog is a box = veil's bounds;
- world black, no clamping, no light threshold, no adaptive sampling, no
  denoising; 256 bounces of every kind (volume included), so nothing is cut.
"""
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_setup  # noqa: E402
import scenes  # noqa: E402


def diffuse_material(name, albedo):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    nt = m.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    d = nt.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*albedo, 1.0)
    d.inputs["Roughness"].default_value = 0.0  # Lambert
    nt.links.new(d.outputs["BSDF"], out.inputs["Surface"])
    return m


def main():
    argv = sys.argv[sys.argv.index("--") + 1:]
    if len(argv) != 5:
        sys.exit("usage: blender -b --factory-startup --python truth.py -- CASE FOG SAMPLES SEED OUT.exr")
    case, fog, samples, seed, out = argv[0], int(argv[1]), int(argv[2]), int(argv[3]), argv[4]
    if case not in scenes.CASES:
        sys.exit("truth.py: unknown case '%s' (expected one of %s)" % (case, ", ".join(scenes.CASES)))
    c = scenes.CASES[case]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene

    for i, (lo, hi, albedo) in enumerate(scenes.BOXES):
        blender_setup.box("box%d" % i, lo, hi, diffuse_material("mat%d" % i, (0.0, 0.0, 0.0) if fog == 2 else albedo))

    if fog:
        lo, hi = scenes.FOG_BOX
        f = blender_setup.box("fog", lo, hi, blender_setup.fog_material(c))
        f.data.materials.clear()
        f.data.materials.append(bpy.data.materials["fog"])

    blender_setup.add_lights(sc, c["lights"])

    cam = scenes.CAMERA
    blender_setup.add_camera(sc, cam)
    blender_setup.black_world(sc)
    blender_setup.unbiased(sc, cam["width"], cam["height"], samples, seed, 256, out)
    cy = sc.cycles
    cy.volume_step_rate = 1.0
    cy.volume_max_steps = 4096
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    vl = sc.view_layers[0]
    vl.use_pass_z = True
    vl.use_pass_diffuse_direct = vl.use_pass_diffuse_indirect = vl.use_pass_diffuse_color = True
    bpy.ops.render.render(write_still=True)


main()
