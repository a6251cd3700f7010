"""veil.render and veil.turntable: the outputs' shapes and order, scenes as dicts, text and files,
errors with their file and field, the files written, the contexts and their threads."""

import json
import os
import subprocess
import threading

import numpy as np
import pytest

import veil
from conftest import H, W, placement, scene, sphere, write_vdb

CHANNELS = {"rgba": 4, "transmittance": 3, "density_integral": 1, "depth": 1, "z": 1, "single": 3, "multiple": 3,
            "multiple_volume": 3, "multiple_screen": 3}


def top_slab(tmp_path):
    """A VDB whose medium lies only above y = 0 (m): the image's top half."""
    d = np.zeros((32, 32, 32), np.float32)
    d[:, 16:, :] = 1.0  # j >= 16: y >= 0.1 * (16 - 15.5) = 0.05 m; the box reaches y, z = +-1.55 m
    write_vdb(tmp_path / "slab.vdb", d, placement(0.1, 32))
    return scene({"type": "vdb", "file": "slab.vdb"})


def test_outputs_shapes_dtypes_and_top_row_first(gl, tmp_path):
    out = veil.render(top_slab(tmp_path), base_dir=tmp_path)
    assert set(out) == set(CHANNELS)
    for key, c in CHANNELS.items():
        a = out[key]
        assert a.dtype == np.float32 and a.shape == (H, W, c) and a.flags.c_contiguous, key
        if key != "z":  # Z is +inf where no medium
            assert np.all(np.isfinite(a)), key
    assert (out.width, out.height) == (W, H)
    alpha = out["rgba"][..., 3]
    # At 4 m with a 40 degree field of view, row r's ray climbs s = tan(20 deg) (1 - (r + 1/2) / 24) m per
    # metre: rows 0..22 enter the slab (y > 0.05 m within its z range, 2.45..5.55 m away), and the
    # trilinear ramp between voxels 15 and 16 reaches down to y = -0.05 m, which rows below 27
    # (s < -0.05 / 2.45) never meet. So: the top quarter opaque, the bottom 20 rows empty, exactly.
    assert alpha[: H // 4].min() > 0.5, "the medium is above the centre: row 0 (the top row) must be opaque"
    assert alpha[28:].max() == 0.0, "the bottom rows meet no medium: alpha exactly 0"
    assert np.all(out["depth"][28:] == 0.0) and out["depth"][: H // 4].min() > 2.0  # m from the camera
    assert np.all(out["transmittance"][28:] == 1.0)
    # Z: the depth along the view axis, +inf where no medium; elsewhere depth x cos of the pixel's ray, so
    # at most the depth and at least depth x cos(the corner's angle): tan(20 deg) up, aspect W/H across
    z, depth = out["z"][..., 0], out["depth"][..., 0]
    assert np.all(np.isposinf(z[depth == 0.0])) and not np.any(np.isinf(z[depth > 0.0]))
    t = np.tan(np.radians(20.0))
    cos_corner = 1.0 / np.sqrt(1.0 + t * t * (1.0 + (W / H) ** 2))
    hit = depth > 0.0
    assert np.all(z[hit] <= depth[hit] * (1 + 2.0 ** -22)) and np.all(z[hit] >= depth[hit] * cos_corner * (1 - 2.0 ** -22))
    # the outputs compose as veil.h says: rgba = T x background + single + multiple.volume + multiple.screen.
    # Four float32 terms summed on the GPU in its own order: each addition rounds by at most half an
    # ulp of the partial sum, so |rgba - sum| <= 3 * 2^-24 * (sum of the terms' magnitudes); 4 ulp here.
    bg = np.array([0.02, 0.025, 0.03], np.float32)
    terms = [out["transmittance"] * bg, out["single"], out["multiple_volume"], out["multiple_screen"]]
    bound = 4 * 2.0 ** -24 * sum(np.abs(t) for t in terms) + 1e-30
    assert np.all(np.abs(out["rgba"][..., :3] - sum(terms)) <= bound)
    np.testing.assert_array_equal(out["multiple"], out["multiple_volume"] + out["multiple_screen"])
    assert out["multiple_volume"][: H // 4].max() > 0  # the volumetric estimate ran
    # alpha is 1 - mean transmittance (float32 rounding of a mean of 3 and a subtraction: 2 ulp of 1)
    assert np.all(np.abs(alpha - (1 - out["transmittance"].mean(axis=2))) <= 2 * 2.0 ** -24 * 2)
    names = [s[0] for s in out.stages]
    assert names == list(veil.STAGES)


def test_aovs_false_gives_rgba_only(gl):
    out = veil.render(scene({"type": "exponential", "density": 0.5, "falloff": 1.0, "origin": [0, 0, 0],
                             "direction": [0, 1, 0], "bounds": [[-1, -1, -1], [1, 1, 1]]}), aovs=False)
    assert list(out) == ["rgba"] and out["rgba"].shape == (H, W, 4)


def test_scene_as_dict_json_text_and_file_agree(gl, tmp_path):
    s = scene({"type": "rbf", "particles": [{"center": [0, 0, 0], "amplitude": 2.0, "sharpness": 2.0}]})
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(s))
    a = veil.render(s)
    b = veil.render(json.dumps(s))
    c = veil.render(path)  # os.PathLike
    d = veil.render(str(path))
    for other in (b, c, d):
        np.testing.assert_array_equal(a["rgba"], other["rgba"])
    assert a["rgba"][..., 3].max() > 0.3


def test_quality_and_size_override(gl, tmp_path):
    s = scene({"type": "rbf", "particles": [{"center": [0, 0, 0], "amplitude": 2.0, "sharpness": 2.0}]},
              quality="default")
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(s))
    out = veil.render(path, quality="draft", size=(40, 30))
    assert out["rgba"].shape == (30, 40, 4)
    render_why = dict((st[0], st[3]) for st in out.stages)["render"]
    assert "quality draft" in render_why, render_why  # the override reached the library
    assert json.loads(path.read_text())["quality"] == "default"  # the file is not touched
    with pytest.raises(ValueError, match="quality"):
        veil.render(path, quality="ultra")
    with pytest.raises(ValueError, match="size"):
        veil.render(path, size=(0, 30))


def valid_scene():
    return scene({"type": "rbf", "particles": [{"center": [0, 0, 0], "amplitude": 1.0, "sharpness": 2.0}]})


def test_bad_field_names_its_path():
    s = valid_scene()
    s["camera"]["fov_y_deg"] = "x"
    with pytest.raises(veil.VeilError) as e:
        veil.render(s)
    err = e.value
    assert err.name in ("VEIL_ERR_PARSE", "VEIL_ERR_INVALID") and err.code == veil.RESULT_CODES[err.name]
    assert "camera.fov_y_deg" in err.message and "<scene dict>" in err.message
    assert str(err).startswith(err.name + ": ")


def test_bad_file_names_the_file(tmp_path):
    s = valid_scene()
    s["lights"][0]["irradiance"] = "red"
    path = tmp_path / "bad_light.json"
    path.write_text(json.dumps(s))
    for kwargs in ({}, {"quality": "draft"}):  # read by veil, or by Python first for the override
        with pytest.raises(veil.VeilError) as e:
            veil.render(path, **kwargs)
        assert str(path) in e.value.message and "lights[0].irradiance" in e.value.message
    path.write_text('{"camera": {')  # malformed JSON: veil's parser says so, naming the file
    with pytest.raises(veil.VeilError) as e:
        veil.render(path, quality="draft")
    assert e.value.name == "VEIL_ERR_PARSE" and str(path) in e.value.message


def test_missing_scene_file_and_missing_vdb(tmp_path):
    with pytest.raises(veil.VeilError) as e:
        veil.render(tmp_path / "nowhere.json")
    assert e.value.name == "VEIL_ERR_IO" and "nowhere.json" in e.value.message
    with pytest.raises(veil.VeilError) as e:
        veil.render(scene({"type": "vdb", "file": "missing_smoke.vdb"}), base_dir=tmp_path)
    assert "missing_smoke.vdb" in e.value.message and "medium.sources[0].file" in e.value.message


def test_non_finite_number_in_a_dict_names_its_path():
    s = valid_scene()
    s["camera"]["position"][1] = float("nan")
    with pytest.raises(veil.VeilError) as e:
        veil.render(s)
    assert "camera.position[1]" in e.value.message and "nan" not in e.value.message.lower()


def test_numpy_values_inside_a_scene_dict(gl):
    s = valid_scene()
    s["camera"]["position"] = np.array([0.0, 0.0, 4.0])
    s["camera"]["fov_y_deg"] = np.float32(40)
    np.testing.assert_array_equal(veil.render(s)["rgba"], veil.render(valid_scene())["rgba"])


def test_output_files_and_the_cli(gl, tmp_path):
    """output= writes what `veil render` writes for the same scene, size and seed."""
    d = sphere()
    write_vdb(tmp_path / "sphere.vdb", d, placement(0.05, 32))
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene({"type": "vdb", "file": "sphere.vdb"})))
    out = veil.render(path, output=tmp_path / "module.png")
    assert out.path == str(tmp_path / "module.png")
    veil.render(path, output=tmp_path / "module.exr")
    cli = os.environ["VEIL_CLI"]
    if not os.access(cli, os.X_OK):
        pytest.fail("VEIL_CLI=%s is not the veil tool (ctest sets it; build/veil otherwise)" % cli)
    run = subprocess.run([cli, "render", str(path), "-o", str(tmp_path / "cli.exr"), "--png",
                          str(tmp_path / "cli.png"), "--aovs"], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    # the same 8-bit preview, byte for byte (same library code, same pixels, same encoder)
    assert (tmp_path / "module.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert (tmp_path / "module.exr").stat().st_size > 0
    with pytest.raises(ValueError, match=".tif"):
        veil.render(path, output=tmp_path / "out.tif")


def test_failed_render_writes_nothing(gl, grids_api, tmp_path):
    """A render that fails (here in veil_render: a source reads a grid never given) leaves output alone."""
    target = tmp_path / "keep.exr"
    target.write_bytes(b"an earlier frame")
    with pytest.raises(veil.VeilError) as e:
        veil.render(scene({"type": "array", "grid": "smoke"}), output=target)
    assert "smoke" in e.value.message
    assert target.read_bytes() == b"an earlier frame"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.exr"]


def test_output_never_overwrites_an_input(gl, tmp_path):
    """Issue 41, item 1: output= naming the environment's map, the scene file or a link to either is refused
    by the library (VEIL_ERR_INVALID naming the scene's field) and the file is left as it was; the same
    scene renders to another name."""
    fog = {"type": "exponential", "density": 0.5, "falloff": 1.0, "origin": [0, 0, 0], "direction": [0, 1, 0],
           "bounds": [[-1, -1, -1], [1, 1, 1]]}
    veil.render(scene(fog), size=(8, 4), output=tmp_path / "sky.exr")  # a 2:1 map
    sky = (tmp_path / "sky.exr").read_bytes()
    s = scene(fog)
    s["lights"].append({"type": "environment", "file": "sky.exr"})
    (tmp_path / "scene.json").write_text(json.dumps(s))
    os.symlink("sky.exr", tmp_path / "link.exr")
    os.link(tmp_path / "scene.json", tmp_path / "scene.png")
    for source, target, field in ((s, "sky.exr", "lights[1].file"), (s, "link.exr", "lights[1].file"),
                                  (tmp_path / "scene.json", "sky.exr", "lights[1].file"),
                                  (tmp_path / "scene.json", "scene.png", "the scene")):
        with pytest.raises(veil.VeilError) as e:
            veil.render(source, base_dir=tmp_path, output=tmp_path / target)
        assert e.value.name == "VEIL_ERR_INVALID" and field in e.value.message and "overwritten" in e.value.message
    frames = veil.turntable(s, 2, base_dir=tmp_path, output=tmp_path / "sky#.exr")
    next(frames)  # frame 0 is sky0.exr, not the map
    os.link(tmp_path / "sky.exr", tmp_path / "sky1.exr")
    next(frames)  # frame 1 renders; its file is written while the caller holds it (issue 42) ...
    with pytest.raises(veil.VeilError, match="lights\\[1\\].file"):
        next(frames)  # ... and the refusal comes with the next call
    assert (tmp_path / "sky.exr").read_bytes() == sky and "environment" in (tmp_path / "scene.json").read_text()
    assert veil.render(s, base_dir=tmp_path, output=tmp_path / "other.exr").path == str(tmp_path / "other.exr")


def test_turntable(gl, tmp_path):
    s = scene({"type": "rbf", "particles": [{"center": [0.6, 0, 0], "amplitude": 2.0, "sharpness": 3.0}]})
    frames = list(veil.turntable(s, 4, start=1, output=tmp_path / "tt.####.exr"))
    assert [f for f, _ in frames] == [1, 2, 3]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["tt.0001.exr", "tt.0002.exr", "tt.0003.exr"]
    # one context, one scene: the medium is injected and propagated once, then reused
    later = dict((st[0], st[1]) for st in frames[1][1].stages)
    assert later["inject"] == "cached" and later["propagate"] == "cached"
    # frame f of the turntable is render(frame=f, frames=4), and the camera moved between frames
    np.testing.assert_array_equal(frames[1][1]["rgba"], veil.render(s, frame=2, frames=4)["rgba"])
    assert not np.array_equal(frames[0][1]["rgba"], frames[1][1]["rgba"])
    with pytest.raises(ValueError, match="#"):
        next(veil.turntable(s, 4, output=tmp_path / "no_number.exr"))


def test_context_is_bound_to_its_thread(gl):
    ctx = veil.Context()
    caught = []

    def other():
        try:
            ctx.render(valid_scene())
        except veil.VeilError as e:
            caught.append(e)
        # this thread's default context is its own, not the main thread's
        caught.append(veil.default_context() is not gl)

    t = threading.Thread(target=other, name="worker")
    t.start()
    t.join()
    assert caught[0].name == "VEIL_ERR_GPU" and "'worker'" in caught[0].message and "MainThread" in caught[0].message
    assert caught[1] is True
    with ctx:
        assert ctx.render(valid_scene(), aovs=False)["rgba"].shape == (H, W, 4)
    assert ctx.closed
    with pytest.raises(veil.VeilError, match="after close"):
        ctx.render(valid_scene())
    assert veil.default_context() is gl  # reused across calls


def _exr_header(path):
    """(compression code, {channel: pixel type}) from an EXR's header (OpenEXR's layout: attributes
    name\\0 type\\0 size value, after the magic and version; pixel types 1 half, 2 float)."""
    data = open(path, "rb").read()
    assert data[:4] == b"\x76\x2f\x31\x01"
    at, attrs = 8, {}
    while data[at] != 0:
        name_end = data.index(b"\0", at)
        type_end = data.index(b"\0", name_end + 1)
        size = int.from_bytes(data[type_end + 1:type_end + 5], "little")
        attrs[data[at:name_end].decode()] = data[type_end + 5:type_end + 5 + size]
        at = type_end + 5 + size
    channels, cl = {}, attrs["channels"]
    while cl[0] != 0:
        end = cl.index(b"\0")
        channels[cl[:end].decode()] = int.from_bytes(cl[end + 1:end + 5], "little")
        cl = cl[end + 17:]
    return attrs["compression"][0], channels


def test_exr_type_and_compression(gl, tmp_path):
    """Issue 42: exr= stores the pixels as half or float with the compression asked for (OpenEXR's codes:
    none 0, zip 3, piz 4, dwaa 8); in a half file the distances and P stay float; a turntable's frames the
    same; bad values raise before any render."""
    fog = {"type": "exponential", "density": 0.5, "falloff": 1.0, "origin": [0, 0, 0], "direction": [0, 1, 0],
           "bounds": [[-1, -1, -1], [1, 1, 1]]}
    plain = veil.render(scene(fog), output=tmp_path / "plain.exr")
    assert _exr_header(tmp_path / "plain.exr") == (3, {c: 2 for c in _exr_header(tmp_path / "plain.exr")[1]})
    for kind, comp, code in (("half", "piz", 4), ("float", "none", 0), ("half", "dwaa", 8)):
        veil.render(scene(fog), output=tmp_path / ("%s_%s.exr" % (kind, comp)), exr={"type": kind, "compression": comp})
        got, channels = _exr_header(tmp_path / ("%s_%s.exr" % (kind, comp)))
        assert got == code
        for name, t in channels.items():
            assert t == (1 if kind == "half" and name not in ("Z", "depth", "P") else 2), (kind, name, t)
    assert {"R", "G", "B", "A", "Z", "depth", "P"} <= set(channels)
    frames = list(veil.turntable(scene(fog), 2, output=tmp_path / "t#.exr", exr={"compression": "zips"}))
    assert len(frames) == 2 and all(_exr_header(tmp_path / ("t%d.exr" % f))[0] == 2 for f in (0, 1))
    for bad, exc in (({"type": "double"}, ValueError), ({"compression": "lzma"}, ValueError), ({"level": 3}, ValueError),
                     ("half", TypeError)):
        with pytest.raises(exc):
            veil.render(scene(fog), output=tmp_path / "bad.exr", exr=bad)
    assert not (tmp_path / "bad.exr").exists() and plain.path == str(tmp_path / "plain.exr")
