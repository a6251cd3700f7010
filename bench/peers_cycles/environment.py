#!/usr/bin/env python3
"""Light from the environment (issue 26): the ruler first, then the GPU path measured by it.

    /usr/bin/python3 bench/peers_cycles/environment.py [--scenes smoke,cloud] [--skies constant,hdri]
        [--size 160x120] [--ref-spp 2048] [--cycles-spp 1024] [--lights 1,2,4,8,16] [--split 8,16] [--no-cycles]
        [--remainder cache,lights] [--quality default,high,max] [--g G] [--ref FOLDER] [--runs 3]
        [--veil build/veil] [--out docs/results]

For each scene (the shared smoke of bench/regress.py; the generated cloud of cloud.py) under each sky:
  - constant: a light {"type": "environment", "color": [0.5, 0.65, 0.9]};
  - hdri: a 512 x 256 lat-long EXR made here (sky_map): a smooth sky (brighter overhead, darker below,
    no edge anywhere in view) and a sun of 3 degrees' radius 50 degrees up carrying 4 W/m^2;
with the scene's own lights removed, it runs
  1. `veil reference` (the environment importance-sampled by luminance, MIS with the phase function)
     against Blender 3.4 Cycles' world (blender_scene.py: the colour, or the map as an Environment
     Texture read with Closest interpolation): the light the medium scattered (each image less the
     exact T x environment seen through it, the same in both), where T < 0.99: the mean bias with its
     standard error (the reference's noise) and the RMS difference on 4x4 blocks beside the
     reference's own noise there;
  2. `veil render` for each K of --lights, each "remainder" of --remainder (cache: the median cut of the
     map's bright part into at most K lights, the rest by the light cache; lights: the whole map as K
     directional lights, scene/environment.h) and each --quality: time (median of --runs whole runs) and
     error against the reference, measured as Cycles' is (the scattered light where T < 0.99: mean bias,
     RMS on 4x4 blocks);
  3. for each K of --split (remainder lights, default quality), the two errors apart: the cut's (the
     reference of its K lights against the reference of the map) and the GPU pipeline's (veil render
     against the reference of the K lights).
--g replaces the medium's phase function by HG(g); --ref keeps the references in a folder and reuses them.
Results: OUT/peers_cycles_environment.md. Needs blender (unless --no-cycles), numpy and OpenImageIO for
/usr/bin/python3."""
import argparse, json, os, statistics, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
import peers  # noqa: E402
from run import cloud_scene, combined_to_rgba, smoke_scene  # noqa: E402

SKY = [0.5, 0.65, 0.9]
SUN_DIR = (0.45, 0.766, -0.46)  # towards the sun, 50 degrees up
SUN_DEG = 3.0
SUN_E = 4.0  # W/m^2 from the sun's disc


def sky_map(path, w=512, h=256):
    """The hdri sky in veil's lat-long convention (scene/environment.h): texel (i, j) looks along
    (-sin t cos p, cos t, -sin t sin p), t = pi (j + 1/2) / h, p = 2 pi (i + 1/2) / w."""
    import numpy as np
    import OpenImageIO as oiio
    j, i = np.mgrid[0:h, 0:w]
    t, p = np.pi * (j + 0.5) / h, 2 * np.pi * (i + 0.5) / w
    d = np.stack([-np.sin(t) * np.cos(p), np.cos(t), -np.sin(t) * np.sin(p)], -1)
    y = d[..., 1]
    L = (0.35 + 0.3 * y)[..., None] * np.array([0.45, 0.6, 1.0]) + (0.05 * (1 - y))[..., None] * np.array([1.0, 0.8, 0.6])
    s = np.array(SUN_DIR) / np.linalg.norm(SUN_DIR)
    disc = d @ s > np.cos(np.radians(SUN_DEG))
    # the disc's texels' solid angle, summed exactly as veil does (piecewise constant texels)
    dw = 2 * np.pi / w * (np.cos(np.pi * j / h) - np.cos(np.pi * (j + 1) / h))
    L[disc] = SUN_E / dw[disc].sum() * np.array([1.0, 0.93, 0.8])
    spec = oiio.ImageSpec(w, h, 3, oiio.FLOAT)
    buf = oiio.ImageBuf(spec)
    buf.set_pixels(oiio.ROI(), L.astype(np.float32))
    if not buf.write(path):
        sys.exit("environment.py: cannot write %s: %s" % (path, buf.geterror()))


def read(path):
    import OpenImageIO as oiio
    buf = oiio.ImageBuf(path)
    return list(buf.spec().channelnames), buf.get_pixels(oiio.FLOAT)


def behind(sc, env_rgb_of, w, h):
    """T-less environment radiance along each pixel's centre ray, as the reference sees it behind the medium."""
    import numpy as np
    cam = sc["camera"]
    pos, at = np.array(cam["position"], float), np.array(cam["look_at"], float)
    up = np.array(cam.get("up", [0, 1, 0]), float)
    f = at - pos
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    ty = np.tan(np.radians(cam.get("fov_y_deg", 45)) / 2)
    tx = ty * w / h
    py, px = np.mgrid[0:h, 0:w]
    sx = (2 * (px + 0.5) / w - 1) * tx
    sy = (1 - 2 * (py + 0.5) / h) * ty
    d = f[None, None] + sx[..., None] * r[None, None] + sy[..., None] * u[None, None]
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    return env_rgb_of(d)


def env_lookup(map_path):
    import numpy as np
    if map_path is None:
        return lambda d: np.broadcast_to(np.array(SKY), d.shape)
    _, m = read(map_path)
    h, w = m.shape[:2]

    def f(d):
        t = np.arccos(np.clip(d[..., 1], -1, 1))
        p = np.arctan2(d[..., 2], d[..., 0]) + np.pi
        i = np.clip((p / (2 * np.pi) * w).astype(int), 0, w - 1)
        j = np.clip((t / np.pi * h).astype(int), 0, h - 1)
        return m[j, i, :3]
    return f


def cycles_vs_reference(ref, cyc, lookup, sc, w, h, cyc_behind=True, ref_behind=True):
    """Both images' scattered light where T < 0.99: each less T x the environment where it sees it
    (cyc_behind, ref_behind; a scene of the cut's lights sees a black background instead)."""
    import numpy as np
    rn, rp = read(ref)
    cn, cp = read(cyc)
    T = 1.0 - rp[..., rn.index("A")]
    seen = T[..., None] * behind(sc, lookup, w, h)
    clear = T >= 1.0  # no medium: the reference is the environment itself there, exactly
    if ref_behind:
        off = float(np.abs(rp[..., [rn.index(c) for c in "RGB"]] - seen)[clear].max()) if clear.any() else 0.0
        if off > 1e-4 * float(np.abs(seen[clear]).max()):
            sys.exit("environment.py: the camera model here disagrees with veil's by %g where no medium is" % off)
    r_sc = rp[..., [rn.index(c) for c in "RGB"]] - (seen if ref_behind else 0.0)
    c_sc = cp[..., [cn.index(c) for c in "RGB"]] - (seen if cyc_behind else 0.0)
    se = np.abs(rp[..., [rn.index("stderr." + c) for c in "RGB"]])
    mask = T < 0.99
    r_mean, c_mean = float(r_sc[mask].mean()), float(c_sc[mask].mean())
    r_mean_se = float(np.sqrt((se[mask] ** 2).sum()) / se[mask].size)
    bias, bias_se = c_mean / r_mean - 1.0, (c_mean / r_mean) * r_mean_se / r_mean

    def blocks(x, b):
        hh, ww = x.shape[0] // b * b, x.shape[1] // b * b
        return x[:hh, :ww].reshape(hh // b, b, ww // b, b, -1).mean(axis=(1, 3))

    mb = blocks(mask[..., None].astype(np.float64), 4)[..., 0] > 0.999
    rb, cb = blocks(r_sc, 4), blocks(c_sc, 4)
    rel4 = float(np.sqrt(((cb - rb)[mb] ** 2).mean()) / np.abs(rb[mb]).mean())
    noise4 = float(np.sqrt((blocks(se ** 2, 4)[mb] / 16.0).mean()) / np.abs(rb[mb]).mean())
    return int(mask.sum()), bias, bias_se, rel4, noise4


def split(a, sc, scene_path, ref, img, lookup, w, h, name, sky, k, tmp):
    """The error of K lights taken apart: the cut itself (the reference of a scene whose lights are the
    cut's K directional lights, from `veil render --explain`, against the reference of the map) and
    the GPU pipeline (veil render against that reference of the same K lights)."""
    import re
    import subprocess
    text = subprocess.run([a.veil, "render", scene_path, "-o", os.path.join(tmp, "unused.exr"), "--explain"],
                          check=True, capture_output=True, text=True).stdout
    lights = []
    for m in re.finditer(r"cut +\d+ +direction \[([^\]]*)\] irradiance \[([^\]]*)\]", text):
        lights.append({"type": "directional", "direction": [float(v) for v in m.group(1).split(",")],
                       "irradiance": [float(v) for v in m.group(2).split(",")]})
    if len(lights) != k:
        sys.exit("environment.py: --explain listed %d cut lights, not %d" % (len(lights), k))
    sk = json.loads(json.dumps(sc))
    sk["lights"] = lights
    sk["background"] = {"color": [0.0, 0.0, 0.0]}
    cut_scene = os.path.join(tmp, "cut.json")
    with open(cut_scene, "w") as f:
        json.dump(sk, f, indent=1)
    cut_ref = os.path.join(tmp, "cut_ref.exr")
    peers.run([a.veil, "reference", cut_scene, "-o", cut_ref, "--spp", str(a.ref_spp), "--seed", "9"])
    _, cb, _, c4, _ = cycles_vs_reference(ref, cut_ref, lookup, sc, w, h, cyc_behind=False)
    _, gb, _, g4, n4 = cycles_vs_reference(cut_ref, img, lookup, sc, w, h, ref_behind=False)
    row = "| %s | %s | %d | %+.2f %% | %.2f %% | %+.2f %% | %.2f %% | %.2f %% |" % (name, sky, k, 100 * cb, 100 * c4,
                                                                            100 * gb, 100 * g4, 100 * n4)
    print(row, flush=True)
    return row


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--scenes", default="smoke,cloud")
    ap.add_argument("--skies", default="constant,hdri")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--ref-spp", type=int, default=2048)
    ap.add_argument("--cycles-spp", type=int, default=1024)
    ap.add_argument("--lights", default="1,2,4,8,16")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--split", default="8,16", help="the Ks whose error is taken apart (empty: none)")
    ap.add_argument("--remainder", default="cache,lights",
                    help="the environment's \"remainder\" settings to measure: cache (the median cut of its bright "
                         "part, the rest by the light cache's photons), lights (the whole map as the cut's lights)")
    ap.add_argument("--quality", default="default", help="veil render's --quality (a comma list)")
    ap.add_argument("--ref", default=None, help="a folder to keep the references in and reuse them from")
    ap.add_argument("--g", type=float, default=None, help="the medium's phase function: HG of this g instead")
    ap.add_argument("--no-cycles", action="store_true")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    tmp = tempfile.mkdtemp()
    hdri = os.path.join(tmp, "sky.exr")
    sky_map(hdri)
    lines = ["The environment light (issue 26), %dx%d, every order. `/usr/bin/python3 "
             "bench/peers_cycles/environment.py --size %s --ref-spp %d --cycles-spp %d --lights %s` (%s). "
             "Skies: constant %s; hdri: a 512x256 map with a smooth sky and a sun of %g degrees' radius 50 degrees "
             "up carrying %g W/m^2 (made by the script). The scenes' own lights removed."
             % (w, h, a.size, a.ref_spp, a.cycles_spp, a.lights, time.strftime("%Y-%m-%d"), SKY, SUN_DEG, SUN_E), ""]
    cyc_rows, gpu_rows, split_rows = [], [], []
    for name in a.scenes.split(","):
        for sky in a.skies.split(","):
            sc = smoke_scene(w, h) if name == "smoke" else cloud_scene(w, h)
            if a.g is not None:
                sc["medium"]["phase"] = {"type": "hg", "g": a.g}
            env = {"type": "environment", "color": SKY} if sky == "constant" else {"type": "environment", "file": hdri}
            sc["lights"] = [env]
            sc.pop("background", None)
            scene = os.path.join(tmp, "%s_%s.json" % (name, sky))
            with open(scene, "w") as f:
                json.dump(sc, f, indent=1)
            ref = os.path.join(a.ref or tmp, "%s_%s_%dx%d_%d%s_ref.exr" % (
                name, sky, w, h, a.ref_spp, "" if a.g is None else "_g%g" % a.g))
            t0 = time.perf_counter()
            if not (a.ref and os.path.exists(ref)):
                peers.run([a.veil, "reference", scene, "-o", ref, "--spp", str(a.ref_spp), "--seed", "7"])
            t_ref = time.perf_counter() - t0
            lookup = env_lookup(None if sky == "constant" else hdri)
            if not a.no_cycles:
                raw, cyc = os.path.join(tmp, "c_raw.exr"), os.path.join(tmp, "c.exr")
                t0 = time.perf_counter()
                peers.run([a.blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_scene.py"),
                           "--", scene, str(a.cycles_spp), "1", raw])
                t_cyc = time.perf_counter() - t0
                combined_to_rgba(raw, cyc)
                n, bias, bias_se, rel4, noise4 = cycles_vs_reference(ref, cyc, lookup, sc, w, h)
                cyc_rows.append("| %s | %s | %d | %+.3f %% | %.3f %% | %.2f %% | %.2f %% | %.1f s | %.1f s |" % (
                    name, sky, n, 100 * bias, 100 * bias_se, 100 * rel4, 100 * noise4, t_ref, t_cyc))
                print(cyc_rows[-1], flush=True)
            for k, rem, q in ((int(v), r, q) for v in a.lights.split(",") for r in a.remainder.split(",")
                              for q in a.quality.split(",")):
                sk = json.loads(json.dumps(sc))
                sk["lights"][0]["lights"] = k
                sk["lights"][0]["remainder"] = rem
                sp = os.path.join(tmp, "%s_%s_%d_%s.json" % (name, sky, k, rem))
                with open(sp, "w") as f:
                    json.dump(sk, f, indent=1)
                img = os.path.join(tmp, "gpu.exr")
                times = []
                for _ in range(a.runs):
                    t0 = time.perf_counter()
                    peers.run([a.veil, "render", sp, "-o", img, "--quality", q])
                    times.append(time.perf_counter() - t0)
                n, bias, bias_se, rel4, noise4 = cycles_vs_reference(ref, img, lookup, sc, w, h)
                if str(k) in a.split.split(",") and rem == "lights" and q == "default":
                    split_rows.append(split(a, sc, sp, ref, img, lookup, w, h, name, sky, k, tmp))
                gpu_rows.append("| %s | %s | %s | %d | %s | %.2f s | %+.2f %% | %.2f %% | %.2f %% |" % (
                    name, sky, rem, k, q, statistics.median(times), 100 * bias, 100 * rel4, 100 * noise4))
                print(gpu_rows[-1], flush=True)
    if cyc_rows:
        lines += ["Cycles against the reference: the light the medium scattered (each image less the exact T x "
                  "environment), over the pixels where T < 0.99; the bias's standard error is the reference's "
                  "noise alone, the 4x4 RMS difference holds both noises.", "",
                  "| scene | sky | pixels | mean bias | its se | RMS 4x4 | reference noise 4x4 | reference | Cycles |",
                  "|---|---|---:|---:|---:|---:|---:|---:|---:|"] + cyc_rows + [""]
    lines += ["`veil render` against the reference, measured as Cycles is: the light the medium scattered (the "
              "image less the reference's exact T x environment) where T < 0.99; time a median of %d whole runs "
              "(process start, GL context and every stage included). Remainder `cache`: the median cut of the "
              "map's bright part into at most K lights, the rest by the light cache's photons; `lights`: the "
              "whole map as K lights." % a.runs, "",
              "| scene | sky | remainder | lights K | quality | time | mean bias | RMS 4x4 | reference noise 4x4 |",
              "|---|---|---|---:|---|---:|---:|---:|---:|"]
    lines += gpu_rows + [""]
    if split_rows:
        lines += ["K = %s taken apart: the cut (the reference of its K directional lights against the reference of "
                  "the environment) and the GPU pipeline (veil render against the reference of those K lights), the "
                  "scattered light where T < 0.99." % a.split, "",
                  "| scene | sky | K | cut: mean bias | cut: RMS 4x4 | GPU: mean bias | GPU: RMS 4x4 | reference noise 4x4 |",
                  "|---|---|---:|---:|---:|---:|---:|---:|"] + split_rows + [""]
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "peers_cycles_environment.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
