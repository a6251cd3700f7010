#!/usr/bin/python3
"""`veil fog` against the Cycles truth (truth.py): energy and error, by part.

    /usr/bin/python3 bench/fog_truth/compare.py OUTDIR [--veil build/veil] [--cases night,day]

OUTDIR holds CASE_nofog.exr (the surfaces, seed 1) and CASE_fog_s1.exr,
CASE_fog_s2.exr (the truth, two seeds) from run.sh. For each case this
writes the frame `veil fog` reads (CASE_frame.exr: R, G, B, Z; Cycles'
1e10 "no hit" depth as +inf), the veil scenes of each variant, runs
`veil fog --stats` on the frame, and prints per variant:

- bias: mean RGB of veil / mean RGB of the truth - 1;
- rel-RMSE per pixel and of 4x4-pixel means: the metric of `veil compare`
  (reference/compare.c: sqrt of the mean over pixels and channels of
  (|a - b| / max(|b|, floor))^2, floor 1 % of the truth's mean), with the
  truth's own noise taken out in quadrature (excess = sqrt(max(0, e^2 -
  noise^2))). The noise: the truth is the mean M = (A + B) / 2 of two
  independent seeds, so var(M) = var(A - B) / 4 and each pixel's (or
  block's) standard error is estimated by |A - B| / 2; noise is the rms of
  it relative to M with the same floor;
- time: the sum of the stages' wall times that `--stats` reports (ms).

Then the parts, truth passes against veil differences:
  surfaces: Cycles (DiffDir + DiffInd) DiffCol  vs veil's T frame (no lights, no spread)
  single:   Cycles VolumeDir                    vs veil ss - T frame
  higher:   Cycles VolumeInd                    vs veil default - ss (volumetric + spread)
and the same split of veil's own higher orders (octaves: ss+oct - ss;
spread: default - ss+oct).
"""
import argparse
import json
import os
import re
import subprocess
import sys
import time

import numpy as np
import OpenImageIO as oiio

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import scenes  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# name, lights, multiple_scattering, extra arguments: the variants; each removes one part
VARIANTS = [
    ("attenuation", False, {"screen_space": False}, []),
    ("atten+spread", False, None, []),
    ("ss", True, {"screen_space": False, "volumetric": False}, []),
    ("ss+volumetric", True, {"screen_space": False}, []),  # the default volumetric estimate (the light cache)
    ("ss+octaves", True, {"screen_space": False, "volumetric_method": "octave"}, []),
    ("ss+spread", True, {"volumetric": False}, []),
    ("default", True, None, []),
    # the frame's surfaces neither shadow the medium nor absorb its light (scene/solid.h)
    ("no occluders", True, None, ["--no-occluders"]),
]


def read_exr(path):
    b = oiio.ImageBuf(path)
    if b.has_error:
        sys.exit("compare.py: %s: %s" % (path, b.geterror()))
    names = list(b.spec().channelnames)
    a = b.get_pixels(oiio.FLOAT)
    return names, a


def layer(names, a, prefix, chans="RGB"):
    out = []
    for c in chans:
        key = prefix + "." + c
        if key not in names:
            key2 = "ViewLayer." + key
            if key2 not in names:
                sys.exit("compare.py: no channel %s (have %s)" % (key, ", ".join(names)))
            key = key2
        out.append(a[..., names.index(key)])
    return np.stack(out, axis=-1).astype(np.float64)


def write_frame(path, rgb, z):
    h, w = z.shape
    spec = oiio.ImageSpec(w, h, 4, oiio.FLOAT)
    spec.channelnames = ("R", "G", "B", "Z")
    px = np.concatenate([rgb.astype(np.float32), z[..., None].astype(np.float32)], axis=-1)
    out = oiio.ImageOutput.create(path)
    if not out or not out.open(path, spec) or not out.write_image(px):
        sys.exit("compare.py: cannot write %s" % path)
    out.close()


def block(img, b):
    if b == 1:
        return img
    h, w = img.shape[0] // b * b, img.shape[1] // b * b
    x = img[:h, :w].reshape(h // b, b, w // b, b, -1)
    return x.mean(axis=(1, 3))


def metrics(a, ref, ref_a, ref_b, b):
    """bias, rel-RMSE and noise of a against ref = (ref_a + ref_b) / 2, b x b blocks"""
    A, R = block(a, b), block(ref, b)
    se = np.abs(block(ref_a, b) - block(ref_b, b)) / 2.0
    floor = max(0.01 * float(np.abs(R).mean()), 1e-30)
    den = np.maximum(np.abs(R), floor)
    e = float(np.sqrt(np.mean((np.abs(A - R) / den) ** 2)))
    noise = float(np.sqrt(np.mean((se / den) ** 2)))
    return e, noise, float(np.sqrt(max(0.0, e * e - noise * noise)))


def stats_ms(text):
    ms = 0.0
    for line in text.splitlines():
        m = re.match(r"^\S+\s+([0-9.]+) ms", line)
        if m:
            ms += float(m.group(1))
    return ms


def run_veil(veil, frame, scene, out, folder, name, extra):
    path = os.path.join(folder, name + ".json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    t0 = time.time()
    p = subprocess.run([veil, "fog", frame, "--scene", path, "-o", out, "--stats"] + extra, capture_output=True,
                       text=True)
    wall = time.time() - t0
    if p.returncode != 0:
        sys.exit("compare.py: veil fog failed on %s:\n%s%s" % (path, p.stdout, p.stderr))
    return stats_ms(p.stdout), wall


def rgb_of(path):
    names, a = read_exr(path)
    if "R" in names:
        return np.stack([a[..., names.index(c)] for c in "RGB"], axis=-1).astype(np.float64)
    return layer(names, a, "Combined")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("outdir")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--cases", default="night,day")
    ap.add_argument("--json", help="also write the numbers here")
    args = ap.parse_args()
    results = {}
    for case in args.cases.split(","):
        d = args.outdir
        n0, a0 = read_exr(os.path.join(d, case + "_nofog.exr"))
        n1, a1 = read_exr(os.path.join(d, case + "_fog_s1.exr"))
        n2, a2 = read_exr(os.path.join(d, case + "_fog_s2.exr"))
        frame = layer(n0, a0, "Combined")
        z = layer(n0, a0, "Depth", "Z")[..., 0]
        z = np.where(z >= 1e9, np.inf, z)  # Cycles writes 1e10 where nothing was hit
        frame_path = os.path.join(d, case + "_frame.exr")
        write_frame(frame_path, frame, z)
        ta, tb = layer(n1, a1, "Combined"), layer(n2, a2, "Combined")
        truth = (ta + tb) / 2.0
        parts_t = {}
        for nm, aa in (("a", a1), ("b", a2)):
            col = [layer(n, aa, "DiffCol") for n in (n1,)][0]
            nn = n1
            parts_t.setdefault("surfaces", []).append((layer(nn, aa, "DiffDir") + layer(nn, aa, "DiffInd")) * col)
            parts_t.setdefault("surf_direct", []).append(layer(nn, aa, "DiffDir") * col)
            parts_t.setdefault("single", []).append(layer(nn, aa, "VolumeDir"))
            parts_t.setdefault("higher", []).append(layer(nn, aa, "VolumeInd"))
        m_truth = float(truth.mean())
        print("\n== %s: truth mean RGB %.5g (frame without fog %.5g); truth noise (4x4) %.2f %%, per pixel %.2f %%"
              % (case, m_truth, float(frame.mean()), 100 * metrics(truth, truth, ta, tb, 4)[1],
                 100 * metrics(truth, truth, ta, tb, 1)[1]))
        for k, (pa, pb) in parts_t.items():
            print("   truth part %-12s mean %.5g (%5.1f %% of the truth)" % (k, float((pa + pb).mean() / 2),
                                                                       100 * float((pa + pb).mean() / 2) / m_truth))
        print("   %-14s %9s %14s %14s %10s" % ("variant", "bias", "relRMSE 4x4", "per pixel", "time (ms)"))
        imgs = {}
        res = {}
        for name, lights, ms, extra in VARIANTS:
            tag = name.replace(" ", "_")
            out = os.path.join(d, "%s_veil_%s.exr" % (case, tag))
            sc = scenes.veil_scene(case, lights=lights, multiple=ms)
            t_ms, wall = run_veil(args.veil, frame_path, sc, out, d, "%s_%s" % (case, tag), extra)
            img = rgb_of(out)
            imgs[name] = img
            bias = float(img.mean()) / m_truth - 1.0
            e4, nz4, x4 = metrics(img, truth, ta, tb, 4)
            e1, nz1, x1 = metrics(img, truth, ta, tb, 1)
            res[name] = {"bias": bias, "rel_rmse_4x4": x4, "rel_rmse_px": x1, "noise_4x4": nz4, "noise_px": nz1,
                         "ms": t_ms}
            print("   %-14s %+8.1f %% %12.1f %% %12.1f %% %10.0f" % (name, 100 * bias, 100 * x4, 100 * x1, t_ms))
        # parts, as means relative to the truth's total mean
        T = imgs["attenuation"]
        vparts = {
            "surfaces (T frame)": (T, "surfaces"),
            "single": (imgs["ss"] - T, "single"),
            "higher (vol+spread)": (imgs["default"] - imgs["ss"], "higher"),
        }
        print("   parts (mean, %% of the truth's total): veil vs Cycles")
        for k, (v, tk) in vparts.items():
            pt = sum(parts_t[tk]) / 2.0
            print("     %-20s veil %6.1f %%  Cycles %6.1f %%  (veil/Cycles %.2f)" % (
                k, 100 * float(v.mean()) / m_truth, 100 * float(pt.mean()) / m_truth,
                float(v.mean()) / max(float(pt.mean()), 1e-30)))
        print("     of veil's higher: volumetric (default) %.1f %% (the octaves instead: %.1f %%), spread of the "
              "frame %.1f %%" % (100 * float((imgs["ss+volumetric"] - imgs["ss"]).mean()) / m_truth,
                                 100 * float((imgs["ss+octaves"] - imgs["ss"]).mean()) / m_truth,
                                 100 * float((imgs["default"] - imgs["ss+volumetric"]).mean()) / m_truth))
        print("     the frame's spread alone (no lights): %.1f %%; Cycles' surfaces lit directly: %.1f %%" % (
            100 * float((imgs["atten+spread"] - T).mean()) / m_truth,
            100 * float((sum(parts_t["surf_direct"]) / 2).mean()) / m_truth))
        bl1, bl2 = (os.path.join(d, "%s_black_s%d.exr" % (case, k)) for k in (1, 2))
        if os.path.exists(bl1) and os.path.exists(bl2):
            # Cycles with black surfaces: the medium's own light from the lights, all orders
            med = (rgb_of(bl1) + rgb_of(bl2)) / 2.0
            vmed = imgs["ss+volumetric"] - T
            print("   split by black surfaces (truth.py FOG 2), %% of the truth's total:")
            print("     medium's light (lights, all orders)  veil ss+volumetric %6.1f %%  Cycles %6.1f %%  (veil/Cycles %.2f)"
                  % (100 * float(vmed.mean()) / m_truth, 100 * float(med.mean()) / m_truth,
                     float(vmed.mean()) / max(float(med.mean()), 1e-30)))
            print("       of which orders >= 2               veil volumetric %6.1f %%  Cycles %6.1f %%" % (
                100 * float((imgs["ss+volumetric"] - imgs["ss"]).mean()) / m_truth,
                100 * float((med - sum(parts_t["single"]) / 2).mean()) / m_truth))
            vsurf = imgs["atten+spread"]
            tsurf = truth - med
            print("     light that meets a surface           veil T frame + spread %6.1f %%  Cycles %6.1f %%  "
                  "(veil/Cycles %.2f)" % (100 * float(vsurf.mean()) / m_truth, 100 * float(tsurf.mean()) / m_truth,
                                          float(vsurf.mean()) / max(float(tsurf.mean()), 1e-30)))
            print("       of which scattered on the way      veil spread %6.1f %%  Cycles %6.1f %%" % (
                100 * float((vsurf - T).mean()) / m_truth,
                100 * float((tsurf - sum(parts_t["surfaces"]) / 2).mean()) / m_truth))
            res["split"] = {"medium_veil": float(vmed.mean()) / m_truth, "medium_cycles": float(med.mean()) / m_truth,
                            "surface_veil": float(vsurf.mean()) / m_truth,
                            "surface_cycles": float(tsurf.mean()) / m_truth}
        res["parts"] = {k: {"veil": float(v.mean()) / m_truth, "cycles": float((sum(parts_t[tk]) / 2).mean()) / m_truth}
                        for k, (v, tk) in vparts.items()}
        results[case] = res
    if args.json:
        with open(args.json, "w") as f:
            json.dump(results, f, indent=1)


if __name__ == "__main__":
    main()
