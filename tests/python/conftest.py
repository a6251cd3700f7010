"""Shared set-up of the Python module's tests (tests/python/, run by `make test` through ctest).

The module under test is the repository's python/veil (ctest also sets
PYTHONPATH to it); the library is VEIL_LIBRARY (ctest passes the build's
libveil.so), else build/libveil.so; the CLI is VEIL_CLI, else build/veil.

GPU tests take the `gl` fixture: with no GL 4.5 context they are skipped,
and the session then exits 77 when VEIL_PYTEST_SKIP_EXIT=77 (what ctest sets:
SKIP_RETURN_CODE 77), so ctest reports the suite skipped instead of passed.
Under CI=true a missing context fails instead (a broken install).
"""

import os
import sys

import numpy as np
import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "python"))
if not os.environ.get("VEIL_LIBRARY") and os.path.exists(os.path.join(REPO, "build", "libveil.so")):
    os.environ["VEIL_LIBRARY"] = os.path.join(REPO, "build", "libveil.so")
os.environ.setdefault("VEIL_CLI", os.path.join(REPO, "build", "veil"))
os.environ.setdefault("VEIL_MAKE_ENV_MAP", os.path.join(REPO, "build", "tests", "make_env_map"))

import veil  # noqa: E402  (after the path set-up above)

_no_gl = []  # the reason, once a context could not be made


@pytest.fixture(scope="session")
def gl():
    """This thread's default context, or a skip (a failure under CI=true) when no GL 4.5 context can be made."""
    if _no_gl:
        pytest.skip(_no_gl[0])
    try:
        return veil.default_context()
    except veil.VeilError as e:
        if e.code != veil.RESULT_CODES["VEIL_ERR_GPU"]:
            raise
        if os.environ.get("CI") == "true":
            pytest.fail("no GL 4.5 context under CI=true (a broken install): %s" % e)
        _no_gl.append("no GL 4.5 context: %s" % e)
        pytest.skip(_no_gl[0])


@pytest.fixture(scope="session")
def grids_api():
    """The grids API is part of the library under test (veil 0.3): its absence fails, it is not skipped."""
    assert hasattr(veil._render._Lib.lib, "veil_scene_set_grid"), (
        "libveil.so (%s, veil %s) has no veil_scene_set_grid" % (veil.library_path(), veil.__version__))


def pytest_sessionfinish(session, exitstatus):
    if _no_gl and exitstatus == 0 and os.environ.get("VEIL_PYTEST_SKIP_EXIT") == "77":
        session.exitstatus = 77


# ---- scenes and grids shared by the tests ------------------------------------

W, H = 64, 48  # tiny images: llvmpipe renders one in well under a second at draft quality


def sphere(n=32, sigma=6.0):
    """A smooth Gaussian ball of n^3 voxels, centred in the grid, float32, C order.

    Positive in every voxel (its smallest value, in the corners, is
    exp(-3 (n-1)^2 / (8 sigma^2)) ~ 4.5e-5 for n=32, sigma=6), so a VDB made
    of it with copyFromArray keeps every voxel active and its box is the
    array's: the file and the array describe the same voxels."""
    c = (n - 1) / 2.0
    i, j, k = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    r2 = (i - c) ** 2 + (j - c) ** 2 + (k - c) ** 2
    return np.exp(-r2 / (2.0 * sigma * sigma)).astype(np.float32)


def blob(shape=(24, 32, 40), centre=(6.0, 22.0, 30.0), sigma=(3.0, 4.0, 5.0)):
    """An asymmetric grid: sides of different lengths and a Gaussian away from the centre, so that a
    swapped or mirrored axis moves it (and a transposed array does not even have the same shape)."""
    idx = np.meshgrid(*[np.arange(n) for n in shape], indexing="ij")
    e = sum((x - c) ** 2 / (2.0 * s * s) for x, c, s in zip(idx, centre, sigma))
    return np.exp(-e).astype(np.float32)


def placement(scale, n_or_shape):
    """index_to_world: voxels `scale` m apart, the grid's centre at the origin (4x4, column vectors)."""
    shape = (n_or_shape,) * 3 if np.isscalar(n_or_shape) else n_or_shape
    m = np.eye(4)
    for a in range(3):
        m[a, a] = scale
        m[a, 3] = -scale * (shape[a] - 1) / 2.0
    return m


def scene(source, size=(W, H), quality="draft", **extra):
    """A camera on +z looking at the origin (x right, y up in the image), one sun, one source."""
    s = {
        "camera": {"position": [0.0, 0.0, 4.0], "look_at": [0.0, 0.0, 0.0], "fov_y_deg": 40,
                   "width": size[0], "height": size[1]},
        "medium": {"sigma_a": [0.1, 0.1, 0.1], "sigma_s": [3.0, 3.2, 3.4], "sources": [source]},
        "lights": [{"type": "directional", "direction": [0.3, -0.8, -0.5], "irradiance": [2.0, 2.0, 2.0]}],
        "background": {"color": [0.02, 0.025, 0.03]},
        "quality": quality,
    }
    s.update(extra)
    return s


def write_vdb(path, values, index_to_world=None, name="density"):
    """The grid written with pyopenvdb, as a user would: copyFromArray (a[i, j, k] -> voxel (i, j, k)),
    the transform given as OpenVDB's row-vector matrix (the transpose of veil's column-vector one)."""
    try:
        import pyopenvdb as vdb
    except ImportError as e:  # a dependency (scripts/install-deps.sh), not an option: no skip
        raise ImportError("the tests write VDBs with pyopenvdb: apt-get install python3-openvdb (%s)" % e) from e
    g = vdb.FloatGrid()
    g.copyFromArray(values)
    g.name = name
    if index_to_world is not None:
        g.transform = vdb.createLinearTransform(np.asarray(index_to_world, dtype=float).T.tolist())
    vdb.write(str(path), grids=[g])
    return g
