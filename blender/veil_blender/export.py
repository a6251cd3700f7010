"""Blender scene -> veil scene dict (docs/scene-format.md; the mapping is docs/blender.md's table).

Pure bpy and mathutils: no veil import, so the exporter runs (and is tested) without the library.
Blender is Z-up in metres; veil's scene format is axis-agnostic (world coordinates in metres, the
camera's up vector given), so every position, direction and matrix is written in Blender's world
coordinates as it is: no axis swap.
"""
import json
import math
import os
import re

import bpy
from mathutils import Matrix, Vector

# veil's limits that an export can reach (docs/scene-format.md)
MAX_LIGHTS = 16  # VEIL_MAX_LIGHTS
WATTS_TO_W_PER_SR = 1.0 / (4.0 * math.pi)  # a point/spot light of P watts has radiant intensity P / (4 pi) W/sr
FRAME_NONE = 2**31 - 1  # VolumeGrids.frame of a sequence with no file at this frame (Blender's VOLUME_FRAME_NONE)
NO_DEPTH = 1.0e10  # Blender's Z pass value where a ray meets nothing (as Cycles writes it)


class ExportError(Exception):
    """A Blender setting that veil cannot render; the message names the object and the property."""


# ---------------------------------------------------------------------------------------------
# Camera


def render_size(scene):
    """The render size in pixels: resolution x percentage, as Blender rounds it (integer division)."""
    r = scene.render
    return (r.resolution_x * r.resolution_percentage) // 100, (r.resolution_y * r.resolution_percentage) // 100


def fitted_axis(sensor_fit, width, height):
    """'horizontal' or 'vertical': the image axis the field of view is measured along. Blender's
    AUTO fits the larger side, the width on a tie (BKE_camera_sensor_fit: sizex >= sizey)."""
    if sensor_fit == 'AUTO':
        return 'horizontal' if width >= height else 'vertical'
    return 'horizontal' if sensor_fit == 'HORIZONTAL' else 'vertical'


def camera_frame(cam, width, height):
    """The image's window on the plane one metre in front of the camera, in camera space
    (x right, y up): (left, right, bottom, top), read from the exported veil camera dict `cam`
    through veil's definitions (fov along the fitted axis; shift in units of the fitted side's
    extent, as Blender's: measured against Camera.view_frame, tests/blender/test_mapping.py).
    The Depth pass uses it for each pixel's cosine to the view axis."""
    fit = cam.get('sensor_fit', 'vertical')
    axis = fitted_axis(fit.upper(), width, height)
    fov = cam['fov_deg'] if 'fov_deg' in cam else cam.get('fov_y_deg', 45.0)  # fov_y_deg: a vertical fit
    ext = 2.0 * math.tan(math.radians(fov) / 2.0)  # extent along the fitted axis
    if axis == 'horizontal':
        ex, ey = ext, ext * height / width
    else:
        ex, ey = ext * width / height, ext
    sx, sy = cam.get('shift', (0.0, 0.0))
    cx, cy = sx * ext, sy * ext
    return cx - ex / 2, cx + ex / 2, cy - ey / 2, cy + ey / 2


def export_camera(scene, cam_obj, width, height, warnings):
    if cam_obj is None:
        raise ExportError("the scene has no camera (Scene properties > Camera): veil renders from the scene camera")
    cd = cam_obj.data
    if cd.type != 'PERSP':
        raise ExportError("camera '%s': type %s: veil renders perspective (pinhole) cameras only"
                          % (cam_obj.name, cd.type.lower()))
    r = scene.render
    if abs(r.pixel_aspect_x - r.pixel_aspect_y) > 1e-6 * max(r.pixel_aspect_x, r.pixel_aspect_y):
        warnings.append("render pixel aspect %g:%g: veil renders square pixels" % (r.pixel_aspect_x, r.pixel_aspect_y))
    if r.use_border:
        warnings.append("render region (border) ignored: veil renders the whole frame")
    if cd.dof.use_dof:
        warnings.append("camera '%s': depth of field ignored (veil's camera is a pinhole)" % cam_obj.name)
    m = cam_obj.matrix_world
    rot = m.to_3x3().normalized()  # Blender's camera ignores the object's scale
    pos = m.translation
    forward = (rot @ Vector((0.0, 0.0, -1.0))).normalized()  # a camera looks along its local -Z
    up = (rot @ Vector((0.0, 1.0, 0.0))).normalized()  # and its local +Y is up in the image
    fit = cd.sensor_fit
    sensor = cd.sensor_height if fit == 'VERTICAL' else cd.sensor_width  # AUTO uses sensor_width for the larger side
    fov = math.degrees(2.0 * math.atan(0.5 * sensor / cd.lens))
    cam = {
        'position': list(pos),
        'look_at': list(pos + forward),
        'up': list(up),
        'sensor_fit': fit.lower(),
        'fov_deg': fov,
        'width': width,
        'height': height,
        'clip': [cd.clip_start, cd.clip_end],
    }
    # Blender moves the frame by shift x the frame's extent along the fitted axis (with AUTO the
    # larger side), and so does veil's "shift" (scene/camera.c): the same numbers
    if cd.shift_x != 0.0 or cd.shift_y != 0.0:
        cam['shift'] = [cd.shift_x, cd.shift_y]
    return cam


# ---------------------------------------------------------------------------------------------
# Lights


def _colour(c, k):
    return [max(0.0, float(v) * k) for v in c]


def export_light(ob, matrix, warnings):
    """One veil light for the Light object `ob` placed by `matrix`, or None (with a warning)."""
    ld = ob.data
    bad = [name for name, v in (("power", ld.energy), ("color", sum(ld.color))) if not math.isfinite(v)]
    if bad:  # Python's max(0, nan) is 0: a NaN power would export as a black light, silently
        raise ExportError("light '%s': its %s is not a number (power %r W, color %r)"
                          % (ob.name, " and ".join(bad), ld.energy, tuple(ld.color)))
    if ld.energy < 0.0:
        warnings.append("light '%s': negative power %g W read as 0" % (ob.name, ld.energy))
    energy = max(0.0, ld.energy)
    rot = matrix.to_3x3().normalized()
    pos = list(matrix.translation)
    direction = list((rot @ Vector((0.0, 0.0, -1.0))).normalized())  # lights shine along local -Z
    if ld.type == 'POINT':
        if ld.shadow_soft_size > 0.0:
            warnings.append("light '%s': radius %g m ignored (veil's point lights are points)"
                            % (ob.name, ld.shadow_soft_size))
        return {'type': 'point', 'position': pos, 'intensity': _colour(ld.color, energy * WATTS_TO_W_PER_SR)}
    if ld.type == 'SUN':
        if ld.angle > 0.0:
            warnings.append("light '%s': sun angle %.3g deg ignored (veil's sun is a direction)"
                            % (ob.name, math.degrees(ld.angle)))
        return {'type': 'directional', 'direction': direction, 'irradiance': _colour(ld.color, energy)}
    if ld.type == 'SPOT':
        sc = matrix.to_scale()
        if abs(sc.x - sc.y) > 1e-6 * max(abs(sc.x), abs(sc.y)):
            warnings.append("light '%s': scale %g x %g makes Blender's cone elliptic; veil's is round (the spot size is used)"
                            % (ob.name, sc.x, sc.y))
        if ld.shadow_soft_size > 0.0:
            warnings.append("light '%s': radius %g m ignored (veil's spot lights are points)"
                            % (ob.name, ld.shadow_soft_size))
        outer = math.degrees(ld.spot_size) / 2.0  # spot_size is the cone's full angle, at most 180 deg
        co = math.cos(math.radians(outer))
        # Blender's blend: the smooth band is cos theta in [co, co + (1 - co) * blend], a smoothstep in
        # cos theta as veil's is, so the inner cone is at cos = co + (1 - co) * blend
        ci = min(1.0, co + (1.0 - co) * ld.spot_blend)
        inner = math.degrees(math.acos(ci))
        # blend 0 is a hard edge; veil wants inner < outer (checked in single precision): a band of
        # 1e-3 deg, under a pixel at any practical size
        inner = max(0.0, min(inner, outer - 1e-3))
        return {'type': 'spot', 'position': pos, 'direction': direction,
                'intensity': _colour(ld.color, energy * WATTS_TO_W_PER_SR),
                'inner_angle_deg': inner, 'outer_angle_deg': outer}
    warnings.append("light '%s': %s lights are not exported (veil has point, sun and spot lights)"
                    % (ob.name, ld.type.lower()))
    return None


# ---------------------------------------------------------------------------------------------
# World


def _world_surface(w):
    """The node feeding the world's active output's Surface, or None."""
    out = None
    for n in w.node_tree.nodes:
        if n.bl_idname == 'ShaderNodeOutputWorld' and (out is None or n.is_active_output):
            out = n
    if out is None or not out.inputs['Surface'].is_linked:
        return None
    return out.inputs['Surface'].links[0].from_node


def export_world(scene, warnings):
    """The world as veil's environment light (it lights the medium, as Cycles' world does, and is seen
    behind it): {"type": "environment", "up": "z", ...} with a Background node's colour x strength, or
    its Environment Texture's image (an OpenEXR file, equirectangular, no mapping: veil's map in
    Blender's axes, docs/scene-format.md) times the strength; None for a black world. A transparent
    film still lights the medium but shows nothing behind it: the caller writes a black background."""
    w = scene.world
    if w is None:
        return None
    if not w.use_nodes or w.node_tree is None:
        col = _colour(w.color, 1.0)
        return {'type': 'environment', 'color': col, 'up': 'z'} if any(c > 0.0 for c in col) else None
    src = _world_surface(w)
    if src is None:
        return None  # no output: Blender's world is black too
    if src.bl_idname != 'ShaderNodeBackground':
        warnings.append("world '%s': its surface is a %s node; veil reads a Background node (a colour or an "
                        "Environment Texture, times its strength) only: no environment" % (w.name, src.bl_idname))
        return None
    col, strength = src.inputs['Color'], src.inputs['Strength']
    if strength.is_linked:
        warnings.append("world '%s': the Background node's Strength is linked: veil uses its unlinked value" % w.name)
    k = max(float(strength.default_value), 0.0)
    if not col.is_linked:
        c = _colour(col.default_value[:3], k)
        return {'type': 'environment', 'color': c, 'up': 'z'} if any(v > 0.0 for v in c) else None
    tex = col.links[0].from_node
    if tex.bl_idname != 'ShaderNodeTexEnvironment' or tex.image is None:
        warnings.append("world '%s': the Background's Color comes from a %s node; veil reads an Environment "
                        "Texture with an image: no environment" % (w.name, tex.bl_idname))
        return None
    path = bpy.path.abspath(tex.image.filepath, library=tex.image.library)
    if tex.image.packed_file is not None or not path.lower().endswith('.exr') or not os.path.isfile(path):
        warnings.append("world '%s': image '%s' is not an OpenEXR file on disk (%s); veil reads lat-long EXR maps: "
                        "no environment" % (w.name, tex.image.name, path or "packed"))
        return None
    if tex.projection != 'EQUIRECTANGULAR':
        warnings.append("world '%s': the Environment Texture's projection is %s; veil reads equirectangular "
                        "maps: no environment" % (w.name, tex.projection.lower()))
        return None
    if tex.inputs['Vector'].is_linked:
        warnings.append("world '%s': the Environment Texture's Vector is linked (a mapping): veil reads the map "
                        "in Blender's axes, unrotated" % w.name)
    if tex.interpolation != 'Closest':
        warnings.append("world '%s': veil reads the map's texels as constant cells (Blender's Closest "
                        "interpolation), not %s" % (w.name, tex.interpolation))
    return {'type': 'environment', 'file': path, 'intensity': k, 'up': 'z'}


# ---------------------------------------------------------------------------------------------
# Volumes

_DIGITS = re.compile(r'(\d+)(?=\D*$)')  # the last run of digits of a file name (Blender's frame number)


def sequence_pattern(path):
    """'cache/smoke_0042.vdb' -> 'cache/smoke_####.vdb' (as many # as the digits: veil reads at least
    that many), or None when the file name holds no digits."""
    head, name = os.path.split(path)
    stem, ext = os.path.splitext(name)
    m = _DIGITS.search(stem)
    if m is None:
        return None
    stem = stem[:m.start()] + '#' * len(m.group(1)) + stem[m.end():]
    return os.path.join(head, stem + ext)


def _grid_names(vol):
    return [g.name for g in vol.grids]


def _pick_density(vol, wanted, where):
    names = _grid_names(vol)
    if wanted:
        if wanted not in names:
            raise ExportError("%s: density grid '%s' is not in the file (grids: %s)" % (where, wanted, ', '.join(names) or 'none'))
        return wanted
    if 'density' in names:
        return 'density'
    for g in vol.grids:
        if g.data_type in ('FLOAT', 'DOUBLE'):
            return g.name
    raise ExportError("%s: no float grid to read as density (grids: %s)" % (where, ', '.join(names) or 'none'))


def _velocity(vol, orig, where, warnings):
    """The volume's velocity as veil's {"grid", "unit", "scale"} (Blender's Velocity panel: a vector grid, or
    three float grids, which veil reads as NAME.x, NAME.y, NAME.z), or None with a warning when the file has
    no such grid: Cycles then blurs nothing either."""
    grids = {g.name: g.data_type for g in vol.grids}
    name = orig.velocity_grid.strip()
    found = None
    if name in grids and grids[name].startswith('VECTOR'):
        found = name
    else:
        xyz = [orig.velocity_x_grid.strip(), orig.velocity_y_grid.strip(), orig.velocity_z_grid.strip()]
        stem = xyz[0][:-2] if xyz[0].endswith('.x') else None
        if stem and xyz == [stem + '.x', stem + '.y', stem + '.z'] and all(n in grids for n in xyz):
            found = stem
        elif all(xyz) and all(n in grids for n in xyz):
            warnings.append("%s: velocity grids '%s', '%s', '%s': veil reads three float grids named NAME.x, NAME.y, "
                            "NAME.z: not motion-blurred" % ((where,) + tuple(xyz)))
            return None
    if found is None:
        warnings.append("%s: motion blur is on but the file has no velocity grid%s: not motion-blurred"
                        % (where, " '%s'" % name if name else ""))
        return None
    return {'grid': found, 'unit': orig.velocity_unit.lower(), 'scale': orig.velocity_scale}


def export_volume(ob, matrix, depsgraph, settings, warnings, sequences_as_pattern):
    """A "vdb" source for the Volume object `ob` (evaluated) placed by `matrix`, or None when the
    volume has no file at this frame (a clipped sequence)."""
    vol = ob.data
    orig = vol.original if vol.original is not None else vol
    where = "volume '%s'" % ob.name
    vs = orig.veil
    if not vol.filepath:
        raise ExportError("%s: no file (veil renders Volume objects that read a .vdb file)" % where)
    if orig.packed_file is not None or vol.packed_file is not None:
        # Blender reads the grids from the .blend; the path may not exist, or hold other data (issue 41)
        raise ExportError("%s: its VDB is packed into the .blend file; veil reads VDB files on disk: unpack it "
                          "(File > External Data > Unpack Resources) and export again" % where)
    lib = orig.library
    if not vol.grids.is_loaded:
        vol.grids.load()
    frame_file = vol.grids.frame_filepath or vol.filepath
    abs_file = os.path.normpath(bpy.path.abspath(frame_file, library=lib))
    if orig.is_sequence and vol.grids.frame == FRAME_NONE:
        # a CLIP sequence outside its frames: Blender shows nothing, and has no file to read the grids of
        if not sequences_as_pattern:
            return None
        raise ExportError("%s: the sequence has no file at the current frame %d (its frames: %d-%d): set the "
                          "current frame inside it to export it" % (where, depsgraph.scene.frame_current,
                                                                    orig.frame_start, orig.frame_start + orig.frame_duration - 1))
    if vol.grids.error_message or not vol.grids.is_loaded:
        raise ExportError("%s: cannot read '%s': %s" % (where, abs_file, vol.grids.error_message or 'not loaded'))
    if len(ob.modifiers) > 0:
        warnings.append("%s: modifiers ignored (veil reads the file's grids as they are)" % where)
    density = _pick_density(vol, vs.density_grid.strip(), where)
    src = {'type': 'vdb', 'file': abs_file, 'grid': density}
    if sequences_as_pattern and orig.is_sequence:
        pattern = sequence_pattern(os.path.normpath(bpy.path.abspath(vol.filepath, library=lib)))
        if pattern is None:
            raise ExportError("%s: a sequence whose file name '%s' holds no frame number" % (where, vol.filepath))
        src['file'] = pattern
        # Blender reads file number (f - frame_start + 1) + frame_offset at scene frame f
        # (BKE_volume_sequence_frame, CLIP and EXTEND inside the sequence); veil turntable reads f + frame_offset
        off = orig.frame_offset - orig.frame_start + 1
        if off != 0:
            src['frame_offset'] = off
        if orig.sequence_mode != 'CLIP':
            warnings.append("%s: sequence mode %s: veil maps frames linearly (as CLIP); frames outside the "
                            "sequence's %d files are missing (veil turntable --skip-missing)"
                            % (where, orig.sequence_mode.lower(), orig.frame_duration))
    t = matrix.copy()
    if settings.blender_voxel_centres:
        # Cycles renders voxel i's centre at index i + 1/2, veil (and OpenVDB) at i (docs/peers.md
        # measured it): move the grid half a voxel so that veil's smoke sits where Cycles has it
        g = vol.grids[density]
        half = g.matrix_object.to_3x3() @ Vector((0.5, 0.5, 0.5))
        t = t @ Matrix.Translation(half)
    if t != Matrix.Identity(4):
        src['transform'] = [list(row) for row in t]
    if vs.density_scale != 1.0:
        src['density_scale'] = vs.density_scale
    names = _grid_names(vol)
    if vs.emission_grid.strip():
        name = vs.emission_grid.strip()
        if name not in names:
            raise ExportError("%s: emission grid '%s' is not in the file (grids: %s)" % (where, name, ', '.join(names)))
        src['emission'] = {'grid': name, 'scale': vs.emission_scale, 'color': list(vs.emission_color)}
    if vs.temperature_grid.strip():
        name = vs.temperature_grid.strip()
        if name not in names:
            raise ExportError("%s: temperature grid '%s' is not in the file (grids: %s)" % (where, name, ', '.join(names)))
        temp = {'grid': name, 'scale': vs.temperature_scale, 'offset': vs.temperature_offset}
        if vs.use_temperature_intensity:
            temp['intensity'] = vs.temperature_intensity
        src['temperature'] = temp
    if depsgraph.scene.render.use_motion_blur:
        vel = _velocity(vol, orig, where, warnings)
        if vel is not None:
            src['velocity'] = vel
    return src


# ---------------------------------------------------------------------------------------------
# The scene


def export_medium(settings):
    med = {'sigma_a': list(settings.sigma_a), 'sigma_s': list(settings.sigma_s)}
    if settings.phase_g != 0.0:
        med['phase'] = {'type': 'hg', 'g': settings.phase_g}
    if settings.max_resolution > 0:
        med['max_resolution'] = settings.max_resolution
    if settings.representation != 'AUTO':
        med['representation'] = settings.representation.lower()
    return med


def export_scene(depsgraph, *, sequences_as_pattern=False, size=None, render_visibility=True):
    """The veil scene dict of the evaluated `depsgraph` at its frame, and the warnings (strings).

    sequences_as_pattern: a VDB sequence as its '####' pattern and frame_offset (for veil
    turntable) instead of the current frame's file. size: (width, height) overriding the render
    size. render_visibility: skip objects hidden from renders (the viewport depsgraph of an
    operator holds them)."""
    scene = depsgraph.scene
    settings = scene.veil
    warnings = []
    width, height = size if size is not None else render_size(scene)
    cam_obj = scene.camera.evaluated_get(depsgraph) if scene.camera is not None else None
    out = {'camera': export_camera(scene, cam_obj, width, height, warnings)}
    rd = scene.render
    if rd.use_motion_blur:
        # Blender's shutter is a fraction of a frame placed at the frame's start, centre or end (Cycles'
        # motion_blur_position); veil's is [open, close] in frames around the frame, and fps converts a
        # velocity per second
        s_len = rd.motion_blur_shutter
        pos = getattr(scene.cycles, 'motion_blur_position', 'CENTER') if hasattr(scene, 'cycles') else 'CENTER'
        out['camera']['shutter'] = {'START': [0.0, s_len], 'END': [-s_len, 0.0]}.get(pos, [-0.5 * s_len, 0.5 * s_len])
        out['fps'] = rd.fps / rd.fps_base
    medium = export_medium(settings)
    sources, lights = [], []
    skipped = set()
    for inst in depsgraph.object_instances:
        ob = inst.object
        orig = ob.original if ob.original is not None else ob
        if render_visibility and orig.hide_render:
            continue
        if ob.type == 'VOLUME':
            if not orig.data.veil.use:
                continue
            src = export_volume(ob, inst.matrix_world, depsgraph, settings, warnings, sequences_as_pattern)
            if src is not None:
                sources.append(src)
        elif ob.type == 'LIGHT':
            light = export_light(ob, inst.matrix_world, warnings)
            if light is not None:
                lights.append(light)
        elif ob.type not in ('CAMERA', 'EMPTY'):
            skipped.add(ob.type.lower())
    if skipped:
        warnings.append("not exported (veil renders Volume objects and lights): %s objects" % ', '.join(sorted(skipped)))
    if not sources:
        warnings.append("no Volume object with veil's Volume panel on is rendered: the image holds no medium, "
                        "only what lies behind")
    env = export_world(scene, warnings)
    if env is not None:
        lights.append(env)
    if len(lights) > MAX_LIGHTS:
        raise ExportError("%d lights%s: veil renders at most %d" % (len(lights), " (the world's included)"
                                                                      if env is not None else "", MAX_LIGHTS))
    medium['sources'] = sources
    out['medium'] = medium
    out['lights'] = lights
    if env is None or scene.render.film_transparent:
        out['background'] = {'color': [0.0, 0.0, 0.0]}  # transparent film: the medium alone, alpha 1 - mean T
    out['quality'] = settings.quality.lower()
    if not settings.multiple_scattering:
        out['multiple_scattering'] = {'volumetric': False, 'screen_space': False}
    return out, warnings


def to_json(value, indent=0):
    """JSON text of a scene dict as docs/scene-format.md writes it: an object's keys a line each, a
    list of numbers (a vector, a colour, a matrix row) on one line. Numbers as Python's repr, which
    reads back as the same double."""
    pad = " " * indent
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = ['%s  %s: %s' % (pad, json.dumps(k), to_json(v, indent + 2)) for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + pad + "}"
    if isinstance(value, (list, tuple)):
        if all(not isinstance(v, (dict, list, tuple)) for v in value):
            return "[" + ", ".join(json.dumps(v) for v in value) + "]"
        return "[\n" + ",\n".join(pad + "  " + to_json(v, indent + 2) for v in value) + "\n" + pad + "]"
    return json.dumps(value)
