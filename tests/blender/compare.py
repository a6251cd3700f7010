#!/usr/bin/env python3
"""Compares the veil engine's render in Blender with `veil render` of the exported scene (issue 25's
Blender test (2)); run with /usr/bin/python3 (numpy, OpenImageIO).

    compare.py WORKDIR     (blender.exr, blender_layers.exr, cli.exr, scene.json from test_render.py and run.sh)

Expected: bit-identical radiance. Both images come from the same library rendering the same scene
(the engine's in-memory dict is what the operator wrote to scene.json, json's float repr round-trips
every double exactly) at the same size and seed, and both files hold 32-bit float channels written
losslessly (ZIP): Blender's engine flips veil's top-first rows to Blender's bottom-first order and
Blender's EXR writer flips them back, so nothing is converted and the tolerance on Combined and the
AOV passes is zero. Depth is not veil's raw channel: the engine turns the ray distance d into depth
along the view axis, d cos(theta); recomputed here from scene.json's camera in float64, the float32
results may differ by rounding, so that pass is compared within 4 ulps (relative 2^-21 ~ 4.8e-7),
and 1e10 where veil's depth is 0 (no medium).
"""
import json
import math
import os
import sys

import numpy as np
import OpenImageIO as oiio

work = sys.argv[1]
failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what, flush=True)
    if not ok:
        failures.append(what)


def read(path):
    i = oiio.ImageInput.open(path)
    if i is None:
        sys.exit("compare.py: cannot open %s: %s" % (path, oiio.geterror()))
    spec = i.spec()
    a = i.read_image(oiio.FLOAT)  # top row first, as OpenEXR stores it
    i.close()
    return {name: a[:, :, k] for k, name in enumerate(spec.channelnames)}


def same(a, b):
    return a.shape == b.shape and np.array_equal(a.view(np.uint32), b.view(np.uint32))


def report(name, a, b):
    d = np.abs(a.astype(np.float64) - b.astype(np.float64))
    return "%s: max |difference| %.3g, %d of %d values differ" % (name, d.max(), int((a != b).sum()), a.size)


bl = read(os.path.join(work, "blender.exr"))
layers = read(os.path.join(work, "blender_layers.exr"))
cli = read(os.path.join(work, "cli.exr"))
with open(os.path.join(work, "scene.json")) as f:
    cam = json.load(f)["camera"]

rgba_b = np.stack([bl[c] for c in "RGBA"], -1)
rgba_c = np.stack([cli[c] for c in "RGBA"], -1)
# the comparison means something: medium covers part of the frame, and the image is not its own
# vertical mirror (a forgotten or doubled row flip would change it)
alpha = rgba_c[..., 3]
check(alpha.max() > 0.2 and alpha.min() < 0.01, "the sphere covers part of the frame (alpha %.3f..%.3f)"
      % (alpha.min(), alpha.max()))
check(not np.array_equal(rgba_c, rgba_c[::-1]), "the image differs from its vertical mirror (a row flip would show)")
check(same(rgba_b, rgba_c), "blender.exr RGBA = veil render's RGBA, bit for bit (%s)" % report("RGBA", rgba_b, rgba_c))

pairs = [("Combined", "RGBA", "RGBA")] + [
    ("veil_transmittance", "RGB", ["T.R", "T.G", "T.B"]),
    ("veil_single", "RGB", ["single.R", "single.G", "single.B"]),
    ("veil_density", "X", ["P"])]
for name, ids, chans in pairs:
    a = np.stack([layers["ViewLayer.%s.%s" % (name, c)] for c in ids], -1)
    b = np.stack([cli[c] for c in chans], -1)
    check(same(a, b), "pass %s = veil render's %s, bit for bit (%s)" % (name, ",".join(chans), report(name, a, b)))
# veil_multiple: the module's sum of the two estimates, each a float32 sum (correctly rounded, so numpy's
# float32 addition of the same two channels gives the same bits)
a = np.stack([layers["ViewLayer.veil_multiple.%s" % c] for c in "RGB"], -1)
b = np.stack([cli["multiple.volume." + c] + cli["multiple.screen." + c] for c in "RGB"], -1)
check(same(a, b), "pass veil_multiple = multiple.volume + multiple.screen, bit for bit (%s)" % report("multiple", a, b))

# Depth: veil's distance along the ray times the pixel's cosine to the view axis (the frame on the
# plane one metre ahead from the camera's fov, fit and shift, as docs/scene-format.md defines them)
h, w = alpha.shape
fit = cam.get("sensor_fit", "vertical")
if fit == "auto":
    fit = "horizontal" if w >= h else "vertical"
fov = cam.get("fov_deg", cam.get("fov_y_deg"))
t = math.tan(math.radians(fov) / 2)
hx, hy = (t, t * h / w) if fit == "horizontal" else (t * w / h, t)
sx, sy = cam.get("shift", [0.0, 0.0])  # fractions of the fitted side's extent, 2t
x = sx * 2 * t + (-hx + (np.arange(w) + 0.5) * (2 * hx / w))
y = sy * 2 * t + (hy - (np.arange(h) + 0.5) * (2 * hy / h))  # row 0 is the top
cos = 1.0 / np.sqrt(1.0 + x[None, :] ** 2 + y[:, None] ** 2)
d = cli["depth"].astype(np.float64)
want = np.where(d > 0, d * cos, 1e10).astype(np.float32)
got = layers["ViewLayer.Depth.Z"]
hit = d > 0
rel = np.abs(got.astype(np.float64) - want) / np.maximum(np.abs(want), 1e-30)
check(hit.any() and (~hit).any(), "depth: medium in %d pixels, none in %d" % (hit.sum(), (~hit).sum()))
check(bool(np.all(got[~hit] == np.float32(1e10))), "pass Depth = 1e10 where no medium")
check(float(rel[hit].max()) <= 2.0 ** -21, "pass Depth = veil's distance x cos(angle to the view axis), within 4 ulps "
      "(max relative difference %.3g)" % float(rel[hit].max()))
# and it is veil's own Z (the CLI's --aovs channel), +inf there written as Blender's 1e10: bit for bit
if "Z" in cli:
    z = cli["Z"]
    check(bool(np.array_equal(got, np.where(np.isinf(z), np.float32(1e10), z).astype(np.float32))),
          "pass Depth = veil's Z channel (inf: 1e10), bit for bit")
else:
    check(False, "the CLI's EXR has no Z channel (veil 0.3 writes one with --aovs)")
print("%d check(s) failed" % len(failures) if failures else "all checks passed")
sys.exit(1 if failures else 0)
