"""The GIL is released while veil renders: another Python thread keeps running."""

import threading
import time

import veil
from conftest import placement, scene, sphere, write_vdb


def count_until(event):
    """The loop whose speed is measured: the same body alone and beside a render."""
    n = 0
    while not event.is_set():
        n += 1
    return n


def test_gil_released_while_rendering(gl, tmp_path):
    write_vdb(tmp_path / "ball.vdb", sphere(48, 9.0), placement(0.033, 48))
    # default quality at 128x128: about a second of work on llvmpipe, mostly the light cache
    s = scene({"type": "vdb", "file": "ball.vdb"}, size=(128, 128), quality="default")
    ready, go, done = threading.Event(), threading.Event(), threading.Event()
    result = {}

    def worker():
        try:
            veil.default_context()  # this thread's context, made before the measured window
            ready.set()
            go.wait()
            t0 = time.perf_counter()
            result["out"] = veil.render(s, base_dir=tmp_path)
            result["wall"] = time.perf_counter() - t0
        except BaseException as e:  # reported by the main thread
            result["error"] = e
        finally:
            ready.set()
            done.set()

    t = threading.Thread(target=worker)
    t.start()
    ready.wait()
    # the loop's speed alone (the worker waits on an event: it holds no GIL and takes no CPU)
    alone = threading.Event()
    timer = threading.Timer(0.3, alone.set)
    t0 = time.perf_counter()
    timer.start()
    n_alone = count_until(alone)
    rate = n_alone / (time.perf_counter() - t0)
    go.set()
    t0 = time.perf_counter()
    n = count_until(done)
    elapsed = time.perf_counter() - t0
    t.join()
    if "error" in result:
        raise result["error"]
    in_c = sum(ms for _, status, ms, _ in result["out"].stages) / 1000.0  # s the stages ran, GIL released
    assert in_c > 0.5 * elapsed, "the render should spend most of its time in the library: %.3f of %.3f s" % (
        in_c, elapsed)
    # Had veil_render held the GIL, the main thread could have counted only outside the stages, at
    # most at its solo speed: rate * (elapsed - in_c). Released, it shares two cores with llvmpipe's
    # threads and gets a fair share, about a third of its solo speed; ask for a twentieth of it
    # during the stages, on top of the most the time outside them could give.
    held_at_most = rate * (elapsed - in_c)
    assert n > held_at_most + 0.05 * rate * in_c, (
        "the main thread counted %d (solo %.0f/s) during a %.2f s render whose stages took %.2f s: "
        "no more than with the GIL held (%d)" % (n, rate, elapsed, in_c, held_at_most))
