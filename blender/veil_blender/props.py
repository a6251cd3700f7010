"""The veil settings stored in .blend files: the medium and the render (Scene.veil) and each Volume's
grids (Volume.veil). docs/blender.md maps each to the scene format."""
import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty, PointerProperty, StringProperty

QUALITIES = [
    ('DRAFT', "Draft", "March step 1 voxel, coarse optical-depth grids: the fastest"),
    ('DEFAULT', "Default", "March step 0.5 voxel (docs/performance.md has each rung's time and error)"),
    ('HIGH', "High", "Finer optical-depth grids"),
    ('MAX', "Max", "March step 0.25 voxel: the slowest"),
]


class VeilSceneSettings(bpy.types.PropertyGroup):
    # the medium (one per scene in veil: every Volume object is one of its sources)
    sigma_s: FloatVectorProperty(name="Scattering", subtype='COLOR', size=3, min=0.0, max=1e10, soft_max=100.0,
                                 default=(1.0, 1.0, 1.0),
                                 description="sigma_s: scattering coefficient per unit density (1/m), per colour channel")
    sigma_a: FloatVectorProperty(name="Absorption", subtype='COLOR', size=3, min=0.0, max=1e10, soft_max=100.0,
                                 default=(0.0, 0.0, 0.0),
                                 description="sigma_a: absorption coefficient per unit density (1/m), per colour channel")
    phase_g: FloatProperty(name="Anisotropy", min=-0.99, max=0.99, default=0.0,
                           description="Henyey-Greenstein g (0: isotropic, > 0: forward scattering)")
    max_resolution: IntProperty(name="Max Resolution", min=0, max=2048, default=0,
                                description="Voxels along the longest side of the extinction volume (0: the VDBs' own voxels)")
    representation: EnumProperty(name="Representation", default='AUTO', items=[
        ('AUTO', "Auto", "Dense when the grid fits, sparse bricks otherwise"),
        ('DENSE', "Dense", "One 3D texture of the whole box"),
        ('SPARSE', "Sparse", "Only the 8^3 bricks that hold density")])
    multiple_scattering: BoolProperty(name="Multiple Scattering", default=True,
                                      description="Light scattered more than once (veil's light cache and screen-space spread)")
    # the render
    quality: EnumProperty(name="Quality", items=QUALITIES, default='DEFAULT',
                          description="veil's quality rung: the march step and the optical-depth grids together")
    seed: IntProperty(name="Seed", min=0, default=0, description="The jitter's seed")
    use_aov_passes: BoolProperty(name="veil Passes", default=True,
                                 description="veil_transmittance, veil_single, veil_multiple and veil_density render passes")
    blender_voxel_centres: BoolProperty(
        name="Blender Voxel Placement", default=True,
        description="Place voxel i's centre at index i + 1/2, as Cycles renders it (off: at i, as OpenVDB "
                    "and veil's own scene files do)")


class VeilVolumeSettings(bpy.types.PropertyGroup):
    use: BoolProperty(name="Render with veil", default=True, description="This volume is a source of veil's medium")
    density_grid: StringProperty(name="Density Grid", default="",
                                 description="The grid read as density (empty: 'density', else the first float grid)")
    density_scale: FloatProperty(name="Density Scale", min=0.0, max=1e10, soft_max=100.0, default=1.0,
                                 description="Multiplies the density grid's values")
    emission_grid: StringProperty(name="Emission Grid", default="",
                                  description="A float grid of emitted radiance per metre (pyro caches: heat, flame); empty: none")
    emission_scale: FloatProperty(name="Emission Scale", min=0.0, max=1e21, soft_max=100.0, default=1.0,
                                  description="Emission = scale x value x colour (W m^-3 sr^-1)")
    emission_color: FloatVectorProperty(name="Emission Color", subtype='COLOR', size=3, min=0.0, max=1e21,
                                        soft_max=1.0, default=(1.0, 1.0, 1.0))
    temperature_grid: StringProperty(name="Temperature Grid", default="",
                                     description="A float grid of temperatures for blackbody emission (pyro caches: temperature); empty: none")
    temperature_scale: FloatProperty(name="Temperature Scale", min=-1e5, max=1e5, default=1.0,
                                     description="Kelvin = scale x value + offset")
    temperature_offset: FloatProperty(name="Temperature Offset", min=-1e5, max=1e5, default=0.0,
                                      description="Kelvin = scale x value + offset")
    use_temperature_intensity: BoolProperty(name="Blackbody Intensity", default=False,
                                            description="Set the blackbody emission's strength (off: the absorption, as Kirchhoff's law has it)")
    temperature_intensity: FloatProperty(name="Intensity", min=0.0, max=1e10, soft_max=100.0, default=1.0,
                                         description="Blackbody emission per unit density (1/m)")


classes = (VeilSceneSettings, VeilVolumeSettings)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.Scene.veil = PointerProperty(type=VeilSceneSettings)
    bpy.types.Volume.veil = PointerProperty(type=VeilVolumeSettings)


def unregister():
    del bpy.types.Volume.veil
    del bpy.types.Scene.veil
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
