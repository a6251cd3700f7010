"""The veil render engine (F12): the evaluated scene exported to a veil scene dict in memory, rendered
by the Python module `veil` (ctypes over libveil.so), its images written into Blender's render result.

veil's arrays are top row first; Blender's render passes are bottom row first: every image is
flipped. Passes: Combined (veil's rgba), Depth (camera-space depth along the view axis, as Blender's
Z pass: veil's mean distance of the first interaction times the pixel's cosine to the view axis,
1e10 where the ray meets no medium), and with Scene.veil.use_aov_passes veil_transmittance (RGB),
veil_single (RGB), veil_multiple (RGB) and veil_density (the density integral along the ray).
"""
import math
import os
import time

import bpy

from . import export

# veil's stages in the order a frame runs them, for one progress bar (equal shares: the split of
# time between them depends on the scene, and a bar that moves per stage is what matters)
STAGES = ("inject", "propagate", "volumetric", "render", "spread")

# (pass name, channels, channel ids, pass type, veil array)
AOV_PASSES = (
    ("veil_transmittance", 3, "RGB", 'COLOR', "transmittance"),
    ("veil_single", 3, "RGB", 'COLOR', "single"),
    ("veil_multiple", 3, "RGB", 'COLOR', "multiple"),
    ("veil_density", 1, "X", 'VALUE', "density_integral"),
)


def import_veil():
    """The Python module `veil`, or an ExportError that says how to make it importable."""
    try:
        import veil  # noqa: F401  (python/veil in the repository, or installed beside libveil)
    except ImportError as e:
        raise export.ExportError(
            "the Python module 'veil' cannot be imported (%s): install veil (cmake --install, or pip install "
            "python/ into Blender's Python), or start Blender with PYTHONPATH=<veil>/python and "
            "VEIL_LIBRARY=<veil>/build/libveil.so (docs/blender.md)" % e) from None
    return veil


def depth_along_axis(distance, frame):
    """veil's ray distance (H x W, top row first, as veil gives it) -> depth along the view axis, 1e10
    where no medium (veil's distance 0).

    Used with a library older than veil 0.3, which has no Z of its own.
    Pixel (column i, row r from the top) looks through the point (x, y, -1) of camera space, (x, y)
    its centre on the frame one metre ahead (export.camera_frame); its ray makes the angle theta with
    the view axis, cos theta = 1 / sqrt(1 + x^2 + y^2), and a point at distance d along the ray lies
    at depth d cos theta."""
    import numpy as np
    h, w = distance.shape
    left, right, bottom, top = frame
    x = left + (np.arange(w, dtype=np.float64) + 0.5) * ((right - left) / w)
    y = top - (np.arange(h, dtype=np.float64) + 0.5) * ((top - bottom) / h)
    cos = 1.0 / np.sqrt(1.0 + x[None, :] ** 2 + y[:, None] ** 2)
    z = distance * cos
    return np.where(distance > 0.0, z, export.NO_DEPTH).astype(np.float32)


class VeilRenderEngine(bpy.types.RenderEngine):
    bl_idname = "VEIL"
    bl_label = "veil"
    bl_use_preview = False           # no material previews: veil renders media, not surfaces
    bl_use_postprocess = True        # the compositor and the sequencer run on veil's frames
    bl_use_eevee_viewport = True     # Material Preview in the viewport stays EEVEE's
    bl_use_shading_nodes_custom = False

    def update_render_passes(self, scene=None, renderlayer=None):
        """The passes this engine fills, for the render result and the compositor's sockets."""
        self.register_pass(scene, renderlayer, "Combined", 4, "RGBA", 'COLOR')
        if renderlayer.use_pass_z:
            self.register_pass(scene, renderlayer, "Depth", 1, "Z", 'VALUE')
        if scene.veil.use_aov_passes:
            for name, channels, ids, kind, _ in AOV_PASSES:
                self.register_pass(scene, renderlayer, name, channels, ids, kind)

    def render(self, depsgraph):
        scene = depsgraph.scene
        width, height = self.resolution_x, self.resolution_y
        # Blender calls render() once per view layer: this call's result is that layer's
        result = self.begin_result(0, 0, width, height, layer=depsgraph.view_layer.name)
        cancelled = True
        try:
            images = self._render(depsgraph, width, height)
            if images is not None:
                self._fill(result, scene, images, width, height)
                cancelled = False
            else:
                # an ERROR, not INFO: Blender 3.4 crashes writing a still (write_still, -f) after a result
                # ended with cancel=True unless the render reported an error
                self.report({'ERROR'}, "veil: render cancelled: no image")
        except export.ExportError as e:
            self.report({'ERROR'}, "veil: %s" % e)
        except Exception as e:  # a veil.VeilError (or a bug): a message in Blender's report, never a crash
            if hasattr(e, "message") and hasattr(e, "code"):  # veil.VeilError: the file and the JSON field
                self.report({'ERROR'}, "veil: %s" % e.message)
            else:
                self.report({'ERROR'}, "veil: %s: %s" % (type(e).__name__, e))
        finally:
            # every begun result is ended, or Blender's render job is left holding it
            self.end_result(result, cancel=cancelled)

    def _render(self, depsgraph, width, height):
        scene = depsgraph.scene
        t0 = time.perf_counter()
        self.update_stats("", "veil: exporting the scene")
        data, warnings = export.export_scene(depsgraph, size=(width, height), render_visibility=False)
        for w in warnings:
            self.report({'WARNING'}, "veil: %s" % w)
        veil = import_veil()
        self._frame = export.camera_frame(data['camera'], width, height)
        t_export = time.perf_counter() - t0
        broke = []
        shown = [None]

        def progress(stage, done):
            if self.test_break():  # Esc in Blender
                broke.append(stage)
                return False  # veil's rule: False cancels (veil.render raises veil.Cancelled)
            i = STAGES.index(stage) if stage in STAGES else len(STAGES) - 1
            self.update_progress(min(1.0, (i + max(0.0, min(1.0, done))) / len(STAGES)))
            step = (stage, int(10 * done))  # the status line in tenths (in the background each is a log line)
            if step != shown[0]:
                shown[0] = step
                self.update_stats("", "veil: %s %d%%" % (stage, 10 * step[1]))
            return None

        # veil 0.2's library has no progress callback (the module refuses one): no progress, no cancel
        has_progress = tuple(getattr(veil, "version_info", (0, 0, 0)))[:2] >= (0, 3)
        try:
            # a context of this render's own, made and closed on this thread: Blender renders on a
            # job thread, and an OpenGL context belongs to the thread that made it
            with veil.Context() as ctx:
                images = veil.render(data, quality=None, seed=scene.veil.seed, context=ctx,
                                     progress=progress if has_progress else None,
                                     base_dir=bpy.path.abspath("//") or None)
        except Exception as e:
            if broke or type(e).__name__ == "Cancelled":
                return None  # cancelled (Esc): no image, no error
            raise
        self._times = (t_export, time.perf_counter() - t0 - t_export)
        if os.environ.get("VEIL_BLENDER_TIMES"):
            print("veil_blender: export %.3f s, veil.render %.3f s" % self._times, flush=True)
        return images

    def _fill(self, result, scene, images, width, height):
        import numpy as np
        t0 = time.perf_counter()
        layer = result.layers[0]
        passes = {p.name: p for p in layer.passes}

        def put(name, a):
            if name not in passes:
                return
            # top row first -> bottom row first, into a native float32 array: bpy's buffer path takes
            # the format 'f' only (veil's arrays may say '<f', the same bytes)
            flipped = np.empty(a.shape, dtype=np.float32)
            flipped[...] = a[::-1]
            a = flipped
            # rect is (pixels x channels); foreach_set takes the float32 buffer whole (a 640x480 RGBA
            # pass in under 1 ms, where assigning rect = array goes value by value: 0.13 s)
            passes[name].rect.foreach_set(a.reshape(width * height, a.shape[2] if a.ndim == 3 else 1))

        rgba = images["rgba"]
        if rgba.shape[:2] != (height, width):
            raise export.ExportError("veil returned %dx%d, Blender expects %dx%d"
                                     % (rgba.shape[1], rgba.shape[0], width, height))
        put("Combined", rgba)
        if "Depth" in passes:
            if "z" in images:  # veil's own Z (0.3): the depth along the view axis, +inf where no medium
                import numpy as np
                z = images["z"][..., 0]
                put("Depth", np.where(np.isinf(z), np.float32(export.NO_DEPTH), z).astype(np.float32)[..., None])
            else:  # an older library: the same from the ray distance here
                put("Depth", depth_along_axis(images["depth"][..., 0], self._frame)[..., None])
        if scene.veil.use_aov_passes:
            for name, _, _, _, key in AOV_PASSES:
                if key in images:
                    put(name, images[key])
        self.update_result(result)
        if os.environ.get("VEIL_BLENDER_TIMES"):
            print("veil_blender: passes %.3f s" % (time.perf_counter() - t0), flush=True)


def register():
    bpy.utils.register_class(VeilRenderEngine)


def unregister():
    bpy.utils.unregister_class(VeilRenderEngine)
