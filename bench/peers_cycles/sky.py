#!/usr/bin/env python3
"""The ruler under a sky (issue 26, first step): `veil reference --background lights` (a constant sky
that lights the medium, every order, the phase function sampling it) against Blender 3.4 Cycles' world
lighting of the same colour, on the shared smoke, before the reference judges any sky approximation.

    /usr/bin/python3 bench/peers_cycles/sky.py [--size 160x120] [--ref-spp 1024] [--cycles-spp 1024]
        [--sky 0.5,0.65,0.9] [--veil build/veil] [--out docs/results]

The scene: bench/regress.py's smoke (sigma_s 0.093, sigma_a 0.007, HG g 0.3, the VDB at its own voxels)
without its lights, its background the sky colour. Compared: the light the medium scattered (each
image less the exact T x sky, which is the same in both), where the medium is: the mean bias with its
standard error (from the reference's stderr channels; Cycles writes none, so its own noise adds to the
spread), and the RMS difference on 4x4 blocks.
Results: OUT/peers_cycles_sky.md. Needs blender, numpy and OpenImageIO for /usr/bin/python3."""
import argparse, json, os, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)
import peers  # noqa: E402
from run import combined_to_rgba, smoke_scene  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--ref-spp", type=int, default=1024)
    ap.add_argument("--cycles-spp", type=int, default=1024)
    ap.add_argument("--sky", default="0.5,0.65,0.9")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    sky = [float(v) for v in a.sky.split(",")]
    sc = smoke_scene(w, h)
    sc["lights"] = []
    sc["background"] = {"color": sky}
    tmp = tempfile.mkdtemp()
    scene = os.path.join(tmp, "sky.json")
    with open(scene, "w") as f:
        json.dump(sc, f, indent=1)
    ref, cyc, cyc_raw = (os.path.join(tmp, n) for n in ("ref.exr", "cycles.exr", "cycles_raw.exr"))
    t0 = time.perf_counter()
    peers.run([a.veil, "reference", scene, "-o", ref, "--spp", str(a.ref_spp), "--seed", "7", "--background",
               "lights"])
    t_ref = time.perf_counter() - t0
    t0 = time.perf_counter()
    peers.run([a.blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_scene.py"), "--",
               scene, str(a.cycles_spp), "1", cyc_raw, "sky"])
    t_cyc = time.perf_counter() - t0
    combined_to_rgba(cyc_raw, cyc)
    # The sky seen straight through the medium, T sky, is the same in both (the reference's T is exact,
    # Cycles' an unbiased estimate of it) and would swamp the comparison (most pixels are sky): both
    # images less the exact T sky leave the light the medium scattered, compared where the medium is
    # (T < 0.99): environment.py's measure, with the sky as a constant environment.
    import numpy as np
    from environment import cycles_vs_reference
    n, bias, bias_se, rel4, noise4 = cycles_vs_reference(
        ref, cyc, lambda d: np.broadcast_to(np.array(sky, dtype=np.float64), d.shape), sc, w, h)
    lines = ["The shared smoke under a constant sky %s (no other light), %dx%d, every order: `veil reference "
             "--background lights` at %d spp (%.1f s) against Blender 3.4 Cycles' world lighting at %d spp (%.1f s "
             "wall). `/usr/bin/python3 bench/peers_cycles/sky.py --size %s --ref-spp %d --cycles-spp %d` (%s). "
             "Compared: the light the medium scattered (each image less the exact T x sky), over the %d pixels "
             "where T < 0.99." % (sky, w, h, a.ref_spp, t_ref, a.cycles_spp, t_cyc, a.size, a.ref_spp,
                                  a.cycles_spp, time.strftime("%Y-%m-%d"), n), "",
             "| Cycles against the reference, scattered light | value |", "|---|---:|",
             "| mean bias (Cycles' mean / the reference's - 1) | %+.3f %% |" % (100 * bias),
             "| its standard error (the reference's noise alone) | %.3f %% |" % (100 * bias_se),
             "| relative RMS difference on 4x4 blocks (both noises in) | %.2f %% |" % (100 * rel4),
             "| the reference's own noise on 4x4 blocks | %.2f %% |" % (100 * noise4), ""]
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "peers_cycles_sky.md"), "w") as f:
        f.write("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
