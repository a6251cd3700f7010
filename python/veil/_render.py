"""veil.Context, veil.render and veil.turntable."""

import collections.abc
import ctypes
import os
import re
import threading
import warnings

import numpy as np

from . import _grids, _progress, _scene
from ._errors import Cancelled, VeilError, raise_for
from ._lib import (RESULT_CODES, veil_context_desc, veil_error, veil_render_desc_0_2, veil_render_desc_0_3,
                   veil_scene_desc)

# image channels, as veil_image_channel names them, grouped into the arrays render() returns
_AOVS = (
    ("transmittance", ("T.R", "T.G", "T.B")),
    ("density_integral", ("P",)),
    ("depth", ("depth",)),
    ("z", ("Z",)),
    ("single", ("single.R", "single.G", "single.B")),
    ("multiple_volume", ("multiple.volume.R", "multiple.volume.G", "multiple.volume.B")),
    ("multiple_screen", ("multiple.screen.R", "multiple.screen.G", "multiple.screen.B")),
)


class Result(dict):
    """render()'s answer: a dict of float32 numpy arrays, each H x W x C, top row first.

    Keys: "rgba" (C=4), and unless aovs=False "transmittance" (3),
    "density_integral" (1), "depth" (1: the mean distance of the first
    interaction along the ray, 0 where none), "z" (1: that depth along the
    view axis, +inf where no medium; needs veil 0.3), "single" (3),
    "multiple" (3: the sum of the next two), "multiple_volume" (3),
    "multiple_screen" (3).

    Attributes:
        width, height: the image size in pixels
        frame: the turntable frame rendered (0 for a still)
        stages: [(name, status, ms, why)] the library's report per stage
            ("inject", "propagate", "volumetric", "render", "spread"; status
            "ran", "cached" or "skipped")
        path: the file written (output=), else None
    """

    width = height = frame = 0
    stages = ()
    path = None


class _Lib:
    """The loaded library and what it supports (set by veil/__init__.py)."""

    lib = None
    has_grids = False
    has_progress = False
    has_scene_create = False


def _err():
    return veil_error()


def _check(code, err):
    raise_for(_Lib.lib, code, err)


class Context:
    """A veil context: a headless OpenGL 4.5 context and the stage results veil
    keeps between renders (a turntable of one scene injects and propagates once).

    Use it only from the thread that created it (OpenGL's rule): another
    thread's call raises VeilError (VEIL_ERR_GPU) naming both threads.
    veil.render() without context= uses one context per thread, made on
    first use and kept.

    Context(force_software=False, debug=False); close() releases it (so does
    `with veil.Context() as ctx:`). VeilError VEIL_ERR_GPU when no GL 4.5
    context can be made.
    """

    def __init__(self, force_software=False, debug=False):
        lib = _Lib.lib
        self._handle = None
        self._rendering = False  # inside veil_render: close() is refused (a progress callback's)
        self._thread = threading.get_ident()
        self._thread_name = threading.current_thread().name
        desc = veil_context_desc(ctypes.sizeof(veil_context_desc), 1 if force_software else 0, 1 if debug else 0)
        handle = ctypes.c_void_p()
        err = _err()
        _check(lib.veil_context_create(ctypes.byref(desc), ctypes.byref(handle), ctypes.byref(err)), err)
        self._handle = handle
        self._destroy = lib.veil_context_destroy  # kept for __del__ at interpreter exit

    def _use(self):
        if self._handle is None:
            raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"], "veil.Context: used after close()")
        if threading.get_ident() != self._thread:
            raise VeilError(
                RESULT_CODES["VEIL_ERR_GPU"],
                "veil.Context: created on thread %r, used on thread %r: a context (an OpenGL context) is "
                "used only from the thread that created it; make one per thread, or call veil.render() "
                "without context= (one context per thread)" % (self._thread_name, threading.current_thread().name))
        return self._handle

    @property
    def closed(self):
        return self._handle is None

    def close(self):
        """Releases the GL context and everything veil kept on it (from its own thread)."""
        if self._handle is None:
            return
        self._use()
        if self._rendering:
            raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"],
                            "veil.Context.close: the context is rendering (this call came from its render's progress "
                            "callback): close it once render() has returned")
        handle, self._handle = self._handle, None
        self._destroy(handle)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def __del__(self):
        # on another thread veil frees what it can and leaves the GL objects to the driver (veil.h)
        handle, self._handle = getattr(self, "_handle", None), None
        if handle is not None and getattr(self, "_destroy", None) is not None:
            self._destroy(handle)

    def __repr__(self):
        return "<veil.Context %s, thread %r>" % ("closed" if self.closed else "open", self._thread_name)

    def render(self, scene, **kwargs):
        """veil.render(scene, ..., context=self): see veil.render."""
        return render(scene, context=self, **kwargs)

    def turntable(self, scene, frames, **kwargs):
        """veil.turntable(scene, frames, ..., context=self): see veil.turntable."""
        return turntable(scene, frames, context=self, **kwargs)


_per_thread = threading.local()


def default_context():
    """This thread's context, made on first use and kept (veil.render without context=)."""
    ctx = getattr(_per_thread, "context", None)
    if ctx is None or ctx.closed:
        ctx = Context()
        _per_thread.context = ctx
    return ctx


def close_default_context():
    """Releases this thread's default context (the next render makes a new one)."""
    ctx = getattr(_per_thread, "context", None)
    _per_thread.context = None
    if ctx is not None:
        ctx.close()


# ---- one scene handle with its grids ---------------------------------------

def _raise_from_bridge(bridge, code, err):
    """After a veil call with a progress bridge: the callback's own exception (or Ctrl-C's) with veil's
    error as its context, or veil.Cancelled when it returned False; else nothing."""
    lib = _Lib.lib
    if bridge.interrupted and bridge.raised is None:
        bridge.raised = KeyboardInterrupt()
    if bridge.raised is not None:
        exc = bridge.raised
        try:
            if code != 0:
                raise_for(lib, code, err)
        except VeilError as veil_exc:
            exc.__context__ = veil_exc
        raise exc
    if code == 0 and bridge.cancelled:
        # cancelled at the very end: veil made the result anyway; what was asked is honoured
        raise Cancelled(RESULT_CODES["VEIL_ERR_CANCELLED"], "the progress callback returned False")


def _open_scene(st, progress):
    """veil_scene_create (veil 0.4: Ctrl-C and progress returning False cancel a long read, such as an 8K
    environment map's), else veil_scene_open / veil_scene_from_json. The callable progress sees the read
    as the inject stage at 0 (veil.STAGES has no stage of its own for it)."""
    lib = _Lib.lib
    handle = ctypes.c_void_p()
    err = _err()
    if _Lib.has_scene_create:
        fn = progress if callable(progress) else None
        bridge = _progress.Bridge((lambda stage, done: fn("inject", 0.0)) if fn is not None else None)
        desc = veil_scene_desc()
        desc.size = ctypes.sizeof(desc)
        if st.path is not None:
            desc.path = os.fsencode(st.path)
        else:
            desc.json = st.text.encode("utf-8")
            desc.base_dir = os.fsencode(st.base_dir) if st.base_dir is not None else None
            desc.name = st.name.encode("utf-8")
        desc.progress = bridge.c_callback
        with bridge.interrupts():
            code = lib.veil_scene_create(ctypes.byref(desc), ctypes.byref(handle), ctypes.byref(err))
        try:
            _raise_from_bridge(bridge, code, err)
        except BaseException:
            if code == 0:
                lib.veil_scene_close(handle)
            raise
    elif st.path is not None:
        code = lib.veil_scene_open(os.fsencode(st.path), ctypes.byref(handle), ctypes.byref(err))
    else:
        code = lib.veil_scene_from_json(st.text.encode("utf-8"),
                                        os.fsencode(st.base_dir) if st.base_dir is not None else None,
                                        st.name.encode("utf-8"), ctypes.byref(handle), ctypes.byref(err))
    _check(code, err)
    return handle


class _Scene:
    def __init__(self, scene, grids, quality, base_dir, progress=None):
        lib = _Lib.lib
        self.handle = None
        st = _scene.prepare(scene, quality, base_dir)
        self.name = st.path or st.name
        self.file = st.file  # the scene's file (libveil knows it only when it opened the file itself)
        prepared = [_grids.prepare(name, value) for name, value in (grids or {}).items()]
        if prepared and not _Lib.has_grids:
            raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"],
                            "grids: the loaded libveil.so (veil %s) has no veil_scene_set_grid: grids from memory "
                            "need veil 0.3 or later" % lib.veil_version().decode())
        self.handle = _open_scene(st, progress)
        err = _err()
        if st.unparsed is not None:  # veil read it; Python's json could not, so the override was not applied
            self.close()
            raise VeilError(RESULT_CODES["VEIL_ERR_PARSE"],
                            "%s: quality= needs the scene as JSON Python reads too: %s" % (st.name, st.unparsed))
        if prepared:
            self._warn_unused(st, prepared)
        for g in prepared:
            desc = g.desc()
            code = lib.veil_scene_set_grid(self.handle, g.name.encode("utf-8"), ctypes.byref(desc), ctypes.byref(err))
            if code != 0:
                self.close()
                _check(code, err)

    @staticmethod
    def _warn_unused(st, prepared):
        data = st.data
        if data is None and st.path is not None:
            try:
                with open(st.path, "rb") as f:
                    data = _scene._strict_loads(f.read().decode("utf-8"))
            except (OSError, ValueError, UnicodeDecodeError):
                return
        if not isinstance(data, dict):
            return
        used = _scene.grid_names(data)
        unused = sorted(g.name for g in prepared if g.name not in used)
        if unused:
            warnings.warn("veil: grid%s %s: no \"array\" source of %s reads %s (its \"grid\", or its emission's or "
                          "temperature's \"grid\")" % ("" if len(unused) == 1 else "s", ", ".join(map(repr, unused)),
                                                       st.path or st.name, "it" if len(unused) == 1 else "them"),
                          stacklevel=4)

    def close(self):
        if self.handle is not None:
            _Lib.lib.veil_scene_close(self.handle)
            self.handle = None

    def __del__(self):
        self.close()


# ---- render ------------------------------------------------------------------

def _size(size):
    if size is None:
        return 0, 0
    try:
        w, h = size
    except (TypeError, ValueError):
        raise TypeError("size: expected (width, height), got %r" % (size,)) from None
    for label, v in (("width", w), ("height", h)):
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)) or not 1 <= v <= 16384:
            raise ValueError("size: %s %r is not an integer in 1..16384" % (label, v))
    return int(w), int(h)


def _image_arrays(img, aovs):
    lib = _Lib.lib
    w, h = ctypes.c_int(), ctypes.c_int()
    lib.veil_image_size(img, ctypes.byref(w), ctypes.byref(h))
    w, h = w.value, h.value
    out = Result()
    out.width, out.height = w, h
    rgba = lib.veil_image_rgba(img)
    out["rgba"] = np.ctypeslib.as_array(rgba, shape=(h, w, 4)).copy()  # top row first, as veil keeps it
    if aovs:
        err = _err()
        for key, names in _AOVS:
            if key == "z" and not _Lib.has_progress:  # Z came with veil 0.3, as the progress callback did
                continue
            planes = np.empty((len(names), h, w), dtype=np.float32)
            for c, name in enumerate(names):
                ptr = planes[c].ctypes.data_as(ctypes.POINTER(ctypes.c_float))
                _check(lib.veil_image_channel(img, name.encode(), ptr, ctypes.byref(err)), err)
            out[key] = np.ascontiguousarray(np.moveaxis(planes, 0, -1))
        out["multiple"] = out["multiple_volume"] + out["multiple_screen"]
    stages = []
    for i in range(lib.veil_image_stage_count(img)):
        name, status, why = ctypes.c_char_p(), ctypes.c_char_p(), ctypes.c_char_p()
        ms = ctypes.c_double()
        if lib.veil_image_stage(img, i, ctypes.byref(name), ctypes.byref(status), ctypes.byref(ms),
                                ctypes.byref(why)) == 0:
            stages.append(tuple(v.value.decode("utf-8", "replace") if v.value else "" for v in (name, status))
                          + (ms.value, why.value.decode("utf-8", "replace") if why.value else ""))
    out.stages = stages
    return out


_EXR_TYPES = ("float", "half")
_EXR_COMPRESSIONS = ("zip", "none", "rle", "zips", "piz", "pxr24", "b44", "b44a", "dwaa", "dwab")


def _exr_format(exr):
    """exr= checked: None, or a dict {"type": "float"|"half", "compression": NAME} (each key optional), as
    (type, compression) with None for a key left out."""
    if exr is None:
        return None
    if not isinstance(exr, collections.abc.Mapping):
        raise TypeError("exr: expected a dict such as {\"type\": \"half\", \"compression\": \"dwaa\"}, got %s"
                        % type(exr).__name__)
    unknown = sorted(set(exr) - {"type", "compression"})
    if unknown:
        raise ValueError("exr: unknown key %r (the keys are \"type\" and \"compression\")" % unknown[0])
    kind, comp = exr.get("type"), exr.get("compression")
    if kind is not None and kind not in _EXR_TYPES:
        raise ValueError("exr: type %r: expected \"float\" or \"half\"" % (kind,))
    if comp is not None and comp not in _EXR_COMPRESSIONS:
        raise ValueError("exr: compression %r: expected one of %s" % (comp, ", ".join(_EXR_COMPRESSIONS)))
    if not hasattr(_Lib.lib, "veil_image_write_exr_as"):
        raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"], "exr: the loaded libveil.so (veil %s) writes only float ZIP "
                        "EXRs: the type and compression need veil 0.5 or later" % _Lib.lib.veil_version().decode())
    return kind, comp


def _write(img, path, aovs, exposure, exr=None):
    lib = _Lib.lib
    err = _err()
    ext = os.path.splitext(os.fspath(path))[1].lower()
    p = os.fsencode(path)
    if ext == ".exr" and exr is not None:
        code = lib.veil_image_write_exr_as(img, p, 1 if aovs else 0, exr[0].encode() if exr[0] else None,
                                           exr[1].encode() if exr[1] else None, ctypes.byref(err))
    elif ext == ".exr":
        code = lib.veil_image_write_exr(img, p, 1 if aovs else 0, ctypes.byref(err))
    elif ext == ".png":
        code = lib.veil_image_write_png(img, p, ctypes.c_float(exposure), ctypes.byref(err))
    else:
        raise ValueError("output: %s: expected a .exr or .png file name" % os.fspath(path))
    _check(code, err)


def _check_not_scene(output, scene_file):
    """The scene's own file is never written over (libveil refuses its other inputs: veil.h)."""
    try:
        same = scene_file is not None and os.path.samefile(output, scene_file)
    except OSError:  # one of them is not there: nothing to lose
        same = False
    if same:
        raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"], "output: '%s' is the scene '%s', which the render read: it "
                        "would be overwritten" % (os.fsdecode(os.fspath(output)), os.fsdecode(os.fspath(scene_file))))


def _check_arguments(grids, context):
    """TypeError for a grids or context argument of the wrong kind (before: AttributeError from deep inside)."""
    if grids is not None and not isinstance(grids, collections.abc.Mapping):
        raise TypeError("grids: expected a dict {name: array, or (array, index_to_world)}, got %s"
                        % type(grids).__name__)
    if context is not None and not isinstance(context, Context):
        raise TypeError("context: expected a veil.Context, got %s" % type(context).__name__)


def _output_path(output):
    """output= as a str path (a bytes or os.PathLike one decoded as the file system does), or None."""
    if output is None:
        return None
    try:
        return os.fsdecode(os.fspath(output))
    except TypeError:
        raise TypeError("output: expected a path (str, bytes or os.PathLike), got %s" % type(output).__name__) from None


def _check_output(output):
    if output is None:
        return
    ext = os.path.splitext(os.fspath(output))[1].lower()
    if ext not in (".exr", ".png"):
        raise ValueError("output: %s: expected a .exr or .png file name" % os.fspath(output))


def _number(label, v, lo, hi, integer=False):
    if isinstance(v, bool) or not isinstance(v, (int, np.integer) if integer else (int, float, np.integer,
                                                                                    np.floating)):
        raise TypeError("%s: expected %s, got %r" % (label, "an integer" if integer else "a number", v))
    if not (lo <= v <= hi):  # a NaN fails too
        raise ValueError("%s: %r is outside %s..%s" % (label, v, lo, hi))
    return v


class _FrameWriter:
    """A turntable's frames written on a thread of their own while the next renders (issue 42): at most one
    frame in flight (put waits for the one before), libveil's writers release the GIL and stage each file
    beside its target (renamed into place when whole), so a frame is either whole or absent."""

    def __init__(self):
        self._thread = None
        self._error = None

    def wait(self):
        """Waits for the frame in flight; its write's exception, if it failed."""
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        if self._error is not None:
            exc, self._error = self._error, None
            raise exc

    def raise_if_failed(self):
        """The last frame's write error, if it has failed already (before rendering another for nothing)."""
        if self._thread is not None and not self._thread.is_alive():
            self.wait()

    def put(self, img, path, aovs, exposure, exr=None):
        """Writes img to path on the writer's thread and destroys it there."""
        self.wait()

        def run():
            try:
                _write(img, path, aovs, exposure, exr)
            except BaseException as exc:  # raised on the caller's thread by the next wait
                self._error = exc
            finally:
                _Lib.lib.veil_image_destroy(img)

        self._thread = threading.Thread(target=run, name="veil frame writer")
        self._thread.start()


def _render_one(ctx, scn, width, height, seed, step_voxels, frame, frames, progress, output, aovs, exposure,
                writer=None, exr=None):
    lib = _Lib.lib
    handle = ctx._use()
    fn, close_bar = _progress.resolve(progress, "frame %d: " % frame if frames > 1 else "")
    if _Lib.has_progress:
        desc = veil_render_desc_0_3()
        bridge = _progress.Bridge(fn)  # always: Ctrl-C cancels the render through it
        desc.progress = bridge.c_callback
    else:
        if fn is not None:
            raise VeilError(RESULT_CODES["VEIL_ERR_INVALID"],
                            "progress: the loaded libveil.so (veil %s) has no progress callback: it needs veil 0.3 "
                            "or later" % lib.veil_version().decode())
        desc = veil_render_desc_0_2()
        bridge = None
    desc.size = ctypes.sizeof(desc)
    desc.width, desc.height = width, height
    desc.step_voxels = step_voxels
    desc.seed = seed
    desc.frame, desc.frames = frame, frames
    img = ctypes.c_void_p()
    err = _err()
    ctx._rendering = True
    try:
        if bridge is not None:
            with bridge.interrupts():
                code = lib.veil_render(handle, scn.handle, ctypes.byref(desc), ctypes.byref(img), ctypes.byref(err))
        else:
            code = lib.veil_render(handle, scn.handle, ctypes.byref(desc), ctypes.byref(img), ctypes.byref(err))
    finally:
        ctx._rendering = False
        if close_bar is not None:
            close_bar()
    try:
        if bridge is not None:
            _raise_from_bridge(bridge, code, err)
        _check(code, err)
        out = _image_arrays(img, aovs)
        out.frame = frame
        if output is not None:
            _check_not_scene(output, scn.file)
            if writer is not None:
                writer.put(img, output, aovs, exposure, exr)
                img = None  # the writer's now: it destroys it
            else:
                _write(img, output, aovs, exposure, exr)
            out.path = os.fspath(output)
        return out
    finally:
        if img is not None:
            lib.veil_image_destroy(img)


def render(scene, grids=None, quality=None, size=None, seed=0, step_voxels=None, frame=0, frames=0,
           progress=None, context=None, base_dir=None, output=None, aovs=True, exposure=0.0, exr=None):
    """Renders a scene; returns a dict of float32 numpy arrays, each H x W x C, top row first.

    scene: a dict (the scene format of docs/scene-format.md), JSON text, or a
        path (str or os.PathLike) to a .json file, whose relative paths then
        resolve against the file's folder and whose errors name the file.
    grids: {name: array} or {name: (array, index_to_world)}: the values of
        the scene's "array" sources (a source {"type": "array", "grid": name}
        reads grids[name]). An array is 3-D, indexed a[i, j, k] = the value
        at index (x, y, z) = (i, j, k) as pyopenvdb's copyFromArray does,
        voxel centres at integer indices; float32 (other float dtypes are
        converted; integer, bool, complex and object arrays raise TypeError);
        C- or Fortran-ordered, neither copied when float32. index_to_world:
        4x4, row-major, acting on column vectors (i, j, k, 1), last row
        0 0 0 1; without it voxels are 1 m cubes at integer positions. A
        source's "transform" then maps that world: world = transform x
        index_to_world. veil copies the values.
    quality: "draft", "default", "high" or "max": replaces the scene's "quality".
    size: (width, height) in pixels; None: the scene camera's.
    seed: the jitter seed (the same seed renders the same image).
    step_voxels: the ray-march step in voxels; None: the quality's.
    frame, frames: frames > 1 renders frame `frame` of a turntable of
        `frames` (one turn about the camera's up axis; veil.turntable loops).
    progress: callable(stage, done) -> None or False; False cancels (see
        veil.Cancelled); True or "tqdm": a tqdm bar (True without tqdm: a line
        per stage on stderr). Ctrl-C cancels a render whatever this is.
    context: a veil.Context; None: this thread's default context.
    base_dir: the folder relative paths in the scene resolve against (a dict
        or JSON text: the current folder; a file: its folder).
    output: a .exr or .png path written when the render succeeded (an EXR
        all or nothing, with the AOV channels when aovs is true; a PNG an
        8-bit sRGB preview scaled by 2**exposure). Nothing is written, and
        an existing file is left as it was, when the render fails or is
        cancelled.
    aovs: False returns "rgba" only (and writes an EXR of R, G, B, A only).
    exr: how an EXR output stores its pixels, as Blender's and Nuke's EXR
        outputs offer: {"type": "float" or "half", "compression": "zip",
        "none", "rle", "zips", "piz", or the lossy "pxr24", "b44", "b44a",
        "dwaa", "dwab"}; None (or a key left out): float, zip. In a half
        file the distances ("depth", Z) and P stay float. (veil 0.5)

    Returns a dict (veil.Result, with .width, .height, .stages, .path) of
    numpy float32 arrays of shape (height, width, C), row 0 the top row:
        "rgba" (4: linear radiance and A = 1 - mean transmittance),
        "transmittance" (3), "density_integral" (1: density x m along the
        pixel's ray), "depth" (1: mean distance of the first interaction,
        m; 0 where no medium), "single" (3: single scattering),
        "multiple" (3) = "multiple_volume" (3) + "multiple_screen" (3).
        rgba = transmittance x background + single + multiple.

    Raises veil.VeilError (.code, .name, .message: the file and JSON field),
    veil.Cancelled when cancelled, TypeError/ValueError for bad arguments.
    """
    _check_arguments(grids, context)
    output = _output_path(output)
    if context is not None:
        context._use()
    width, height = _size(size)
    seed = _number("seed", seed, 0, 2**32 - 1, integer=True)
    step = 0.0 if step_voxels is None else float(_number("step_voxels", step_voxels, 1e-6, 1e6))
    frames = _number("frames", frames, 0, 2**31 - 1, integer=True)
    frame = _number("frame", frame, 0, max(frames - 1, 0), integer=True)
    _check_output(output)
    exr = _exr_format(exr)
    _progress.check(progress)
    scn = _Scene(scene, grids, quality, base_dir, progress)  # a bad scene is reported before any GL work
    try:
        ctx = context if context is not None else default_context()
        return _render_one(ctx, scn, width, height, int(seed), step, int(frame), int(frames), progress, output,
                           aovs, exposure, exr=exr)
    finally:
        scn.close()


def _frame_path(output, frame):
    text = os.fspath(output)
    runs = list(re.finditer(r"#+", os.path.basename(text)))
    if len(runs) != 1:
        raise ValueError("output: %s: a turntable's output names its frame number with one run of '#' "
                         "(frame.####.exr)" % text)
    m = runs[0]
    base = os.path.basename(text)
    name = base[:m.start()] + str(frame).zfill(len(m.group())) + base[m.end():]
    return os.path.join(os.path.dirname(text), name)


def turntable(scene, frames, grids=None, quality=None, size=None, seed=0, step_voxels=None, progress=None,
              context=None, base_dir=None, output=None, aovs=True, exposure=0.0, start=0, stop=None, exr=None):
    """Yields (frame, dict) for frames start..stop-1 of a turntable of `frames` frames.

    One full turn about the camera's up axis through its look-at point, in
    `frames` equal steps (frame 0: the scene's camera). The scene is read
    once and every frame renders with one context, so the medium is injected
    and its lights propagated once. output: a path with one run of '#'
    replaced by the zero-padded frame number ("out/frame.####.exr"); each
    frame's file is written on a thread of its own while the next frame
    renders: it is whole once the next frame is yielded or the generator
    ends (a file is never there half-written), and a failed write raises
    then. Every
    other argument and the dicts are as veil.render's. A generator: frames
    render as they are asked for; closing it early releases the scene.
    """
    _check_arguments(grids, context)
    output = _output_path(output)
    frames = _number("frames", frames, 1, 2**31 - 1, integer=True)
    start = _number("start", start, 0, frames - 1, integer=True)
    stop = frames if stop is None else _number("stop", stop, start, frames, integer=True)
    if output is not None:
        _check_output(output)
        _frame_path(output, 0)
    _progress.check(progress)
    exr = _exr_format(exr)
    if context is not None:
        context._use()
    width, height = _size(size)
    seed = _number("seed", seed, 0, 2**32 - 1, integer=True)
    step = 0.0 if step_voxels is None else float(_number("step_voxels", step_voxels, 1e-6, 1e6))
    return _turntable(context, scene, grids, quality, base_dir, width, height, int(seed), step, int(frames), int(start),
                      int(stop), progress, output, aovs, exposure, exr)


def _turntable(ctx, scene, grids, quality, base_dir, width, height, seed, step, frames, start, stop, progress,
               output, aovs, exposure, exr):
    scn = _Scene(scene, grids, quality, base_dir, progress)
    writer = _FrameWriter() if output is not None else None
    try:
        ctx = ctx if ctx is not None else default_context()
        for f in range(start, stop):
            path = _frame_path(output, f) if output is not None else None
            if writer is not None:
                writer.raise_if_failed()
            yield f, _render_one(ctx, scn, width, height, seed, step, f, frames, progress, path, aovs, exposure,
                                 writer, exr)
        if writer is not None:
            writer.wait()  # the last frame whole before the generator ends
    finally:
        try:
            if writer is not None:
                writer.wait()
        finally:
            scn.close()


def _close_main_default():
    """At exit: the main thread's default context goes while the library is still whole."""
    try:
        close_default_context()
    except VeilError:
        pass


import atexit  # noqa: E402

atexit.register(_close_main_default)
