"""veil: headless volumetric rendering (smoke, fog, clouds) from Python.

A pure-Python module over libveil.so (ctypes; no compiled extension, so
every Python that can load the library can use it, Blender's included)::

    import numpy as np, veil
    d = np.zeros((32, 32, 32), np.float32)   # d[i, j, k]: the value at index (x, y, z)
    ...
    out = veil.render(scene, grids={"density": d}, size=(320, 240))
    out["rgba"]           # float32, shape (240, 320, 4), row 0 the top row

veil.render returns a dict of float32 arrays shaped H x W x C, top row
first; veil.turntable yields (frame, dict) per frame; errors raise
veil.VeilError (.code, .name, .message). docs/python.md is the manual.

The library: VEIL_LIBRARY (a path), else the path recorded at install
time, else a copy inside the package, else the system loader
(veil.library_path() says which was loaded).
"""

from . import _lib
from ._errors import Cancelled, VeilError
from ._lib import RESULT_CODES
from ._progress import STAGES
from ._render import Context, Result, close_default_context, default_context, render, turntable
from . import _render

_cdll, _path = _lib.load()
_render._Lib.lib = _cdll
_render._Lib.has_grids = hasattr(_cdll, "veil_scene_set_grid")
_render._Lib.has_scene_create = hasattr(_cdll, "veil_scene_create")


def _numbers():
    import ctypes

    v = [ctypes.c_int() for _ in range(3)]
    _cdll.veil_version_numbers(*[ctypes.byref(x) for x in v])
    return tuple(x.value for x in v)


#: the loaded library's version (veil_version()), e.g. "0.5.0"
__version__ = _cdll.veil_version().decode()
#: the same as numbers: (major, minor, patch)
version_info = _numbers()
# veil 0.3 added the progress callback fields to veil_render_desc (the layout this module then passes)
_render._Lib.has_progress = version_info[:2] >= (0, 3)


def library_path():
    """The path (or soname) libveil.so was loaded from."""
    return _path


__all__ = [
    "Cancelled",
    "Context",
    "RESULT_CODES",
    "Result",
    "STAGES",
    "VeilError",
    "close_default_context",
    "default_context",
    "library_path",
    "render",
    "turntable",
    "version_info",
]
