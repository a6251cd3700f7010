"""numpy grids handed to veil_scene_set_grid.

A grid is a 3-D array indexed a[i, j, k] = the value at index (x, y, z) =
(i, j, k), as pyopenvdb's copyFromArray reads it, voxel centres at integer
indices. A C-ordered array goes as VEIL_AXIS_ORDER_Z_FASTEST and a
Fortran-ordered one as VEIL_AXIS_ORDER_X_FASTEST, both without a copy when
they are float32 already; anything else is made C-contiguous float32 first.
The library copies the values, so the array may change after the call.
"""

import ctypes
import numbers

import numpy as np

from ._lib import VEIL_AXIS_ORDER_X_FASTEST, VEIL_AXIS_ORDER_Z_FASTEST, veil_grid_desc


class Grid:
    """One grid ready for the library: float32 values, their axis order, its index-to-world."""

    def __init__(self, name, values, axis_order, index_to_world):
        self.name = name
        self.values = values  # kept alive while the library copies it
        self.axis_order = axis_order
        self.index_to_world = index_to_world  # 16 floats, row-major, or None: identity

    def desc(self):
        d = veil_grid_desc()
        d.size = ctypes.sizeof(veil_grid_desc)
        d.data = self.values.ctypes.data_as(ctypes.POINTER(ctypes.c_float))
        for a in range(3):
            d.dims[a] = self.values.shape[a]
        d.axis_order = self.axis_order
        if self.index_to_world is not None:
            for n, v in enumerate(self.index_to_world):
                d.index_to_world[n] = v
        return d  # zeros: identity


def _matrix(name, m):
    label = "grids[%r]: index_to_world" % name
    try:
        a = np.asarray(m, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise TypeError("%s: expected a 4x4 matrix of numbers (%s)" % (label, e)) from None
    if a.shape != (4, 4):
        raise ValueError("%s: expected a 4x4 matrix (rows, acting on column vectors (i, j, k, 1)), got shape %s"
                         % (label, a.shape))
    if not np.all(np.isfinite(a)):
        raise ValueError("%s: every entry must be a finite number" % label)
    if not np.array_equal(a[3], [0.0, 0.0, 0.0, 1.0]):
        raise ValueError("%s: the last row must be [0, 0, 0, 1] (an affine map), got %s" % (label, a[3].tolist()))
    if abs(np.linalg.det(a[:3, :3])) == 0.0:
        raise ValueError("%s: the upper 3x3 block is singular (a voxel would have no volume)" % label)
    return [float(v) for v in a.ravel()]


def prepare(name, value):
    """Grid for grids[name] = array or (array, index_to_world 4x4)."""
    if not isinstance(name, str) or not name:
        raise TypeError("grids: a grid's name must be a non-empty string, got %r" % (name,))
    matrix = None
    if isinstance(value, tuple):
        if len(value) != 2:
            raise TypeError("grids[%r]: expected an array or a tuple (array, index_to_world 4x4), got a tuple of %d"
                            % (name, len(value)))
        value, matrix = value
    if not isinstance(value, np.ndarray):
        if isinstance(value, (list, numbers.Number)) or hasattr(value, "__array__"):
            value = np.asarray(value)
        else:
            raise TypeError("grids[%r]: expected a 3-D numpy array of floats, got %s" % (name, type(value).__name__))
    if value.dtype.kind != "f":
        raise TypeError("grids[%r]: dtype %s is not a floating-point type: a grid holds real values (density, "
                        "emission, temperature); convert it with .astype(numpy.float32)" % (name, value.dtype))
    if value.ndim != 3:
        raise ValueError("grids[%r]: expected a 3-D array indexed [i, j, k] (x, y, z), got %d-D, shape %s"
                         % (name, value.ndim, value.shape))
    if value.size == 0:
        raise ValueError("grids[%r]: the array is empty (shape %s)" % (name, value.shape))
    if any(n > np.iinfo(np.int32).max for n in value.shape):
        raise ValueError("grids[%r]: shape %s: each side must fit in a C int" % (name, value.shape))
    # float32 in native byte order; keep a Fortran layout rather than copying it into C order
    if value.dtype != np.float32 or not value.dtype.isnative:
        order = "F" if value.flags.f_contiguous and not value.flags.c_contiguous else "C"
        with np.errstate(over="ignore"):  # a float64 beyond float32's range becomes inf: veil names the voxel
            value = value.astype(np.float32, order=order)
    if value.flags.c_contiguous:
        axis = VEIL_AXIS_ORDER_Z_FASTEST
    elif value.flags.f_contiguous:
        axis = VEIL_AXIS_ORDER_X_FASTEST
    else:  # a strided view: one copy into C order
        value = np.ascontiguousarray(value)
        axis = VEIL_AXIS_ORDER_Z_FASTEST
    return Grid(name, value, axis, _matrix(name, matrix) if matrix is not None else None)
