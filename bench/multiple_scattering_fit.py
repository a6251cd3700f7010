#!/usr/bin/env python3
"""Fits the octave estimate's constants (multiple_scattering.octave_*,
octaves) by a grid search on the scenes in the repository (fog_lights, demo,
cloud, vdb_smoke: the "fitted on" scenes of bench/multiple_scattering.py),
each at two optical thicknesses (the file's and --thick times it), and
reports the chosen set on the others (../shared/data VDBs, when there).

    python3 bench/multiple_scattering_fit.py [--size 160x120] [--spp 256]
        [--ref-veil PATH] [--screen-space]

The first fit (gate "legs") searched a in {0.15, 0.3, 0.5}, b in {0.6, 0.75,
0.85, 0.95}, c = 0.6, N in {3, 6}; the defaults' fit (gate "escape") the
arguments' defaults below. Objective: the mean over the fitting scenes of the 4x4-binned relative RMSE
with the reference noise taken out (veil compare --bin 4). References are
those of bench/multiple_scattering.py (same cache and key).
"""
import argparse, itertools, json, os, sys, tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import multiple_scattering as ms  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--veil", default=os.path.join(ms.ROOT, "build", "veil"))
    ap.add_argument("--ref-veil", default="")
    ap.add_argument("--screen-space", action="store_true", help="fit with the screen-space spread on")
    ap.add_argument("--thick", type=float, default=3.0, help="each scene also with sigma x this")
    ap.add_argument("--gate", default="escape", choices=("legs", "escape"), help="multiple_scattering.octave_gate")
    ap.add_argument("--a", default="0.3,0.5,0.7", help="octave_extinction values")
    ap.add_argument("--b", default="0.8,0.85,0.9", help="octave_contribution values")
    ap.add_argument("--c", default="0.5,0.7", help="octave_eccentricity values")
    ap.add_argument("--n", default="6,10", help="octaves values")
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    ref_veil = a.ref_veil or a.veil
    cache = os.path.join(ms.ROOT, "build", "bench-cache", "ms")
    os.makedirs(cache, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="veil-fit-")
    scenes = []
    for (name, base, folder, fit), k in itertools.product(ms.scenes(), (1.0, a.thick)):
        scene = ms.absolutise(ms.thicken(base, k), folder)
        name = name if k == 1.0 else "%s x%g" % (name, k)
        text = json.dumps(ms.with_ms(scene, None), sort_keys=True)
        ref = os.path.join(cache, ms.reference_key(text, w, h, a.spp, ref_veil) + ".exr")
        if not os.path.exists(ref):
            sp = os.path.join(tmp, "ref.json")
            with open(sp, "w") as f:
                f.write(text)
            print("reference %s ..." % name, file=sys.stderr, flush=True)
            ms.run([ref_veil, "reference", sp, "-o", ref + ".part.exr", "--spp", str(a.spp), "--width", str(w),
                    "--height", str(h)])
            os.replace(ref + ".part.exr", ref)
        scenes.append((name, scene, ref, fit))

    def score(params):
        out = {}
        for name, scene, ref, fit in scenes:
            sp = os.path.join(tmp, "v.json")
            with open(sp, "w") as f:
                json.dump(ms.with_ms(scene, params), f)
            img = os.path.join(tmp, "v.exr")
            ms.run([a.veil, "render", sp, "-o", img, "--width", str(w), "--height", str(h)])
            c = json.loads(ms.run([a.veil, "compare", img, ref, "--bin", "4", "--json"]))
            out[name] = (c["rel_rmse_excess"], c["mean_bias"], fit)
        fitted = [v[0] for v in out.values() if v[2]]
        return sum(fitted) / len(fitted), out

    floats = lambda v: [float(x) for x in v.split(",")]
    grid = itertools.product(floats(a.a), floats(a.b), floats(a.c), [int(x) for x in a.n.split(",")])
    best = None
    for oa, ob, oc, n in grid:
        params = {"screen_space": a.screen_space, "volumetric": True, "octave_gate": a.gate, "octave_extinction": oa,
                  "octave_contribution": ob, "octave_eccentricity": oc, "octaves": n}
        s, out = score(params)
        line = " ".join("%s %.0f/%+.0f" % (k.replace(".vdb", "")[:9].replace(" ", ""), 100 * v[0], 100 * v[1])
                        for k, v in out.items())
        print("a %.2f b %.2f c %.1f N %2d: fit mean %.1f %% | %s" % (oa, ob, oc, n, 100 * s, line), flush=True)
        if best is None or s < best[0]:
            best = (s, params, out)
    print("\nbest on the fitting scenes: %s, mean %.1f %%" % (json.dumps(best[1]), 100 * best[0]))
    for k, v in best[2].items():
        print("  %-26s %s  rel. RMSE %.1f %%  bias %+.1f %%" % (k, "fitted" if v[2] else "check ", 100 * v[0],
                                                                  100 * v[1]))


if __name__ == "__main__":
    main()
