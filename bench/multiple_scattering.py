#!/usr/bin/env python3
"""veil multiple-scattering benchmark: time against error of single scattering
alone, the octaves, and the light cache at every quality rung (with single
scattering at the same rung beside it, for the time ratio), against the
all-orders path tracer (`veil reference --max-order 0`).

    python3 bench/multiple_scattering.py [--quick] [--size WxH] [--spp N]
        [--runs R] [--scenes a,b,...] [--candidates] [--study] [--veil build/veil]
    python3 bench/multiple_scattering.py --converge "demo;dense fog, lamp inside" [--size WxH] [--spp N]

--converge: the cache's error against its budget (photons doubling, then
cells), into docs/results/cache_convergence.{md,dat,png}.

    python3 bench/multiple_scattering.py --times [--rungs default,max] [--runs R] [--scenes a,b,...]

--times: no reference, no error; each scene's still frame at its own
camera's size (the size a user renders it at; the error table is at
--size), single scattering and the light cache at each of --rungs, run in
turn R times (default 3): medians of the stages' sum and the
median of the pairs' ratios, into docs/results/still_times.md.

For each scene (at two optical thicknesses: the file's sigma_a, sigma_s and
those times --thick) it renders every variant with `veil render --stats`
(time: the median over --runs of the sum of the stages' wall times, i.e. a
still frame without process start and file writing; per turntable frame:
render + spread, the stages a moving camera re-runs; the volumetric field
is view-independent and kept). The smoke (../shared/data) is also measured
at --thick times its coefficients., and compares it with
`veil compare --bin 4 --json`: rel_rmse_excess (relative RMSE of 4x4-pixel
means with the reference's own noise taken out in quadrature) and
mean_bias (mean RGB / reference's - 1) with mean_bias_se, its standard error
from the reference's noise (the cloud's lamp makes it several per cent).
--study adds the screen-space
pass's filter sizes and interpolations, and its MIP chains against the
gathering filter (bench/spread_gather).

The references' noise is heavy-tailed on the bright clouds: against 8192-spp
references, the 512-spp one of the side-lit cumulus was 28 % off per 4x4 block
while its own standard errors said 16 %, and the cloud's (a lamp inside a dense
puff) 98 % off against 9.7 %. So the cumulus scenes render their references
at REF_SPP_SCALE times --spp; the results in docs/ are at --spp 4096.

References are cached in build/bench-cache/ms/, keyed by the scene text, the
image size, spp and the bytes of the veil binary that renders them
(--ref-veil, default --veil); --ref-map FILE names them instead (a JSON
object, scene label: EXR path, relative to the repository), for references
rendered by an earlier build of the ruler. Scenes in
../shared/data (third-party VDBs) are used when present, skipped otherwise.
Results: docs/results/multiple_scattering.{csv,md} (and .png with gnuplot).
Python 3 standard library only.
"""
import argparse, csv, hashlib, json, os, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")

CACHE = {"screen_space": False, "volumetric": True, "volumetric_method": "cache"}
# (name, multiple_scattering fields, quality rung): single scattering and the light cache at every rung
# (the cache's budget is the rung's: frame/stages.c), the octaves and the other candidates at the default
VARIANTS = [
    ("ss", {"screen_space": False, "volumetric": False}, "default"),
    ("octaves", {"screen_space": False, "volumetric": True, "volumetric_method": "octave", "octave_gate": "escape"},
     "default"),
    ("ss draft", {"screen_space": False, "volumetric": False}, "draft"),
    ("cache draft", CACHE, "draft"),
    ("cache default", CACHE, "default"),
    # the later light read from its lobe, and gathered towards the camera, whatever g (the default gathers
    # where HG g >= 1/sqrt(2): render/march.h)
    ("cache default, lobe", dict(CACHE, cache_gather_rays=-1), "default"),
    ("cache default, gathered", dict(CACHE, cache_gather_rays=16), "default"),
    ("ss high", {"screen_space": False, "volumetric": False}, "high"),
    ("cache high", CACHE, "high"),
    ("ss max", {"screen_space": False, "volumetric": False}, "max"),
    ("cache max", CACHE, "max"),
]
# the earlier candidates (docs/multiple-scattering.md), with --candidates
CANDIDATES = [
    ("ss+screen", {"screen_space": True, "volumetric": False}, "default"),
    ("ss+octave legs", {"screen_space": False, "volumetric": True, "volumetric_method": "octave", "octave_gate": "legs",
                        "octaves": 3, "octave_extinction": 0.3, "octave_contribution": 0.75,
                        "octave_eccentricity": 0.6}, "default"),
    ("ss+diffusion", {"screen_space": False, "volumetric": True, "volumetric_method": "diffusion"}, "default"),
]
STUDY = [("screen %s %s" % (f, i), {"screen_space": True, "volumetric": False, "filter": f, "interpolation": i},
          "default") for f in ("2x2", "4x4", "6x6") for i in ("linear-bilinear", "linear-bicubic", "cubic-bicubic")]


# scenes whose reference takes more samples than --spp (see the docstring)
REF_SPP_SCALE = {"cumulus, sun behind": 2, "cumulus, sun at the side": 2}


def shared_scene(vdb, camera, sigma_a, sigma_s, g, lights, scale=1.0):
    return {"camera": camera,
            "medium": {"sigma_a": sigma_a, "sigma_s": sigma_s, "phase": {"type": "hg", "g": g},
                       "max_resolution": 128,
                       "sources": [{"type": "vdb", "file": vdb, "density_scale": scale}]},
            "lights": lights, "background": {"color": [0.0, 0.0, 0.0]}}


def cumulus(direction):
    """The cloud scene's puffs as a bright cumulus (albedo 0.999, HG g 0.85), one sun: what cloud renderers
    are judged on; the octaves were never fitted on it."""
    with open(os.path.join(ROOT, "data", "scenes", "cloud.json")) as f:
        s = json.load(f)
    s["medium"]["sigma_s"] = [1.6, 1.6, 1.6]
    s["medium"]["sigma_a"] = [0.0016, 0.0016, 0.0016]
    s["medium"]["phase"] = {"type": "hg", "g": 0.85}
    s["lights"] = [{"type": "directional", "direction": direction, "irradiance": [3.0, 2.9, 2.7]}]
    s["background"] = {"color": [0.0, 0.0, 0.0]}
    return s


def fog_lamp():
    """Dense fog (about 2.5 optical depths to the walls) with a lamp inside it, never fitted on."""
    return {"camera": {"position": [0.0, 1.5, 4.0], "look_at": [0.0, 1.2, -2.0], "fov_y_deg": 55,
                       "width": 640, "height": 480},
            "medium": {"sigma_a": [0.03, 0.03, 0.03], "sigma_s": [0.9, 0.92, 0.95], "phase": {"type": "hg", "g": 0.4},
                       "sources": [{"type": "exponential", "density": 1.0, "falloff": 0.0, "direction": [0, 1, 0],
                                    "origin": [0, 0, 0], "bounds": [[-3.0, 0.0, -5.0], [3.0, 3.0, 5.0]]}]},
            "lights": [{"type": "point", "position": [0.3, 1.6, -1.5], "intensity": [6.0, 4.5, 2.5]}],
            "background": {"color": [0.0, 0.0, 0.0]}}


def scenes():
    """(name, scene dict, folder for relative paths, fitted-on?, also at --thick?)"""
    out = []
    for name, fit in (("fog_lights", True), ("demo", True), ("cloud", True), ("vdb_smoke", True), ("pyro", False)):
        path = os.path.join(ROOT, "data", "scenes", name + ".json")
        with open(path) as f:
            sc = json.load(f)
        vdbs = [src["file"] for src in sc["medium"].get("sources", []) if src.get("type") == "vdb"]
        if any(not os.path.exists(os.path.join(os.path.dirname(path), v)) for v in vdbs):
            print("skipped %s: run make data first" % name, file=sys.stderr)
            continue
        out.append((name, sc, os.path.dirname(path), fit, False))
    out.append(("cumulus, sun behind", cumulus([0.1, -0.35, 0.93]), ROOT, False, False))
    out.append(("cumulus, sun at the side", cumulus([-0.95, -0.3, 0.05]), ROOT, False, False))
    out.append(("dense fog, lamp inside", fog_lamp(), ROOT, False, False))
    smoke = os.path.join(SHARED, "smoke.vdb")
    if os.path.exists(smoke):
        # index (1,2,1)..(111,223,112), voxel 0.476: about 53 x 106 x 53 m
        cam = {"position": [26.0, 45.0, 150.0], "look_at": [26.0, 52.0, 26.0], "fov_y_deg": 45,
               "width": 640, "height": 480}
        lights = [{"type": "directional", "direction": [0.45, -0.7, -0.55], "irradiance": [2.6, 2.5, 2.3]},
                  {"type": "point", "position": [26.0, 30.0, 26.0], "intensity": [900.0, 500.0, 200.0]}]
        out.append(("smoke.vdb", shared_scene(smoke, cam, [0.007, 0.007, 0.007], [0.093, 0.093, 0.093], 0.3,
                                              lights), ROOT, False, True))
    dragon = os.path.join(SHARED, "dragon_with_xform.vdb")
    if os.path.exists(dragon):
        cam = {"position": [0.0, 1.0, 9.0], "look_at": [0.0, 0.0, 0.0], "fov_y_deg": 40, "width": 640, "height": 480}
        lights = [{"type": "directional", "direction": [0.4, -0.7, -0.6], "irradiance": [3.0, 2.9, 2.7]}]
        out.append(("dragon.vdb (albedo 0.99)", shared_scene(dragon, cam, [0.02, 0.02, 0.02], [2.0, 2.0, 2.0], 0.6,
                                                             lights), ROOT, False, False))
    return out


def thicken(scene, k):
    s = json.loads(json.dumps(scene))
    for key in ("sigma_a", "sigma_s"):
        s["medium"][key] = [v * k for v in s["medium"].get(key, [0, 0, 0])]
    return s


def with_ms(scene, ms):
    s = json.loads(json.dumps(scene))
    if ms is not None:
        merged = dict(s.get("multiple_scattering", {}))
        merged.update(ms)
        s["multiple_scattering"] = merged
    return s


def absolutise(scene, folder):
    s = json.loads(json.dumps(scene))
    for src in s["medium"].get("sources", []):
        if src.get("type") == "vdb" and not os.path.isabs(src["file"]):
            src["file"] = os.path.normpath(os.path.join(folder, src["file"]))
    return s


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    return p.stdout


def reference_key(scene_text, w, h, spp, ref_veil):
    h_ = hashlib.sha1()
    h_.update(scene_text.encode())
    h_.update(("%dx%d %d" % (w, h, spp)).encode())
    with open(ref_veil, "rb") as fh:  # the ruler itself: a new build makes new references
        h_.update(fh.read())
    for src in json.loads(scene_text)["medium"].get("sources", []):
        if src.get("type") == "vdb":
            st = os.stat(src["file"])
            h_.update(("%s %d %d" % (src["file"], st.st_size, st.st_mtime)).encode())
    return h_.hexdigest()[:16]


def stage_ms(stats_text):
    ms = {}
    for line in stats_text.splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[2] == "ms" and parts[0] in ("inject", "propagate", "volumetric", "render", "spread"):
            ms[parts[0]] = float(parts[1])
    return ms


def reference(scene, label, w, h, spp, ref_veil, cache, tmp):
    """The all-orders reference of scene (its multiple_scattering settings do not matter to it), cached."""
    text = json.dumps(with_ms(scene, None), sort_keys=True)
    ref = os.path.join(cache, reference_key(text, w, h, spp, ref_veil) + ".exr")
    if not os.path.exists(ref):
        sp = os.path.join(tmp, "ref.json")
        with open(sp, "w") as f:
            f.write(text)
        print("reference %s: %dx%d, %d spp ..." % (label, w, h, spp), file=sys.stderr, flush=True)
        out = run([ref_veil, "reference", sp, "-o", ref + ".part.exr", "--spp", str(spp), "--width", str(w),
                   "--height", str(h)])
        os.replace(ref + ".part.exr", ref)
        print(out.strip().splitlines()[0], file=sys.stderr)
    return ref


def converge(a, names, w, h, spp, ref_veil, cache, tmp):
    """The cache's error against its budget: photons doubling at the max rung's cells, then cells at the
    largest photon count, until the reference's noise; each with the cache stage's time."""
    rows = []
    for name, base, folder, fit, thick in scenes():
        if name not in names:
            continue
        scene = absolutise(base, folder)
        ref = reference(scene, name, w, h, spp * REF_SPP_SCALE.get(name, 1), ref_veil, cache, tmp)
        budgets = [(1 << p, 96) for p in range(12, 23)] + [(1 << 22, c) for c in (16, 24, 40, 64)]
        for photons, cells in budgets:
            ms = dict(CACHE, cache_photons=photons, cache_cells=cells)
            sp = os.path.join(tmp, "v.json")
            with open(sp, "w") as f:
                json.dump(with_ms(scene, ms), f)
            img = os.path.join(tmp, "v.exr")
            st = stage_ms(run([a.veil, "render", sp, "-o", img, "--width", str(w), "--height", str(h), "--quality",
                               "max", "--stats"]))
            c = json.loads(run([a.veil, "compare", img, ref, "--bin", "4", "--json"]))
            row = {"scene": name, "photons": photons, "cells": cells, "cache_ms": st.get("volumetric", 0.0),
                   "rel_rmse_excess_bin4": c["rel_rmse_excess"], "mean_bias": c["mean_bias"], "noise_bin4": c["noise"]}
            rows.append(row)
            print("%-24s %9d photons %3d cells %9.0f ms  err %6.2f %%  bias %+6.2f %%  (ref noise %.2f %%)" % (
                name, photons, cells, row["cache_ms"], 100 * row["rel_rmse_excess_bin4"], 100 * row["mean_bias"],
                100 * row["noise_bin4"]), flush=True)
    base = os.path.join(a.out, "cache_convergence")
    with open(base + ".md", "w") as f:
        f.write("| scene | photons | cells | cache (ms) | rel. RMSE 4x4, noise out | mean bias | ref. noise 4x4 |\n"
                "|---|---:|---:|---:|---:|---:|---:|\n")
        for r in rows:
            f.write("| %s | %d | %d | %.0f | %.2f %% | %+.2f %% | %.2f %% |\n" % (
                r["scene"], r["photons"], r["cells"], r["cache_ms"], 100 * r["rel_rmse_excess_bin4"],
                100 * r["mean_bias"], 100 * r["noise_bin4"]))
    with open(base + ".dat", "w") as f:
        for n in names:
            f.write("# %s\n" % n)
            for r in rows:
                if r["scene"] == n and r["cells"] == 96:
                    f.write("%d %g %g\n" % (r["photons"], 100 * r["rel_rmse_excess_bin4"], 100 * r["noise_bin4"]))
            f.write("\n\n")
    try:
        plot = "; ".join([
            "set terminal pngcairo size 900,600", "set output '%s.png'" % base, "set logscale xy",
            "set xlabel 'photons (96 cells along the longest side)'",
            "set ylabel 'rel. RMSE of 4x4 means vs all orders, noise out (%)'", "set key outside",
            "plot " + ", ".join("'%s.dat' index %d using 1:2 with linespoints title '%s', "
                                "'%s.dat' index %d using 1:3 with lines dashtype 2 title '%s: reference noise'"
                                % (base, i, n, base, i, n) for i, n in enumerate(names))])
        subprocess.run(["gnuplot", "-e", plot], check=True)
    except (OSError, subprocess.CalledProcessError) as e:
        print("no plot (%s)" % e, file=sys.stderr)
    print("wrote %s.md" % base, file=sys.stderr)


def own_size_times(a, tmp):
    """Still frames at each scene's own size: the cache against single scattering at the same rung; and the
    turntable frame (render + spread: the stages a moving camera re-runs)."""
    wanted = [s for s in a.scenes.split(";" if ";" in a.scenes else ",") if s]
    lines = ["| scene | size | rung | single scattering (ms) | light cache (ms) | ratio (range of pairs) "
             "| turntable frame: ss / cache (ms) | ratio (range) |",
             "|---|---|---|---:|---:|---:|---:|---:|"]
    for name, base, folder, fit, thick in scenes():
        if wanted and name not in wanted:
            continue
        scene = absolutise(base, folder)
        size = "%dx%d" % (scene["camera"]["width"], scene["camera"]["height"])
        for rung in a.rungs.split(","):
            ms_of = {}
            for vname, ms in (("ss", {"screen_space": False, "volumetric": False}), ("cache", CACHE)):
                sp = os.path.join(tmp, vname + ".json")
                with open(sp, "w") as f:
                    json.dump(with_ms(scene, ms), f)
                ms_of[vname] = sp
            pairs = {"ss": [], "cache": []}
            turn = {"ss": [], "cache": []}
            for r in range(a.runs):
                for vname in ("ss", "cache"):
                    st = stage_ms(run([a.veil, "render", ms_of[vname], "-o", os.path.join(tmp, "t.exr"), "--quality",
                                       rung, "--stats", "--seed", str(r + 1)]))
                    pairs[vname].append(sum(st.values()))
                    turn[vname].append(st.get("render", 0.0) + st.get("spread", 0.0))
            ratios = [c / s_ for s_, c in zip(pairs["ss"], pairs["cache"])]
            tr = [c / s_ for s_, c in zip(turn["ss"], turn["cache"])]
            line = "| %s | %s | %s | %.0f | %.0f | %.2f (%.2f-%.2f) | %.0f / %.0f | %.2f (%.2f-%.2f) |" % (
                name, size, rung, statistics.median(pairs["ss"]), statistics.median(pairs["cache"]),
                statistics.median(ratios), min(ratios), max(ratios), statistics.median(turn["ss"]),
                statistics.median(turn["cache"]), statistics.median(tr), min(tr), max(tr))
            lines.append(line)
            print(line, flush=True)
    path = os.path.join(a.out, "still_times.md")
    with open(path, "w") as f:
        f.write("Still frames at each scene's own size: `python3 bench/multiple_scattering.py --times --rungs %s "
                "--runs %d` (the stages' sum, medians of %d runs in turn; the ratio: the median of the pairs'). "
                "The turntable frame: the render and spread stages alone (the cache is made once a turntable).\n\n"
                % (a.rungs, a.runs, a.runs))
        f.write("\n".join(lines) + "\n")
    print("wrote %s" % path, file=sys.stderr)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=0)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--thick", type=float, default=3.0)
    ap.add_argument("--scenes", default="")
    ap.add_argument("--study", action="store_true")
    ap.add_argument("--candidates", action="store_true", help="also the earlier candidates (screen, legs, diffusion)")
    ap.add_argument("--times", action="store_true", help="still frames at each scene's own size, no references")
    ap.add_argument("--rungs", default="default,max", help="--times: the quality rungs")
    ap.add_argument("--converge", default="", help="scenes (semicolon-separated: names hold commas): the cache's error against its budget")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--ref-veil", default="", help="the veil that renders the references (default: --veil)")
    ap.add_argument("--ref-map", default="", help="a JSON file naming each scene's reference EXR (label: path), "
                    "used in place of rendering or the cache (references rendered by an earlier ruler)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    spp = a.spp or (256 if a.quick else 1024)
    ref_veil = a.ref_veil or a.veil
    ref_map = {}
    if a.ref_map:
        with open(a.ref_map) as f:
            ref_map = {k: os.path.join(ROOT, v) if not os.path.isabs(v) else v for k, v in json.load(f).items()}
    cache = os.path.join(ROOT, "build", "bench-cache", "ms")
    os.makedirs(cache, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="veil-ms-")
    wanted = [s for s in a.scenes.split(";" if ";" in a.scenes else ",") if s]
    rows = []
    variants = VARIANTS + (CANDIDATES if a.candidates else []) + (STUDY if a.study else [])
    if a.converge:
        return converge(a, [s for s in a.converge.split(";") if s], w, h, spp, ref_veil, cache, tmp)
    if a.times:
        return own_size_times(a, tmp)
    for name, base, folder, fit, thick in scenes():
        if wanted and name not in wanted:
            continue
        for k in ((1.0, a.thick) if thick and not a.quick else (1.0,)):
            scene = absolutise(thicken(base, k), folder)
            label = name if k == 1.0 else "%s x%g" % (name, k)
            ref = ref_map.get(label) or reference(scene, label, w, h, spp * REF_SPP_SCALE.get(name, 1), ref_veil,
                                                  cache, tmp)
            for vname, ms, quality in variants:
                if a.quick and vname.startswith("screen "):
                    continue
                sp = os.path.join(tmp, "v.json")
                with open(sp, "w") as f:
                    json.dump(with_ms(scene, ms), f)
                img = os.path.join(tmp, "v.exr")
                frame, turn = [], []
                for r in range(a.runs):
                    st = stage_ms(run([a.veil, "render", sp, "-o", img, "--width", str(w), "--height", str(h),
                                       "--quality", quality, "--stats"]))
                    frame.append(sum(st.values()))
                    turn.append(st.get("render", 0.0) + st.get("spread", 0.0))
                c = json.loads(run([a.veil, "compare", img, ref, "--bin", "4", "--json"]))
                row = {"scene": label, "fitted_on": "yes" if fit else "no", "variant": vname,
                       "frame_ms": statistics.median(frame), "turntable_frame_ms": statistics.median(turn),
                       "rel_rmse_excess_bin4": c["rel_rmse_excess"], "noise_bin4": c["noise"],
                       "mean_bias": c["mean_bias"], "mean_bias_se": c.get("mean_bias_se")}
                rows.append(row)
                print("%-26s %-16s %8.1f ms %8.1f ms  err %6.1f %%  bias %+6.1f %% +- %.1f  (ref noise %.1f %%)" % (
                    label, vname, row["frame_ms"], row["turntable_frame_ms"], 100 * row["rel_rmse_excess_bin4"],
                    100 * row["mean_bias"], 100 * (row["mean_bias_se"] or 0.0), 100 * row["noise_bin4"]), flush=True)
    if not rows:
        sys.exit("no scene ran")
    base = os.path.join(a.out, "multiple_scattering" + ("-quick" if a.quick else ""))
    keys = list(rows[0].keys())
    with open(base + ".csv", "w", newline="") as f:  # scene names hold commas: quoted where they do
        wr = csv.writer(f)
        wr.writerow(keys)
        for r in rows:
            wr.writerow([r[k] for k in keys])
    with open(base + ".md", "w") as f:
        f.write("| scene | fitted on | variant | still frame (ms) | turntable frame (ms) | rel. RMSE 4x4, noise out | "
                "mean bias (± its standard error from the reference's noise) | ref. noise 4x4 |\n"
                "|---|---|---|---:|---:|---:|---:|---:|\n")
        for r in rows:
            f.write("| %s | %s | %s | %.0f | %.0f | %.1f %% | %+.1f ± %.1f %% | %.1f %% |\n" % (
                r["scene"], r["fitted_on"], r["variant"], r["frame_ms"], r["turntable_frame_ms"],
                100 * r["rel_rmse_excess_bin4"], 100 * r["mean_bias"], 100 * (r["mean_bias_se"] or 0.0),
                100 * r["noise_bin4"]))
    print("wrote %s.csv and %s.md" % (base, base), file=sys.stderr)
    try:
        dat = base + ".dat"
        names = [v[0] for v in variants]
        with open(dat, "w") as f:
            for v in names:
                f.write("# %s\n" % v)
                for r in rows:
                    if r["variant"] == v:
                        f.write("%g %g\n" % (r["frame_ms"], 100 * r["rel_rmse_excess_bin4"]))
                f.write("\n\n")
        plot = "; ".join([
            "set terminal pngcairo size 900,600", "set output '%s.png'" % base, "set logscale x",
            "set xlabel 'still frame (ms, llvmpipe)'", "set ylabel 'rel. RMSE of 4x4 means vs all orders (%)'",
            "set yrange [0:120]", "set title 'each point a scene (12: 6 at two densities); above 120 % clipped'",
            "set key outside", "plot " + ", ".join("'%s' index %d with points pt %d ps 1.5 title '%s'" % (dat, i, 5 + 2 * i, n)
                                                 for i, n in enumerate(names))])
        subprocess.run(["gnuplot", "-e", plot], check=True)
        print("wrote %s.png" % base, file=sys.stderr)
    except (OSError, subprocess.CalledProcessError) as e:
        print("no plot (%s)" % e, file=sys.stderr)


if __name__ == "__main__":
    main()
