"""Progress and cancel: the callback's reports, False cancelling, an exception cancelling and coming
back out, no file written by a cancelled render and an existing one left as it was."""

import importlib.util
import os
import subprocess

import numpy as np
import pytest

import veil
from conftest import placement, scene, sphere


@pytest.fixture(scope="module")
def progress_api():
    """Progress is part of the library under test (veil 0.3): its absence fails, it is not skipped."""
    assert veil._render._Lib.has_progress, "libveil.so (veil %s) has no progress callback" % veil.__version__


def fresh_scene(seed):
    """A scene no earlier render cached (its particle set differs by seed): every stage runs."""
    return scene({"type": "rbf_random", "count": 60, "seed": seed, "bounds": [[-0.6, -0.4, -0.4], [0.6, 0.4, 0.4]],
                  "radius": [0.1, 0.25], "amplitude": [0.5, 1.5]})


def test_progress_reports_stages_in_order(gl, progress_api):
    calls = []
    out = veil.render(fresh_scene(101), progress=lambda stage, done: calls.append((stage, done)))
    assert calls, "the callback was never called"
    stages = [s for s, _ in calls]
    assert set(stages) <= set(veil.STAGES)
    # each stage's reports come together, in the pipeline's order, and its share done never goes back
    order = [s for i, s in enumerate(stages) if i == 0 or stages[i - 1] != s]
    assert order == sorted(set(order), key=veil.STAGES.index), order
    for st in set(stages):
        done = [d for s, d in calls if s == st]
        assert all(0.0 <= d <= 1.0 for d in done) and done == sorted(done), (st, done)
    assert "render" in stages and out["rgba"].shape[2] == 4


@pytest.mark.parametrize("stop_at", ["first call", "render"])
def test_returning_false_cancels_and_writes_nothing(gl, progress_api, tmp_path, stop_at):
    target = tmp_path / "frame.exr"
    target.write_bytes(b"an earlier frame")
    seen = []

    def progress(stage, done):
        seen.append(stage)
        if stop_at == "first call" or stage == stop_at:
            return False
        return None

    with pytest.raises(veil.Cancelled) as e:
        veil.render(fresh_scene(202 if stop_at == "render" else 203), progress=progress, output=target)
    assert isinstance(e.value, veil.VeilError) and e.value.name == "VEIL_ERR_CANCELLED" and e.value.code == 8
    assert target.read_bytes() == b"an earlier frame"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["frame.exr"]
    # cancelled as soon as asked: the work in flight ends, nothing after it starts
    assert seen[-1] == (seen[0] if stop_at == "first call" else "render")
    assert veil.STAGES.index(seen[-1]) <= veil.STAGES.index("render")


def test_exception_in_callback_cancels_and_is_raised(gl, progress_api, tmp_path):
    class Boom(Exception):
        pass

    def progress(stage, done):
        raise Boom("from the callback at %s" % stage)

    with pytest.raises(Boom, match="from the callback") as e:
        veil.render(fresh_scene(303), progress=progress, output=tmp_path / "x.png")
    assert isinstance(e.value.__context__, veil.Cancelled)  # veil's side of it, kept as the context
    assert list(tmp_path.iterdir()) == []


def test_context_renders_after_a_cancel(gl, progress_api):
    """A cancelled render leaves the context usable, and what it finished cached stays right."""
    s = fresh_scene(404)
    with pytest.raises(veil.Cancelled):
        veil.render(s, progress=lambda stage, done: False if stage == "render" else None)
    after = veil.render(s)
    with veil.Context() as fresh:
        np.testing.assert_array_equal(after["rgba"], fresh.render(s)["rgba"])


def test_turntable_cancel_stops_the_generator(gl, progress_api):
    frames = []
    with pytest.raises(veil.Cancelled):
        for f, out in veil.turntable(fresh_scene(505), 3, progress=lambda stage, done: False if frames else None):
            frames.append(f)
    assert frames == [0]


def test_progress_argument_checks():
    with pytest.raises(TypeError, match="progress"):
        veil.render(fresh_scene(1), progress=3)
    with pytest.raises(ValueError, match="progress"):
        veil.render(fresh_scene(1), progress="bar")


def test_tqdm_or_text_progress(gl, progress_api, capsys):
    has_tqdm = importlib.util.find_spec("tqdm") is not None
    out = veil.render(scene({"type": "array", "grid": "density"}),
                      grids={"density": (sphere(8), placement(0.1, 8))}, progress=True)
    assert out["rgba"].shape[2] == 4
    err = capsys.readouterr().err
    assert "render" in err  # a bar (tqdm) or a line per stage names each stage on stderr
    if not has_tqdm:
        with pytest.raises(ImportError, match="tqdm"):
            veil.render(scene({"type": "array", "grid": "density"}), grids={"density": sphere(4)},
                        progress="tqdm")


@pytest.mark.parametrize("stage", ["inject", "propagate", "volumetric", "render"])
def test_callbacks_that_touch_contexts(gl, progress_api, stage):
    """Issue 41, item 3: inside the progress callback, at each stage, a new veil.Context rendering and closed,
    and a nested render with this context or the default one: the outer render's pixels are a plain render's
    bit for bit, a nested render of the rendering context and its close() are refused with VeilError, and
    the context renders on. Before: SIGSEGV (close), SIGABRT (a new context), a wrong image (nesting)."""
    s = fresh_scene(404)
    with veil.Context() as truth_ctx:
        truth = truth_ctx.render(s, seed=3)["rgba"]

    for act in ("new context", "close own", "nested own", "nested default"):
        seen = {}

        def progress(st, done):
            if st != stage or st in seen:
                return None
            seen[st] = True
            if act == "new context":
                with veil.Context() as other:
                    np.testing.assert_array_equal(other.render(s, seed=3)["rgba"], truth)
            elif act == "close own":
                ctx.close()
            elif act == "nested own":
                ctx.render(s, seed=3)
            else:
                veil.render(s, seed=3)  # the default context: not the rendering one, so it renders
            return None

        with veil.Context() as ctx:
            if act in ("close own", "nested own"):
                with pytest.raises(veil.VeilError) as e:
                    ctx.render(s, seed=3, progress=progress)
                assert e.value.name == "VEIL_ERR_INVALID" and "rendering" in e.value.message, e.value.message
                assert not ctx.closed
            else:
                np.testing.assert_array_equal(ctx.render(s, seed=3, progress=progress)["rgba"], truth)
            assert seen, "the callback never reached %s" % stage
            np.testing.assert_array_equal(ctx.render(s, seed=3)["rgba"], truth)  # and it renders on


def test_ctrl_c_cancels_a_long_scene_read(gl, progress_api, tmp_path):
    """Issue 41, item 7: reading an environment map (decoded, then cut into lights) reports to the progress
    callback as the inject stage at 0, so Ctrl-C (here SIGINT sent from the first report) cancels the read
    itself: KeyboardInterrupt, with veil's VEIL_ERR_CANCELLED from the scene read as its context. Before,
    the read ran to its end (an 8K map: ~30 s) before Python saw the signal."""
    import signal
    tool = os.environ["VEIL_MAKE_ENV_MAP"]
    assert os.access(tool, os.X_OK), "VEIL_MAKE_ENV_MAP=%s: no such tool (ctest sets it)" % tool
    subprocess.run([tool, str(tmp_path / "sky.exr"), "2048", "1024"], check=True)
    s = fresh_scene(505)
    s["lights"].append({"type": "environment", "file": "sky.exr"})
    seen = []

    def progress(stage, done):
        seen.append((stage, done))
        if len(seen) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt) as e:
        veil.render(s, base_dir=tmp_path, progress=progress)
    ctx = e.value.__context__
    assert isinstance(ctx, veil.VeilError) and ctx.name == "VEIL_ERR_CANCELLED", repr(ctx)
    assert "environment map" in ctx.message or "pixels were read" in ctx.message, ctx.message
    assert seen[0] == ("inject", 0.0) and len(seen) <= 2, seen
