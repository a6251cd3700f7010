"""Grids from memory: a numpy array as an "array" source against the same values written with
pyopenvdb and read from the file, the axis order both ways, the transforms, the dtypes."""

import os

import numpy as np
import pytest

import veil
from conftest import blob, placement, scene, sphere, write_vdb

ARRAY = {"type": "array", "grid": "density"}


def assert_same_images(a, b, what):
    """Bit for bit, every output: the same library renders the same voxels, values and transform
    through the same code once the grid is read (the "array" source is a "vdb" source whose grids
    come from veil_scene_set_grid), so nothing may differ, not even by one ulp."""
    assert a.keys() == b.keys()
    for key in a:
        assert a[key].shape == b[key].shape, (what, key)
        diff = np.flatnonzero(a[key].view(np.uint32) != b[key].view(np.uint32))
        assert diff.size == 0, "%s: %s differs in %d of %d values (first at flat index %d: %r vs %r)" % (
            what, key, diff.size, a[key].size, diff[0], a[key].flat[diff[0]], b[key].flat[diff[0]])


def opaque_pixels(out):
    return int(np.count_nonzero(out["rgba"][..., 3] > 0.01))


def test_sphere_from_memory_equals_pyopenvdb_file(gl, grids_api, tmp_path):
    d = sphere()
    m = placement(0.05, d.shape[0])  # 1.55 m across, centred at the origin
    write_vdb(tmp_path / "sphere.vdb", d, m)
    from_file = veil.render(scene({"type": "vdb", "file": "sphere.vdb"}), base_dir=tmp_path)
    from_memory = veil.render(scene(ARRAY), grids={"density": (d, m)})
    assert opaque_pixels(from_file) > 200  # the ball is in view (about 27 px across at this distance)
    assert_same_images(from_memory, from_file, "array vs pyopenvdb file")


def test_source_transform_composes_with_index_to_world(gl, grids_api, tmp_path):
    """world = the source's "transform" x the grid's index_to_world, for an array as for a VDB."""
    d = sphere()
    scale = placement(0.05, d.shape[0])
    shift = np.eye(4)
    shift[:3, 3] = [0.4, 0.3, -0.2]  # a translation on top: the ball right of, above and behind the centre
    write_vdb(tmp_path / "sphere.vdb", d, shift @ scale)
    from_file = veil.render(scene({"type": "vdb", "file": "sphere.vdb"}), base_dir=tmp_path)
    # the same placement split three ways between the grid's matrix and the source's transform
    in_grid = veil.render(scene(ARRAY), grids={"density": (d, shift @ scale)})
    in_source = veil.render(scene(dict(ARRAY, transform=(shift @ scale).tolist())), grids={"density": d})
    split = veil.render(scene(dict(ARRAY, transform=shift.tolist())), grids={"density": (d, scale)})
    assert_same_images(in_grid, from_file, "index_to_world vs the file's transform")
    # a product of the two matrices rounds differently from the file's matrix only if the
    # products are inexact; these (powers of two and short decimals times 0 and 1) are exact
    assert_same_images(in_source, from_file, "source transform vs the file's transform")
    assert_same_images(split, from_file, "transform x index_to_world vs the file's transform")
    # and the ball is where the translation put it: right of centre and in the upper half
    a = from_file["rgba"][..., 3]
    rows, cols = np.nonzero(a > 0.01)
    assert cols.mean() > a.shape[1] / 2 + 3 and rows.mean() < a.shape[0] / 2 - 3


@pytest.mark.parametrize("order", ["C", "F"])
def test_axis_order(gl, grids_api, tmp_path, order):
    """a[i, j, k] is index (x, y, z) whichever way the array lies in memory: a C-ordered array goes as
    VEIL_AXIS_ORDER_Z_FASTEST, a Fortran-ordered one as X_FASTEST; both equal pyopenvdb's file."""
    d = blob()
    m = placement(0.05, d.shape)
    path = tmp_path / "blob.vdb"
    write_vdb(path, d, m)
    from_file = veil.render(scene({"type": "vdb", "file": str(path)}))
    arr = np.ascontiguousarray(d) if order == "C" else np.asfortranarray(d)
    assert arr.flags.c_contiguous == (order == "C")
    from_memory = veil.render(scene(ARRAY), grids={"density": (arr, m)})
    assert_same_images(from_memory, from_file, "%s-ordered array vs pyopenvdb file" % order)
    # the blob sits at low x (image left) and high y (image top): centre (6, 22) of (24, 32) voxels
    a = from_memory["rgba"][..., 3]
    rows, cols = np.nonzero(a > 0.01)
    assert rows.size > 20
    assert cols.mean() < a.shape[1] / 2 - 2, "the blob should be left of centre (low i = low x)"
    assert rows.mean() < a.shape[0] / 2 - 2, "the blob should be above centre (high j = high y, top row first)"


def test_swapped_axes_render_differently(gl, grids_api):
    """The tests above could not tell the axes apart if a swap rendered the same: it does not."""
    d = blob()
    m = placement(0.05, d.shape)
    right = veil.render(scene(ARRAY), grids={"density": (d, m)}, aovs=False)
    swapped_data = np.ascontiguousarray(d.transpose(2, 1, 0))  # x and z exchanged
    swapped = veil.render(scene(ARRAY), grids={"density": (swapped_data, placement(0.05, swapped_data.shape))},
                          aovs=False)
    a, b = right["rgba"][..., 3], swapped["rgba"][..., 3]
    assert np.abs(a - b).max() > 0.1
    # the swapped blob's x is the old z (30 of 40, right of centre)
    cols = np.nonzero(b > 0.01)[1]
    assert cols.mean() > b.shape[1] / 2 + 2


def test_strided_view_is_copied_in_c_order(gl, grids_api):
    d = blob()
    m = placement(0.05, d.shape)
    view = np.zeros((48, 32, 40), np.float32)[::2]  # not contiguous either way
    view[...] = d
    assert not view.flags.c_contiguous and not view.flags.f_contiguous
    assert_same_images(veil.render(scene(ARRAY), grids={"density": (view, m)}),
                       veil.render(scene(ARRAY), grids={"density": (d, m)}), "strided view vs C array")


def test_float64_is_converted_and_renders_the_same(gl, grids_api):
    d = sphere()
    m = placement(0.05, d.shape[0])
    # float32 values widened to float64 convert back exactly, so the image is the same bit for bit
    a = veil.render(scene(ARRAY), grids={"density": (d, m)})
    b = veil.render(scene(ARRAY), grids={"density": (d.astype(np.float64), m)})
    c = veil.render(scene(ARRAY), grids={"density": (d.astype(">f4"), m)})  # big-endian float32
    assert_same_images(a, b, "float64 vs float32")
    assert_same_images(a, c, "big-endian vs native float32")


@pytest.mark.parametrize("dtype", [np.int32, np.uint8, np.bool_, np.complex64, object])
def test_non_float_dtypes_are_refused(dtype):
    d = np.ones((4, 4, 4), dtype=dtype)
    with pytest.raises(TypeError, match=r"grids\['smoke'\]: dtype .* is not a floating-point type"):
        veil.render(scene(dict(ARRAY, grid="smoke")), grids={"smoke": d})


@pytest.mark.parametrize("shape", [(4, 4), (4, 4, 4, 1), (0, 4, 4)])
def test_bad_shapes_are_refused(shape):
    with pytest.raises(ValueError, match=r"grids\['density'\]"):
        veil.render(scene(ARRAY), grids={"density": np.ones(shape, np.float32)})


@pytest.mark.parametrize("matrix, match", [
    (np.eye(3), "4x4"),
    (np.diag([1.0, 1.0, 1.0, 2.0]), "last row"),
    (np.diag([1.0, 0.0, 1.0, 1.0]), "singular"),
    (np.full((4, 4), np.nan), "finite"),
])
def test_bad_index_to_world_is_refused(matrix, match):
    with pytest.raises(ValueError, match=match):
        veil.render(scene(ARRAY), grids={"density": (np.ones((4, 4, 4), np.float32), matrix)})


def test_arguments_of_the_wrong_kind_are_type_errors(tmp_path):
    """Issue 41, item 11: grids=[array] and context="x" raised AttributeError from deep inside; now TypeError
    naming the argument. A bytes output path was 'expected a .exr or .png file name'; now it is a path."""
    with pytest.raises(TypeError, match="grids: expected a dict"):
        veil.render(scene(ARRAY), grids=[sphere(8)])
    with pytest.raises(TypeError, match="context: expected a veil.Context, got str"):
        veil.render(scene(ARRAY), grids={"density": sphere(8)}, context="x")
    with pytest.raises(TypeError, match="grids: expected a dict"):
        next(veil.turntable(scene(ARRAY), 2, grids=[sphere(8)]))
    with pytest.raises(TypeError, match="output: expected a path"):
        veil.render(scene(ARRAY), grids={"density": sphere(8)}, output=3)


def test_bytes_output_path(gl, grids_api, tmp_path):
    out = veil.render(scene(ARRAY), grids={"density": sphere(8)}, output=os.fsencode(tmp_path / "b.exr"))
    assert out.path == str(tmp_path / "b.exr") and (tmp_path / "b.exr").stat().st_size > 0


def test_thin_grid_over_the_tree_limit_is_refused_at_once(grids_api):
    """Issue 41, item 11: a (1, 1, 2^28) array padded each value to an 8^3 leaf of OpenVDB's tree: 74 s and
    64 GiB to inject where a cube of as many values takes 1.8 s. Refused from its dimensions, before a value
    is read (np.zeros is not even touched), naming the grid and the numbers."""
    line = np.zeros((1, 1, 2**28), np.float32)
    with pytest.raises(veil.VeilError) as e:
        veil.render(scene(ARRAY), grids={"density": line})
    assert e.value.name == "VEIL_ERR_LIMIT" and "'density': 1x1x268435456 values" in e.value.message, e.value.message
    assert "8^3 leaves" in e.value.message


def test_grid_placed_beyond_what_veil_holds_is_refused(grids_api):
    """Issue 41, item 9: voxels under OpenVDB's floor, or finer than single precision where they lie, or a box
    beyond +-1e15 m: VEIL_ERR_INVALID naming the grid at veil_scene_set_grid (before: VEIL_ERR_IO 'cannot read
    the OpenVDB file' at the render, for a grid that never was a file)."""
    for m, says in ((np.diag([1e-6, 1e-6, 1e-6, 1.0]), "OpenVDB's maps hold"),
                    (np.array([[0.1, 0, 0, 2e15], [0, 0.1, 0, 0], [0, 0, 0.1, 0], [0, 0, 0, 1]]), "beyond the scene's"),
                    (np.array([[0.1, 0, 0, 9e14], [0, 0.1, 0, 0], [0, 0, 0.1, 0], [0, 0, 0, 1]]), "single-precision")):
        with pytest.raises(veil.VeilError) as e:
            veil.render(scene(ARRAY), grids={"density": (sphere(8), m)})
        assert e.value.name == "VEIL_ERR_INVALID" and "'density'" in e.value.message and says in e.value.message


def test_layouts_are_passed_without_a_copy():
    """float32 C and Fortran arrays reach the library as they are (no copy of a big grid)."""
    from veil import _grids, _lib

    d = blob()
    f = np.asfortranarray(d)
    g = _grids.prepare("density", d)
    assert g.values is d and g.axis_order == _lib.VEIL_AXIS_ORDER_Z_FASTEST
    g = _grids.prepare("density", f)
    assert g.values is f and g.axis_order == _lib.VEIL_AXIS_ORDER_X_FASTEST
    g = _grids.prepare("density", f.astype(np.float64, order="F"))  # converted, still Fortran: no reordering
    assert g.axis_order == _lib.VEIL_AXIS_ORDER_X_FASTEST and np.array_equal(g.values, d)


def test_unknown_grid_is_reported_by_the_library(gl, grids_api):
    with pytest.warns(UserWarning, match="'density'"):  # a grid no source reads: a warning
        with pytest.raises(veil.VeilError) as e:
            veil.render(scene(dict(ARRAY, grid="smoke")), grids={"density": sphere(8)})
    assert e.value.name == "VEIL_ERR_INVALID"
    assert "smoke" in e.value.message and "medium.sources[0]" in e.value.message


def test_non_finite_grid_value_is_reported(gl, grids_api):
    d = sphere(8)
    d[1, 2, 3] = np.inf
    with pytest.raises(veil.VeilError) as e:
        veil.render(scene(ARRAY), grids={"density": d})
    # named: the grid, and where: its index [i, j, k] as the array is indexed (C order: offset 3 + 8 (2 + 8 x 1))
    assert "'density'" in e.value.message
    assert "index [1, 2, 3] (offset 83 of 512)" in e.value.message, e.value.message


def test_emission_grid_from_memory_equals_the_file(gl, grids_api, tmp_path):
    """An emission grid is bound by name like the density: {"emission": {"grid": "heat"}} reads grids["heat"]."""
    try:
        import pyopenvdb as vdb
    except ImportError as e:
        raise ImportError("the tests write VDBs with pyopenvdb: apt-get install python3-openvdb") from e
    d = sphere()
    heat = (sphere(sigma=3.0) * 4.0).astype(np.float32)  # a hot core inside the ball
    m = placement(0.05, d.shape[0])
    grids = []
    for name, values in (("density", d), ("heat", heat)):
        g = vdb.FloatGrid()
        g.copyFromArray(values)
        g.name = name
        g.transform = vdb.createLinearTransform(m.T.tolist())
        grids.append(g)
    vdb.write(str(tmp_path / "fire.vdb"), grids=grids)
    emission = {"grid": "heat", "scale": 2.0, "color": [1.0, 0.5, 0.2]}
    from_file = veil.render(scene({"type": "vdb", "file": "fire.vdb", "grid": "density", "emission": emission}),
                            base_dir=tmp_path)
    from_memory = veil.render(scene(dict(ARRAY, emission=emission)), grids={"density": (d, m), "heat": (heat, m)})
    assert_same_images(from_memory, from_file, "density and emission arrays vs the file")
    dark = veil.render(scene(ARRAY), grids={"density": (d, m)})
    assert from_memory["single"][..., 0].max() > dark["single"][..., 0].max()  # the heat glows
