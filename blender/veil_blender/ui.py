"""veil's panels (Render, World and Volume data properties), the File > Export > veil scene operator,
and Blender's own panels (camera, lights, volume file, output) switched on for the engine."""
import errno
import os

import bpy
from bpy.props import BoolProperty, StringProperty
from bpy_extras.io_utils import ExportHelper

from . import export

ENGINE = "VEIL"


class VeilPanel:
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return context.engine in cls.COMPAT_ENGINES


class RENDER_PT_veil(VeilPanel, bpy.types.Panel):
    bl_label = "veil"
    bl_context = "render"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        vs = context.scene.veil
        layout.prop(vs, "quality")
        layout.prop(vs, "seed")
        layout.prop(vs, "multiple_scattering")
        layout.prop(vs, "use_aov_passes")
        layout.prop(vs, "blender_voxel_centres")


class RENDER_PT_veil_medium(VeilPanel, bpy.types.Panel):
    bl_label = "Medium"
    bl_context = "render"
    bl_parent_id = "RENDER_PT_veil"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        vs = context.scene.veil
        layout.prop(vs, "sigma_s")
        layout.prop(vs, "sigma_a")
        layout.prop(vs, "phase_g")
        layout.prop(vs, "max_resolution")
        layout.prop(vs, "representation")


class VIEWLAYER_PT_veil_passes(VeilPanel, bpy.types.Panel):
    bl_label = "Passes"
    bl_context = "view_layer"

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        col = layout.column(heading="Include")
        col.prop(context.view_layer, "use_pass_combined")
        col.prop(context.view_layer, "use_pass_z", text="Z (depth along the view axis)")
        col.prop(context.scene.veil, "use_aov_passes", text="veil Passes")
        sub = col.column()
        sub.active = context.scene.veil.use_aov_passes
        sub.label(text="veil_transmittance, veil_single, veil_multiple, veil_density")


class WORLD_PT_veil_background(VeilPanel, bpy.types.Panel):
    bl_label = "veil World"
    bl_context = "world"

    @classmethod
    def poll(cls, context):
        return context.world is not None and super().poll(context)

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        w = context.world
        if w.use_nodes and w.node_tree is not None:
            bg = next((n for n in w.node_tree.nodes if n.bl_idname == 'ShaderNodeBackground'), None)
            if bg is None:
                layout.label(text="No Background node: black", icon='INFO')
            else:
                if bg.inputs['Color'].is_linked:
                    layout.label(text="Color: an Environment Texture (an OpenEXR file, Closest)", icon='IMAGE_DATA')
                else:
                    layout.prop(bg.inputs['Color'], "default_value", text="Color")
                layout.prop(bg.inputs['Strength'], "default_value", text="Strength")
        else:
            layout.prop(w, "color")
        layout.label(text="Lights the medium (veil's environment light)")
        if context.scene.render.film_transparent:
            layout.label(text="Film is transparent: not seen behind the medium", icon='INFO')
        else:
            layout.label(text="Seen behind the medium")


class DATA_PT_veil_volume(VeilPanel, bpy.types.Panel):
    bl_label = "veil"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return context.volume is not None and super().poll(context)

    def draw_header(self, context):
        self.layout.prop(context.volume.veil, "use", text="")

    def draw(self, context):
        layout = self.layout
        layout.use_property_split = True
        vol = context.volume
        vs = vol.veil
        layout.active = vs.use
        layout.prop_search(vs, "density_grid", vol, "grids")
        layout.prop(vs, "density_scale")
        col = layout.column(heading="Emission")
        col.prop_search(vs, "emission_grid", vol, "grids", text="Emission Grid")
        sub = col.column()
        sub.active = bool(vs.emission_grid.strip())
        sub.prop(vs, "emission_scale", text="Scale")
        sub.prop(vs, "emission_color", text="Color")
        col = layout.column(heading="Temperature")
        col.prop_search(vs, "temperature_grid", vol, "grids", text="Temperature Grid")
        sub = col.column()
        sub.active = bool(vs.temperature_grid.strip())
        sub.prop(vs, "temperature_scale", text="Scale")
        sub.prop(vs, "temperature_offset", text="Offset")
        row = sub.row(heading="Intensity")
        row.prop(vs, "use_temperature_intensity", text="")
        r = row.row()
        r.active = vs.use_temperature_intensity
        r.prop(vs, "temperature_intensity", text="")


def frame_range(scene):
    """veil turntable's --range for the scene's frames: A-B, or A-BxS with a frame step."""
    rng = "%d-%d" % (scene.frame_start, scene.frame_end)
    return rng + ("x%d" % scene.frame_step if scene.frame_step != 1 else "")


SCRIPT = """#!/usr/bin/env bash
# Written by Blender's veil add-on (File > Export > veil Scene) from {blend}:
# frames {range} of {scene}, the camera still (--degrees 0), a VDB sequence's
# file for each frame. docs/blender.md.
#   bash {name}                 renders them here with veil turntable
#   SLURM=N bash {name}         submits them as N Slurm array tasks (scripts/slurm-turntable.sh;
#                               SLURM_TURNTABLE names that script, default: on PATH)
# Environment: VEIL (the veil program, default: on PATH), OUT (the frames' pattern, default
# {out}); further arguments go to veil turntable (--quality high, --skip-missing, --png ...).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
scene="$here/{scene}"
out=${{OUT:-$here/{out}}}
range={range}
if [ -n "${{SLURM:-}}" ]; then
  exec "${{SLURM_TURNTABLE:-slurm-turntable.sh}}" "$scene" "$out" "$range" "$SLURM" -- --degrees 0 "$@"
fi
exec "${{VEIL:-veil}}" turntable "$scene" -o "$out" --range "$range" --degrees 0 "$@"
"""


def write_all(files):
    """Writes [(path, text, mode or None)] all or nothing: each to a temporary file beside its target, then
    all renamed over their targets once every one is written (issue 41: a full disk, a read-only or missing
    folder, a target that is a directory leave every existing file as it was). OSError names the file."""
    staged = []
    try:
        for path, text, mode in files:
            if os.path.isdir(path):
                raise OSError(errno.EISDIR, "cannot write '%s': it is a folder" % path)
            tmp = "%s.veil-tmp%d" % (path, os.getpid())
            staged.append(tmp)
            try:
                with open(tmp, "w", encoding="utf-8") as f:
                    f.write(text)
                    f.flush()
                    os.fsync(f.fileno())
                if mode is not None:
                    os.chmod(tmp, mode)
            except OSError as e:
                raise OSError(e.errno, "cannot write '%s': %s" % (path, e.strerror or e)) from None
        for (path, _, _), tmp in zip(files, staged):
            try:
                os.replace(tmp, path)
            except OSError as e:
                raise OSError(e.errno, "cannot write '%s': %s" % (path, e.strerror or e)) from None
    finally:
        for tmp in staged:
            try:
                os.remove(tmp)
            except OSError:
                pass


class VEIL_OT_export_scene(bpy.types.Operator, ExportHelper):
    """Export the scene as a veil scene file (JSON), for veil render, veil turntable and Slurm"""
    bl_idname = "veil.export_scene"
    bl_label = "Export veil Scene"
    bl_options = {'PRESET'}

    filename_ext = ".json"
    filter_glob: StringProperty(default="*.json", options={'HIDDEN'})
    sequences_as_pattern: BoolProperty(
        name="Sequences as ####", default=True,
        description="A VDB sequence as its #### pattern, so that veil turntable reads each frame's file "
                    "(off: the current frame's file)")
    relative_paths: BoolProperty(name="Relative Paths", default=False,
                                 description="VDB paths relative to the scene file's folder (off: absolute)")
    write_script: BoolProperty(
        name="Render Script", default=True,
        description="Also write NAME.render.sh: the frame range's veil turntable and Slurm command lines")

    def execute(self, context):
        path = bpy.path.ensure_ext(self.filepath, ".json")
        folder = os.path.dirname(os.path.abspath(path))
        try:
            data, warnings = export.export_scene(context.evaluated_depsgraph_get(),
                                                 sequences_as_pattern=self.sequences_as_pattern)
        except export.ExportError as e:
            self.report({'ERROR'}, "veil: %s" % e)
            return {'CANCELLED'}
        for w in warnings:
            self.report({'WARNING'}, "veil: %s" % w)
        if self.relative_paths:
            for src in data['medium']['sources']:
                src['file'] = os.path.relpath(src['file'], folder)
        scene = context.scene
        name = os.path.splitext(os.path.basename(path))[0]
        rng = frame_range(scene)
        files = [(path, export.to_json(data) + "\n", None)]
        msg = "veil: wrote %s (frames %s: veil turntable %s -o %s.####.exr --range %s --degrees 0)" % (
            path, rng, os.path.basename(path), name, rng)
        if self.write_script:
            script = os.path.join(folder, name + ".render.sh")
            files.append((script, SCRIPT.format(blend=bpy.data.filepath or "an unsaved file", range=rng,
                                                scene=os.path.basename(path), name=os.path.basename(script),
                                                out=name + ".####.exr"), 0o755))
            msg += "; %s" % script
        try:
            write_all(files)
        except OSError as e:
            self.report({'ERROR'}, "veil: %s" % e)
            return {'CANCELLED'}
        self.report({'INFO'}, msg)
        return {'FINISHED'}


def menu_export(self, context):
    self.layout.operator(VEIL_OT_export_scene.bl_idname, text="veil Scene (.json)")


# Blender's own panels shown for veil: those the built-in engine shows, less what veil cannot use
EXCLUDED_PANELS = {
    'DATA_PT_area',            # area lights are not exported
    'DATA_PT_falloff_curve',
    'DATA_PT_preview',
    'VIEWLAYER_PT_filter',
}


def _blender_panels():
    for name in dir(bpy.types):
        if name in EXCLUDED_PANELS or 'lightprobe' in name.lower():
            continue
        panel = getattr(bpy.types, name)
        engines = getattr(panel, 'COMPAT_ENGINES', None)
        if isinstance(engines, set) and 'BLENDER_RENDER' in engines:
            yield panel


classes = (RENDER_PT_veil, RENDER_PT_veil_medium, VIEWLAYER_PT_veil_passes, WORLD_PT_veil_background, DATA_PT_veil_volume, VEIL_OT_export_scene)


def register():
    for c in classes:
        bpy.utils.register_class(c)
    bpy.types.TOPBAR_MT_file_export.append(menu_export)
    for p in _blender_panels():
        p.COMPAT_ENGINES.add(ENGINE)


def unregister():
    for p in _blender_panels():
        p.COMPAT_ENGINES.discard(ENGINE)
    bpy.types.TOPBAR_MT_file_export.remove(menu_export)
    for c in reversed(classes):
        bpy.utils.unregister_class(c)
