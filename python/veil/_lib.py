"""Finding and loading libveil.so, and the ctypes declarations of include/veil.h.

Lookup order (the first that loads wins; veil.library_path() says which):

1. the environment variable VEIL_LIBRARY: a path to libveil.so (or to the
   folder holding it);
2. the path recorded at install time in veil/_libpath.py (written by
   ``cmake --install`` and by setup.py when it records instead of copying);
3. a libveil.so* inside the package (veil/lib/, copied there by setup.py);
4. the system loader: ctypes.util.find_library("veil"), then the sonames.

A library that cannot be loaded raises ImportError naming every place tried
and why each failed.

ctypes.CDLL releases the GIL around every foreign call, so a render in one
thread lets the others run; a progress callback takes the GIL back for the
time it runs.
"""

import ctypes
import ctypes.util
import glob
import os

# ---- the C declarations (include/veil.h, include/veil/result.h) --------

VEIL_ERROR_MAX = 2048

#: result codes, as include/veil/result.h defines them (the library names
#: them too: veil_result_name)
RESULT_CODES = {
    "VEIL_OK": 0,
    "VEIL_ERR_IO": 1,
    "VEIL_ERR_PARSE": 2,
    "VEIL_ERR_INVALID": 3,
    "VEIL_ERR_OOM": 4,
    "VEIL_ERR_LIMIT": 5,
    "VEIL_ERR_GPU": 6,
    "VEIL_ERR_SHADER": 7,
    "VEIL_ERR_CANCELLED": 8,
}

VEIL_AXIS_ORDER_X_FASTEST = 0  # value(i,j,k) = data[i + nx*(j + ny*k)]: Fortran order
VEIL_AXIS_ORDER_Z_FASTEST = 1  # value(i,j,k) = data[k + nz*(j + ny*i)]: C order


class veil_error(ctypes.Structure):
    _fields_ = [("msg", ctypes.c_char * VEIL_ERROR_MAX)]


class veil_context_desc(ctypes.Structure):
    _fields_ = [("size", ctypes.c_size_t), ("force_software", ctypes.c_int), ("debug", ctypes.c_int)]


# int (*)(void* user, const char* stage, double done): non-zero cancels
PROGRESS_CALLBACK = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_char_p, ctypes.c_double)


class veil_render_desc_0_2(ctypes.Structure):
    """veil 0.2's layout: no progress callback."""

    _fields_ = [
        ("size", ctypes.c_size_t),
        ("width", ctypes.c_int),
        ("height", ctypes.c_int),
        ("step_voxels", ctypes.c_float),
        ("seed", ctypes.c_uint32),
        ("frame", ctypes.c_long),
        ("frames", ctypes.c_long),
    ]


class veil_render_desc_0_3(ctypes.Structure):
    """veil 0.3's layout: 0.2's plus the progress callback."""

    _fields_ = veil_render_desc_0_2._fields_ + [
        ("progress", PROGRESS_CALLBACK),
        ("progress_user", ctypes.c_void_p),
    ]


class veil_scene_desc(ctypes.Structure):
    """veil 0.4: a scene read with a progress callback (Ctrl-C cancels a long read)."""

    _fields_ = [
        ("size", ctypes.c_size_t),
        ("path", ctypes.c_char_p),
        ("json", ctypes.c_char_p),
        ("base_dir", ctypes.c_char_p),
        ("name", ctypes.c_char_p),
        ("progress", PROGRESS_CALLBACK),
        ("progress_user", ctypes.c_void_p),
    ]


class veil_grid_desc(ctypes.Structure):
    _fields_ = [
        ("size", ctypes.c_size_t),
        ("data", ctypes.POINTER(ctypes.c_float)),
        ("dims", ctypes.c_int * 3),
        ("axis_order", ctypes.c_int),
        ("index_to_world", ctypes.c_double * 16),
    ]


_c = ctypes
_P = ctypes.c_void_p  # every handle is opaque
_PP = ctypes.POINTER(ctypes.c_void_p)
_ERR = ctypes.POINTER(veil_error)

# name: (restype, argtypes); functions added after 0.2 are optional
_PROTOTYPES = {
    "veil_version": (_c.c_char_p, []),
    "veil_version_numbers": (None, [_c.POINTER(_c.c_int)] * 3),
    "veil_result_name": (_c.c_char_p, [_c.c_int32]),
    "veil_result_message": (_c.c_char_p, [_c.c_int32]),
    "veil_context_create": (_c.c_int32, [_c.POINTER(veil_context_desc), _PP, _ERR]),
    "veil_context_destroy": (None, [_P]),
    "veil_scene_open": (_c.c_int32, [_c.c_char_p, _PP, _ERR]),
    "veil_scene_from_json": (_c.c_int32, [_c.c_char_p, _c.c_char_p, _c.c_char_p, _PP, _ERR]),
    "veil_scene_close": (None, [_P]),
    "veil_scene_create": (_c.c_int32, [_c.POINTER(veil_scene_desc), _PP, _ERR]),
    "veil_scene_set_grid": (_c.c_int32, [_P, _c.c_char_p, _c.POINTER(veil_grid_desc), _ERR]),
    "veil_render": (_c.c_int32, [_P, _P, _P, _PP, _ERR]),  # desc: a pointer to either layout
    "veil_image_size": (None, [_P, _c.POINTER(_c.c_int), _c.POINTER(_c.c_int)]),
    "veil_image_rgba": (_c.POINTER(_c.c_float), [_P]),
    "veil_image_channel": (_c.c_int32, [_P, _c.c_char_p, _c.POINTER(_c.c_float), _ERR]),
    "veil_image_write_exr": (_c.c_int32, [_P, _c.c_char_p, _c.c_int, _ERR]),
    "veil_image_write_exr_as": (_c.c_int32, [_P, _c.c_char_p, _c.c_int, _c.c_char_p, _c.c_char_p, _ERR]),
    "veil_image_write_png": (_c.c_int32, [_P, _c.c_char_p, _c.c_float, _ERR]),
    "veil_image_stage_count": (_c.c_int, [_P]),
    "veil_image_stage": (
        _c.c_int32,
        [_P, _c.c_int, _c.POINTER(_c.c_char_p), _c.POINTER(_c.c_char_p), _c.POINTER(_c.c_double),
         _c.POINTER(_c.c_char_p)],
    ),
    "veil_image_destroy": (None, [_P]),
}
_OPTIONAL = {"veil_scene_set_grid", "veil_scene_create", "veil_image_write_exr_as"}  # veil 0.3, 0.4, 0.5 on


# ---- finding the library -------------------------------------------------

def _candidates():
    """(where it came from, path or name to load) in lookup order."""
    env = os.environ.get("VEIL_LIBRARY")
    if env:
        path = os.path.join(env, "libveil.so") if os.path.isdir(env) else env
        yield "VEIL_LIBRARY", path
        return  # an explicit choice is not second-guessed: failing to load it is an error
    here = os.path.dirname(os.path.abspath(__file__))
    try:
        from . import _libpath  # generated at install time
    except ImportError:
        _libpath = None
    recorded = getattr(_libpath, "LIBRARY", None) if _libpath else None
    if recorded:
        if not os.path.isabs(recorded):  # relative to the package (cmake --install --prefix anywhere)
            recorded = os.path.normpath(os.path.join(here, recorded))
        yield "the path recorded at install time (veil/_libpath.py)", recorded
    for path in sorted(glob.glob(os.path.join(here, "lib", "libveil.so*"))):
        yield "the copy inside the package", path
    found = ctypes.util.find_library("veil")
    if found:
        yield "the system loader (find_library)", found
    yield "the system loader", "libveil.so"


def load():
    """(the CDLL, the path or name it was loaded from); ImportError naming every try."""
    tried = []
    for origin, path in _candidates():
        try:
            lib = ctypes.CDLL(path)
        except OSError as e:
            tried.append("  %s: %s: %s" % (origin, path, e))
            continue
        missing = [n for n in _PROTOTYPES if n not in _OPTIONAL and not hasattr(lib, n)]
        if missing:
            tried.append("  %s: %s: not veil's library (no %s)" % (origin, path, ", ".join(missing)))
            continue
        for name, (restype, argtypes) in _PROTOTYPES.items():
            if hasattr(lib, name):
                fn = getattr(lib, name)
                fn.restype = restype
                fn.argtypes = argtypes
        return lib, path
    raise ImportError(
        "veil: libveil.so could not be loaded; tried, in order:\n%s\n"
        "Set VEIL_LIBRARY to a built libveil.so (build/libveil.so after `make`), install veil with "
        "`cmake --install`, or install this package with pip from the repository (docs/python.md)."
        % "\n".join(tried)
    )
