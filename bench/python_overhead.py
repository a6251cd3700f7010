"""The Python module's overhead against the CLI (issue 25's measure), on one scene file:

  cli     veil render SCENE -o OUT.exr                      (one process)
  module  python3 -c 'veil.render(SCENE, output=OUT.exr)'   (one process: the interpreter, numpy,
                                                             the module, the same library)
whole-process wall time, alternated A B A B, median of RUNS each and the median of the pairwise
ratios; then, in one process, veil.render of the scene's first vdb source read into a numpy array
(grids={"density": array}, an "array" source with the grid's transform) against the same scene
from the file, median of RUNS each, and the two images compared.

    /usr/bin/python3 bench/python_overhead.py SCENE.json [--runs 5] [--veil build/veil]
        [--library build/libveil.so]
Needs numpy and pyopenvdb for the array part. Not a test.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def wall(cmd, env):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--library", default=os.path.join(ROOT, "build", "libveil.so"))
    a = ap.parse_args()
    env = dict(os.environ, VEIL_LIBRARY=os.path.abspath(a.library),
               PYTHONPATH=os.path.join(ROOT, "python") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    scene = os.path.abspath(a.scene)
    tmp = tempfile.mkdtemp()
    cli = [a.veil, "render", scene, "-o", os.path.join(tmp, "cli.exr")]
    mod = [sys.executable, "-c", "import sys, veil; veil.render(sys.argv[1], output=sys.argv[2])", scene,
           os.path.join(tmp, "module.exr")]
    wall(cli, env)  # warm the file cache and the shader cache alike
    wall(mod, env)
    tc, tm = [], []
    for _ in range(a.runs):
        tc.append(wall(cli, env))
        tm.append(wall(mod, env))
    ratios = [m / c for c, m in zip(tc, tm)]
    print("whole process, %s, median of %d (s): veil render %.3f, python module %.3f; module/cli pairwise "
          "median %.3f (range %.3f..%.3f)" % (os.path.basename(scene), a.runs, statistics.median(tc),
                                              statistics.median(tm), statistics.median(ratios), min(ratios),
                                              max(ratios)))
    subprocess.run(["cmp", os.path.join(tmp, "cli.exr"), os.path.join(tmp, "module.exr")], check=False)

    # in one process: the grid from memory against the file
    sys.path.insert(0, os.path.join(ROOT, "python"))
    os.environ["VEIL_LIBRARY"] = os.path.abspath(a.library)
    import numpy as np
    import pyopenvdb
    import veil
    with open(scene) as f:
        doc = json.load(f)
    base = os.path.dirname(scene)
    src = next(s for s in doc["medium"]["sources"] if s["type"] == "vdb")
    path = src["file"] if os.path.isabs(src["file"]) else os.path.join(base, src["file"])
    grid = pyopenvdb.read(path, src.get("grid", "density"))
    lo, hi = grid.evalActiveVoxelBoundingBox()
    shape = tuple(h - l + 1 for l, h in zip(lo, hi))
    arr = np.zeros(shape, dtype=np.float32)
    grid.copyToArray(arr, ijk=lo)
    # index -> world: OpenVDB's row-vector matrix, transposed, with the array's origin at index lo
    rows = grid.transform.indexToWorld((0, 0, 0)), grid.transform.indexToWorld((1, 0, 0)), \
        grid.transform.indexToWorld((0, 1, 0)), grid.transform.indexToWorld((0, 0, 1))
    o = np.array(rows[0])
    cols = [np.array(r) - o for r in rows[1:]]
    m = np.eye(4)
    for k in range(3):
        m[:3, k] = cols[k]
    m[:3, 3] = o + sum(cols[k] * lo[k] for k in range(3))
    arr_doc = json.loads(json.dumps(doc))
    for s in arr_doc["medium"]["sources"]:
        if s is not None and s.get("type") == "vdb":
            s.clear()
            s.update({"type": "array", "grid": "density", "density_scale": src.get("density_scale", 1)})
            break
    tf, ta = [], []
    for _ in range(a.runs):
        # a new scene each time, as a script making one render per call would: no stage kept between them
        with veil.Context() as c:
            t0 = time.perf_counter()
            img_f = veil.render(doc, base_dir=base, context=c)
            tf.append(time.perf_counter() - t0)
        with veil.Context() as c:
            t0 = time.perf_counter()
            img_a = veil.render(arr_doc, grids={"density": (arr, m)}, base_dir=base, context=c)
            ta.append(time.perf_counter() - t0)
    diff = float(np.abs(img_a["rgba"] - img_f["rgba"]).max())
    print("in one process, fresh context each, median of %d (s): from the file %.3f, from a %dx%dx%d numpy "
          "array %.3f (ratio %.3f); max |rgba difference| %.3g" % (a.runs, statistics.median(tf), shape[0], shape[1],
                                                                  shape[2], statistics.median(ta),
                                                                  statistics.median(ta) / statistics.median(tf),
                                                                  diff))


if __name__ == "__main__":
    main()
