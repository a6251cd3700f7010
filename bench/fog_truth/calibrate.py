#!/usr/bin/python3
"""Checks that Cycles and veil mean the same thing (truth.py's calibration).

    /usr/bin/python3 bench/fog_truth/calibrate.py OUTDIR [--cases night,day]

On the renders run.sh made, with veil's camera model (scene/camera.c:
pixel centres, vertical fov) and the scene's geometry:
1. depth: every pixel's Z puts its point on one of the boxes' faces
   (|distance to the nearest face| median, m) -- camera, fov and "Z along
   the view axis" agree;
2. lights: on the ground (y = 0) far from the boxes, Cycles' DiffDir
   without fog (direct irradiance / pi) against sum_l I_l cos / (pi r^2)
   (points) or E cos / pi (sun), unshadowed pixels: median ratio, must be 1
   -- the power = 4 pi I and strength = E conventions;
3. medium: the same pixels with fog: Cycles keeps the camera leg's transmittance
   in DiffCol (against exp(-tau_cam)) and the lights' in DiffDir: DiffDir_fog /
   DiffDir_nofog against
   sum_l w_l T_l / sum_l w_l (exp(-sigma_t * length)
   for homogeneous fog, the exponential fog's closed-form optical depth
   otherwise): median ratio of the two, must be 1 -- sigma_t and the
   density's falloff. It also states how much of the surfaces' direct
   light the fog takes away (Cycles) that the frame under `veil fog` keeps.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402
from compare import layer, read_exr  # noqa: E402


def rays(cam):
    w, h = cam["width"], cam["height"]
    pos, at, up = (np.array(cam[k], dtype=np.float64) for k in ("position", "look_at", "up"))
    fwd = at - pos
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    upv = np.cross(right, fwd)
    t = math.tan(math.radians(cam["fov_y_deg"]) / 2)
    px, py = np.meshgrid(np.arange(w) + 0.5, np.arange(h) + 0.5)
    sx, sy = 2 * px / w - 1, 1 - 2 * py / h
    d = fwd + sx[..., None] * right * t * w / h + sy[..., None] * upv * t
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return pos, fwd, d


def optical_depth(c, a, b):
    """sigma_t-weighted density integral from a to b (veil's exponential fog, y falloff), per point"""
    st = c["sigma_s"][0] + c["sigma_a"][0]
    rho0, k = c["fog"]["density"], c["fog"]["falloff"]
    L = np.linalg.norm(b - a, axis=-1)
    if k == 0.0:
        return st * rho0 * L
    dy = b[..., 1] - a[..., 1]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        # integral of exp(-k y) along the segment = L * (exp(-k ya) - exp(-k yb)) / (k dy)
        val = np.where(np.abs(k * dy) > 1e-6, (np.exp(-k * a[..., 1]) - np.exp(-k * b[..., 1])) / (k * dy),
                       np.exp(-k * a[..., 1]))
    return st * rho0 * L * val


def sun_depth(c, p, direction):
    """optical depth from p toward the sun to the fog box's top (y = FOG_BOX top)"""
    d = -np.array(direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    lo, hi = (np.array(v) for v in scenes.FOG_BOX)
    tmax = np.full(p.shape[:-1], np.inf)
    for a in range(3):
        if d[a] > 0:
            tmax = np.minimum(tmax, (hi[a] - p[..., a]) / d[a])
        elif d[a] < 0:
            tmax = np.minimum(tmax, (lo[a] - p[..., a]) / d[a])
    return optical_depth(c, p, p + tmax[..., None] * d)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("outdir")
    ap.add_argument("--cases", default="night,day")
    args = ap.parse_args()
    cam = scenes.CAMERA
    pos, fwd, d = rays(cam)
    ok = True
    for case in args.cases.split(","):
        c = scenes.CASES[case]
        n0, a0 = read_exr(os.path.join(args.outdir, case + "_nofog.exr"))
        n1, a1 = read_exr(os.path.join(args.outdir, case + "_fog_s1.exr"))
        z = layer(n0, a0, "Depth", "Z")[..., 0].astype(np.float64)
        hit = z < 1e9
        t = z / (d @ fwd)
        p = pos + t[..., None] * d
        # 1. depth on a face
        dist = np.full(z.shape, np.inf)
        for lo, hi, _ in scenes.BOXES:  # distance from p to the box's surface
            lo, hi = np.array(lo), np.array(hi)
            out = np.linalg.norm(np.maximum(np.maximum(lo - p, p - hi), 0.0), axis=-1)
            inside = np.min(np.minimum(p - lo, hi - p), axis=-1)
            dist = np.minimum(dist, np.where(out > 0, out, np.abs(inside)))
        med = float(np.median(dist[hit]))
        print("%s: depth -> point on a face: median distance %.2g m over %d hit pixels" % (case, med, int(hit.sum())))
        ok &= med < 0.02
        # 2. direct light on open ground: y ~ 0, |x| < 4, away from the cars
        ground = hit & (np.abs(p[..., 1]) < 0.02) & (np.abs(p[..., 0]) < 4.0)
        for lo, hi, _ in scenes.BOXES[4:]:
            ground &= ~((p[..., 0] > lo[0] - 2.5) & (p[..., 0] < hi[0] + 2.5) & (p[..., 2] > lo[2] - 2.5)
                        & (p[..., 2] < hi[2] + 2.5))
        n = np.array([0.0, 1.0, 0.0])
        pred = np.zeros(z.shape + (3,))
        predT = np.zeros(z.shape + (3,))
        for l in c["lights"]:
            if l["type"] == "point":
                v = np.array(l["position"]) - p
                r2 = np.sum(v * v, axis=-1)
                cos = np.maximum(v @ n, 0) / np.sqrt(r2)
                e = np.array(l["intensity"]) * (cos / (math.pi * r2))[..., None]
                tl = np.exp(-optical_depth(c, p, np.broadcast_to(np.array(l["position"]), p.shape)))
            else:
                cos = max(0.0, -float(np.array(l["direction"]) @ n) / float(np.linalg.norm(l["direction"])))
                e = np.broadcast_to(np.array(l["irradiance"]) * cos / math.pi, z.shape + (3,))
                tl = np.exp(-sun_depth(c, p, l["direction"]))
            pred = pred + e
            predT = predT + e * tl[..., None]
        dd0 = layer(n0, a0, "DiffDir")
        dd1 = layer(n1, a1, "DiffDir")
        lit = ground & (pred[..., 0] > 0.02 * pred[..., 0][ground].max()) & (dd0[..., 0] > 0.2 * pred[..., 0])
        ratio = dd0[lit] / pred[lit]
        print("%s: lights: Cycles DiffDir / closed form on %d open-ground pixels: median %.4f (quartiles %.4f %.4f)"
              % (case, int(lit.sum()), float(np.median(ratio)), *np.percentile(ratio, [25, 75])))
        ok &= abs(float(np.median(ratio)) - 1) < 0.01
        # Cycles keeps the camera ray's transmittance in the colour pass (DiffCol) and the
        # light's in the light pass (DiffDir): each against its closed form
        tcam = np.exp(-optical_depth(c, np.broadcast_to(pos, p.shape), p))
        rc = (layer(n1, a1, "DiffCol")[lit] / np.maximum(layer(n0, a0, "DiffCol")[lit], 1e-30)) / tcam[lit][:, None]
        print("%s: medium, camera leg: (DiffCol fog / no fog) / exp(-tau_cam): median %.4f (quartiles %.4f %.4f)"
              % (case, float(np.median(rc)), *np.percentile(rc, [25, 75])))
        ok &= abs(float(np.median(rc)) - 1) < 0.01
        expect = predT / np.maximum(pred, 1e-30)
        r = (dd1[lit] / np.maximum(dd0[lit], 1e-30)) / expect[lit]
        print("%s: medium, light legs: (DiffDir fog / no fog) / sum_l w_l T_l: median %.4f (quartiles %.4f %.4f)"
              % (case, float(np.median(r)), *np.percentile(r, [25, 75])))
        ok &= abs(float(np.median(r)) - 1) < 0.02
        print("%s: the fog takes %.0f %% of these pixels' direct light on the way from the lights (median of "
              "1 - T_light): light the frame under `veil fog` keeps" % (
                  case, 100 * float(np.median(1 - (predT / np.maximum(pred, 1e-30))[lit]))))
    print("calibration", "ok" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
