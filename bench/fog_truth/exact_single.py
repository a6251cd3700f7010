#!/usr/bin/python3
"""Single scattering with every surface known, against Cycles and veil.

    /usr/bin/python3 bench/fog_truth/exact_single.py OUTDIR [--cases night,day] [--samples 512]

`veil fog` knows the surfaces only from the frame's depth (scene/solid.h):
what the camera does not see casts no shadow. This integrates the medium's
single scattering of each case in numpy with the street's own boxes
(scenes.py) as occluders, along each pixel's ray to the frame's depth: the
shadows a frame that showed everything would give. Printed beside Cycles'
VolumeDir (the truth's own single scattering, mean of the two seeds) and
veil's (CASE_veil_ss.exr minus CASE_veil_attenuation.exr, both written by
compare.py), as % of the truth's mean, and the same with the occluders off.

Midpoint rule in SAMPLES steps per ray for the camera's transmittance and
the fog's density; the light's optical depth in closed form (exponential
fog along a straight path) and its visibility by slab tests against the
boxes.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402
from calibrate import rays  # noqa: E402
from compare import layer, read_exr  # noqa: E402


def slab(o, d, lo, hi, t_max):
    """Whether o + t d, 0 < t < t_max, meets the box [lo, hi] (o, d: (..., 3))."""
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        a, b = (lo - o) * inv, (hi - o) * inv
    t0 = np.nanmax(np.minimum(a, b), axis=-1)
    t1 = np.nanmin(np.maximum(a, b), axis=-1)
    return (t0 < t1) & (t1 > 1e-6) & (t0 < t_max)


def box_exit(o, d, lo, hi):
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / d
        a, b = (lo - o) * inv, (hi - o) * inv
    return np.clip(np.nanmin(np.maximum(a, b), axis=-1), 0.0, None)


def density_integral(y0, dy, length, falloff):
    """The integral of exp(-falloff y) along y0 + s dy, s in [0, length]."""
    if falloff == 0.0:
        return length
    k = -falloff * dy
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        r = np.exp(-falloff * y0) * np.where(np.abs(k) > 1e-9, np.expm1(k * length) / k, length)
    return r


def single(case, depth, samples, occluders):
    c = scenes.CASES[case]
    cam = scenes.CAMERA
    pos, fwd, d = rays(cam)
    dist = depth / (d @ fwd)
    lo, hi = (np.array(v) for v in scenes.FOG_BOX)
    t_end = np.minimum(dist, box_exit(pos[None, None, :], d, lo, hi))
    ss, sa = np.array(c["sigma_s"]), np.array(c["sigma_a"])
    st = ss + sa
    g, falloff, rho0 = c["g"], c["fog"]["falloff"], c["fog"]["density"]
    out = np.zeros(d.shape[:2] + (3,))
    tau_cam = np.zeros(d.shape[:2])
    dt = t_end / samples
    boxes = [(np.array(b[0]), np.array(b[1])) for b in scenes.BOXES]
    for i in range(samples):
        t = (i + 0.5) * dt
        x = pos[None, None, :] + d * t[..., None]
        rho = rho0 * np.exp(-falloff * x[..., 1])
        for lt in c["lights"]:
            if lt["type"] == "directional":
                L = np.array(lt["direction"], dtype=np.float64)
                L /= np.linalg.norm(L)
                to = np.broadcast_to(-L, x.shape)
                length = box_exit(x, to, lo, hi)
                E = np.array(lt["irradiance"])[None, None, :] * np.ones(x.shape[:2] + (1,))
                travel = np.broadcast_to(L, x.shape)
            else:
                v = np.array(lt["position"]) - x
                r = np.linalg.norm(v, axis=-1)
                to = v / r[..., None]
                length = r
                E = np.array(lt["intensity"])[None, None, :] / (r * r)[..., None]
                travel = -to
            D = rho0 * density_integral(x[..., 1], to[..., 1], length, falloff)
            vis = np.ones(x.shape[:2])
            if occluders:
                for blo, bhi in boxes:
                    vis = np.where(slab(x, to, blo, bhi, length), 0.0, vis)
            mu = np.sum(travel * -d, axis=-1)
            p = (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * mu) ** 1.5)
            w = np.exp(-tau_cam)[..., None] * ss * (rho * dt)[..., None]
            out += w * E * np.exp(-st * D[..., None]) * (p * vis)[..., None]
        tau_cam += rho * dt * float(np.mean(st))  # grey here (scenes.py): one channel serves
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("outdir")
    ap.add_argument("--cases", default="night,day")
    ap.add_argument("--samples", type=int, default=512)
    args = ap.parse_args()
    for case in args.cases.split(","):
        dd = args.outdir
        n0, a0 = read_exr(os.path.join(dd, case + "_nofog.exr"))
        depth = layer(n0, a0, "Depth", "Z")[..., 0]
        depth = np.where(depth >= 1e9, np.inf, depth)  # Cycles writes 1e10 where nothing was hit
        truth, vol_dir = [], []
        for s in (1, 2):
            n, a = read_exr(os.path.join(dd, "%s_fog_s%d.exr" % (case, s)))
            truth.append(layer(n, a, "Combined"))
            vol_dir.append(layer(n, a, "VolumeDir"))
        m = float(np.mean(sum(truth) / 2))
        cyc = float(np.mean(sum(vol_dir) / 2)) / m
        exact = float(np.mean(single(case, depth, args.samples, True))) / m
        open_ = float(np.mean(single(case, depth, args.samples, False))) / m
        line = "%s: single scattering, %% of the truth: Cycles %.1f; every box an occluder %.1f; none %.1f" % (
            case, 100 * cyc, 100 * exact, 100 * open_)
        vs, va = (os.path.join(dd, "%s_veil_%s.exr" % (case, k)) for k in ("ss", "attenuation"))
        if os.path.exists(vs) and os.path.exists(va):
            nv, av = read_exr(vs)
            nt, at = read_exr(va)
            veil = float(np.mean(av[..., :3] - at[..., :3])) / m
            line += "; veil fog (the frame's surfaces) %.1f" % (100 * veil)
        print(line)


if __name__ == "__main__":
    main()
