#!/usr/bin/env python3
"""The light at one point of a medium, from `veil reference`, against the
angular models the light cache could use for it.

    /usr/bin/python3 bench/cache_box/probe.py SCENE.json --point X,Y,Z --camera X,Y,Z
        [--spp 256] [--size 32] [--veil build/veil] [--out build/cache_box/probe]

Six cameras with a 90-degree field of view at the point (the faces of a
cube) see, in each pixel, the light arriving there from that pixel's
direction: `veil reference` of the scene with the camera replaced, all
orders (a black background and a sun's delta are never seen by a pixel, so
that is the light that has scattered at least once -- what the cache
holds). From it: the fluence phi, the flux F and the second moment M of
direction, and the exact in-scattering towards the camera v (the march's
term, per unit sigma_s), sum over pixels of L(w) p_HG(w . v; g) dOmega,
against the models with the same moments:
  hg      phi p_HG(F^ . v; g |F| / phi)             (what the cache adds today)
  iso+hg  an isotropic part plus an HG lobe about F, matched to the first
          two moments along F (where they allow it; else hg)
  sh2     spherical harmonics to l = 2 (phi, F, M), each band times g^l
and each again with the once-scattered light (--max-order 1) in its own
HG lobe ("split"). A pixel's solid angle on a cube face of n x n pixels is
(2/n)^2 / (1 + sx^2 + sy^2)^(3/2). Needs numpy and OpenImageIO
(/usr/bin/python3). docs/multiple-scattering.md has what it found.
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FACES = [([1, 0, 0], [0, 1, 0]), ([-1, 0, 0], [0, 1, 0]), ([0, 1, 0], [0, 0, 1]), ([0, -1, 0], [0, 0, 1]),
         ([0, 0, 1], [0, 1, 0]), ([0, 0, -1], [0, 1, 0])]


def hg(mu, g):
    return (1 - g * g) / (4 * np.pi * (1 + g * g - 2 * g * mu) ** 1.5)


def sample(scene, x, veil, n, spp, out, max_order):
    """(L, dOmega, travel direction) for every pixel of the six faces."""
    Ls, Ws, Ds = [], [], []
    for i, (f, up) in enumerate(FACES):
        s = json.loads(json.dumps(scene))
        s["camera"] = {"position": list(x), "look_at": [x[k] + f[k] for k in range(3)], "up": up, "fov_y_deg": 90,
                       "width": n, "height": n}
        sp = os.path.join(out, "face%d.json" % i)
        with open(sp, "w") as fh:
            json.dump(s, fh)
        img = os.path.join(out, "face%d_order%d.exr" % (i, max_order))
        p = subprocess.run([veil, "reference", sp, "-o", img, "--spp", str(spp), "--max-order", str(max_order)],
                           capture_output=True, text=True)
        if p.returncode != 0:
            sys.exit("probe.py: veil reference failed:\n%s%s" % (p.stdout, p.stderr))
        a = oiio.ImageBuf(img).get_pixels(oiio.FLOAT)[..., :3].mean(-1)
        fwd = np.array(f, float)
        right = np.cross(fwd, up)
        right /= np.linalg.norm(right)
        upv = np.cross(right, fwd)
        px = (np.arange(n) + 0.5) / n * 2 - 1
        sx, sy = np.meshgrid(px, -px)
        d = fwd[None, None] + sx[..., None] * right + sy[..., None] * upv
        r = np.linalg.norm(d, axis=-1)
        d /= r[..., None]
        Ls.append(a.ravel())
        Ws.append(((2.0 / n) ** 2 / r ** 3).ravel())
        Ds.append(d.reshape(-1, 3))
    return np.concatenate(Ls), np.concatenate(Ws), -np.concatenate(Ds)


def moments(L, W, Om):
    phi = float((L * W).sum())
    F = (L[:, None] * Om * W[:, None]).sum(0)
    M = (L[:, None, None] * Om[:, :, None] * Om[:, None, :] * W[:, None, None]).sum(0)
    return phi, F, M


def models(phi, F, M, v, g):
    f1 = np.linalg.norm(F) / phi
    ax = F / np.linalg.norm(F)
    mu = float(ax @ v)
    out = {"hg": phi * hg(mu, g * f1)}
    k2 = 1.5 * float(ax @ M @ ax) / phi - 0.5
    if k2 > f1 * f1:
        gl = min(k2 / f1, 0.995)
        a = f1 / gl
        out["iso+hg"] = phi * ((1 - a) / (4 * np.pi) + a * hg(mu, g * gl))
    else:
        out["iso+hg"] = out["hg"]
    Q = M / phi - np.eye(3) / 3
    out["sh2"] = phi / (4 * np.pi) * max(1 + 3 * g * f1 * mu + 7.5 * g * g * float(v @ Q @ v), 0.0)
    return out, f1, k2


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scene")
    ap.add_argument("--point", required=True)
    ap.add_argument("--camera", required=True)
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--size", type=int, default=32)
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--out", default=os.path.join(ROOT, "build", "cache_box", "probe"))
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    with open(a.scene) as f:
        scene = json.load(f)
    folder = os.path.dirname(os.path.abspath(a.scene))
    for src in scene["medium"].get("sources", []):  # the faces' scenes live in --out
        for key in ("file", "particle_file"):
            if key in src and not os.path.isabs(src[key]):
                src[key] = os.path.join(folder, src[key])
    ph = scene["medium"].get("phase", {})
    g = ph.get("g", 0.0) if ph.get("type") == "hg" else 0.0
    x = [float(v) for v in a.point.split(",")]
    v = np.array([float(c) for c in a.camera.split(",")]) - np.array(x)
    v /= np.linalg.norm(v)
    La, W, Om = sample(scene, x, a.veil, a.size, a.spp, a.out, 0)
    L1, _, _ = sample(scene, x, a.veil, a.size, a.spp, a.out, 1)
    exact = float((La * W * hg(Om @ v, g)).sum())
    m_all, f1, k2 = models(*moments(La, W, Om), v, g)
    m_1, _, _ = models(*moments(L1, W, Om), v, g)
    m_rest, _, _ = models(*moments(La - L1, W, Om), v, g)
    phi = float((La * W).sum())
    print("point %s, towards %s: phi %.5g, |F|/phi %.3f, <P2> along F %.3f (HG's: %.3f); in-scattering %.5g" % (
        a.point, a.camera, phi, f1, k2, f1 * f1, exact))
    for k in m_all:
        print("  %-7s %.3f x exact   split (once-scattered in its own HG lobe) %.3f x" % (
            k, m_all[k] / exact, (m_1["hg"] + m_rest[k]) / exact))


if __name__ == "__main__":
    main()
