"""Checks a deep EXR against the flat EXR of the same render, through OpenImageIO (Debian's
python3-openimageio, which scripts/install-deps.sh installs): a consumer's reading of the file.

    deep_check.py DEEP.exr FLAT.exr CAP BR,BG,BB

FLAT has the AOVs (--aovs: T.R, T.G, T.B); B is the scene's background. Checks:
  - the file is deep scanline, ZIPS, channels R, G, B, A, Z, ZBack;
  - every pixel: at most CAP samples, Z < ZBack, sorted, not overlapping, 0 <= A <= 1;
  - OpenImageIO's flatten equals the flat image less T x background, within a bound derived from
    the flatten's float arithmetic. OpenImageIO's flatten composites front to back in float:
    per sample s, with a the alpha accumulated so far, val += (1 - a) * v for each channel (the
    alpha channel too, so a is updated the same way). With u = 2^-24: a's absolute error grows by
    at most 3u a sample (1 - a, the product, the sum; every term <= 1), e_k <= 3 k u before sample
    k; colour channel c then adds |v_k| (e_k + u) (the error of 1 - a, and its rounding) + u T_k |v_k|
    (the product) + u |val| (the sum, |val| <= S = sum_k T_k |v_k|, T_k the exact transmittance in
    front of sample k). Over n samples, first order:
        |flatten - exact| <= u [sum_k |v_k| (3k + 1 + T_k) + n S].
    The samples were made so that their exact flatten is the target up to the float storage of each
    colour (u T_k |v_k| more, u S in all). Second-order terms (products of two u's, n <= 64) are below
    1 % of this and are covered by a factor 1.01; alpha the same with v_k = A_k.
Prints the worst error as a fraction of its bound; exits 1 on any failure."""
import sys

import numpy as np
import OpenImageIO as oiio

U = 2.0 ** -24


def main():
    deep_path, flat_path, cap = sys.argv[1], sys.argv[2], int(sys.argv[3])
    bg = [float(np.float32(x)) for x in sys.argv[4].split(",")]  # as the scene reader stores it
    fails = []
    deep = oiio.ImageBuf(deep_path)
    spec = deep.spec()
    if not deep.deep or deep.has_error:
        sys.exit(f"FAIL: {deep_path} is not a deep image: {deep.geterror()}")
    names = list(spec.channelnames)
    if sorted(names) != sorted(["R", "G", "B", "A", "Z", "ZBack"]):
        fails.append(f"channels {names}")
    if spec.get_string_attribute("compression") != "zips":
        fails.append(f"compression {spec.get_string_attribute('compression')}")
    if spec.tile_width:
        fails.append("tiled, not scanline")
    ch = {n: names.index(n) for n in names}
    flat = oiio.ImageBuf(flat_path)
    fspec = flat.spec()
    fpix = flat.get_pixels(oiio.FLOAT).reshape(fspec.height, fspec.width, fspec.nchannels)
    fch = {n: i for i, n in enumerate(fspec.channelnames)}
    flattened = oiio.ImageBufAlgo.flatten(deep)
    if flattened.has_error:
        sys.exit(f"FAIL: flatten: {flattened.geterror()}")
    gspec = flattened.spec()
    gpix = flattened.get_pixels(oiio.FLOAT).reshape(gspec.height, gspec.width, gspec.nchannels)
    gch = {n: i for i, n in enumerate(gspec.channelnames)}
    dd = deep.deepdata()
    w, h = spec.width, spec.height
    worst, samples, most, split = 0.0, 0, 0, 0
    for y in range(h):
        for x in range(w):
            p = y * w + x
            n = dd.samples(p)
            samples += n
            most = max(most, n)
            split += n > 1
            if n > cap:
                fails.append(f"pixel {x},{y}: {n} samples, cap {cap}")
            v = np.array([[dd.deep_value(p, ch[c], s) for c in ("R", "G", "B", "A", "Z", "ZBack")]
                          for s in range(n)], dtype=np.float64).reshape(n, 6)
            for s in range(n):
                if not (v[s, 4] < v[s, 5] and 0.0 <= v[s, 3] <= 1.0 and (s == 0 or v[s, 4] >= v[s - 1, 5])):
                    fails.append(f"pixel {x},{y} sample {s}: A {v[s, 3]} Z {v[s, 4]} ZBack {v[s, 5]}")
            T = np.concatenate(([1.0], np.cumprod(1.0 - v[:, 3])))[:n]
            k = np.arange(n)
            for i, c in enumerate(("R", "G", "B", "A")):
                vk = np.abs(v[:, i])
                S = float(np.sum(T * vk))
                bound = 1.01 * U * (float(np.sum(vk * (3 * k + 1 + T))) + n * S + S)
                target = float(fpix[y, x, fch[c]])
                if i < 3:
                    target -= float(fpix[y, x, fch["T." + c]]) * bg[i]
                e = abs(float(gpix[y, x, gch[c]]) - target)
                if e > bound:
                    fails.append(f"pixel {x},{y} {c}: flatten {gpix[y, x, gch[c]]!r}, flat less T bg {target!r}, "
                                 f"bound {bound:.3g}")
                elif bound > 0:
                    worst = max(worst, e / bound)
    print(f"{w}x{h}: {samples} samples, at most {most} a pixel, {split} pixels with more than one; "
          f"flatten error at most {worst:.3f} of its bound")
    if split == 0:
        fails.append("no pixel has more than one sample: the split is untested")
    for f in fails[:10]:
        print("FAIL:", f)
    sys.exit(1 if fails else 0)


main()
