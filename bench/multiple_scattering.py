#!/usr/bin/env python3
"""veil multiple-scattering benchmark: time against error of single scattering
alone, + the screen-space spread, + the volumetric (octave) estimate, and the
default, against the all-orders path tracer (`veil reference --max-order 0`).

    python3 bench/multiple_scattering.py [--quick] [--size WxH] [--spp N]
        [--runs R] [--scenes a,b,...] [--study] [--veil build/veil]

For each scene (at two optical thicknesses: the file's sigma_a, sigma_s and
those times --thick) it renders every variant with `veil render --stats`
(time: the median over --runs of the sum of the stages' wall times, i.e. a
still frame without process start and file writing; per turntable frame:
render + spread, the stages a moving camera re-runs; the volumetric field
is view-independent and kept), and compares it with
`veil compare --bin 4 --json`: rel_rmse_excess (relative RMSE of 4x4-pixel
means with the reference's own noise taken out in quadrature) and
mean_bias (mean RGB / reference's - 1). --study adds the screen-space
pass's filter sizes and interpolations, and its MIP chains against the
gathering filter (bench/spread_gather).

References are cached in build/bench-cache/ms/, keyed by the scene text, the
image size, spp and the bytes of the veil binary that renders them
(--ref-veil, default --veil). Scenes in
../shared/data (third-party VDBs) are used when present, skipped otherwise.
Results: docs/results/multiple_scattering.{csv,md} (and .png with gnuplot).
Python 3 standard library only.
"""
import argparse, hashlib, json, os, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")

VARIANTS = [
    ("ss", {"screen_space": False, "volumetric": False}),
    ("ss+screen", {"screen_space": True, "volumetric": False}),
    # the first fit: octaves gated by the legs through each point
    ("ss+octave legs", {"screen_space": False, "volumetric": True, "octave_gate": "legs", "octaves": 3,
                        "octave_extinction": 0.3, "octave_contribution": 0.75, "octave_eccentricity": 0.6}),
    ("ss+octave escape", {"screen_space": False, "volumetric": True, "octave_gate": "escape"}),
    ("ss+diffusion", {"screen_space": False, "volumetric": True, "volumetric_method": "diffusion"}),
    ("default", None),  # the scene's own settings: the defaults
]
STUDY = [("screen %s %s" % (f, i), {"screen_space": True, "volumetric": False, "filter": f, "interpolation": i})
         for f in ("2x2", "4x4", "6x6") for i in ("linear-bilinear", "linear-bicubic", "cubic-bicubic")]


def shared_scene(vdb, camera, sigma_a, sigma_s, g, lights, scale=1.0):
    return {"camera": camera,
            "medium": {"sigma_a": sigma_a, "sigma_s": sigma_s, "phase": {"type": "hg", "g": g},
                       "max_resolution": 128,
                       "sources": [{"type": "vdb", "file": vdb, "density_scale": scale}]},
            "lights": lights, "background": {"color": [0.0, 0.0, 0.0]}}


def scenes():
    """(name, scene dict, folder for relative paths, fitted-on?)"""
    out = []
    for name, fit in (("fog_lights", True), ("demo", True), ("cloud", True), ("vdb_smoke", True)):
        path = os.path.join(ROOT, "data", "scenes", name + ".json")
        with open(path) as f:
            out.append((name, json.load(f), os.path.dirname(path), fit))
    smoke = os.path.join(SHARED, "smoke.vdb")
    if os.path.exists(smoke):
        # index (1,2,1)..(111,223,112), voxel 0.476: about 53 x 106 x 53 m
        cam = {"position": [26.0, 45.0, 150.0], "look_at": [26.0, 52.0, 26.0], "fov_y_deg": 45,
               "width": 640, "height": 480}
        lights = [{"type": "directional", "direction": [0.45, -0.7, -0.55], "irradiance": [2.6, 2.5, 2.3]},
                  {"type": "point", "position": [26.0, 30.0, 26.0], "intensity": [900.0, 500.0, 200.0]}]
        out.append(("smoke.vdb", shared_scene(smoke, cam, [0.007, 0.007, 0.007], [0.093, 0.093, 0.093], 0.3,
                                              lights), ROOT, False))
    dragon = os.path.join(SHARED, "dragon_with_xform.vdb")
    if os.path.exists(dragon):
        cam = {"position": [0.0, 1.0, 9.0], "look_at": [0.0, 0.0, 0.0], "fov_y_deg": 40, "width": 640, "height": 480}
        lights = [{"type": "directional", "direction": [0.4, -0.7, -0.6], "irradiance": [3.0, 2.9, 2.7]}]
        out.append(("dragon.vdb (albedo 0.99)", shared_scene(dragon, cam, [0.02, 0.02, 0.02], [2.0, 2.0, 2.0], 0.6,
                                                             lights), ROOT, False))
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


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=0)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--thick", type=float, default=3.0)
    ap.add_argument("--scenes", default="")
    ap.add_argument("--study", action="store_true")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--ref-veil", default="", help="the veil that renders the references (default: --veil)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    spp = a.spp or (256 if a.quick else 1024)
    ref_veil = a.ref_veil or a.veil
    cache = os.path.join(ROOT, "build", "bench-cache", "ms")
    os.makedirs(cache, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="veil-ms-")
    wanted = [s for s in a.scenes.split(",") if s]
    rows = []
    variants = VARIANTS + (STUDY if a.study else [])
    for name, base, folder, fit in scenes():
        if wanted and name not in wanted:
            continue
        for k in ((1.0,) if a.quick else (1.0, a.thick)):
            scene = absolutise(thicken(base, k), folder)
            label = name if k == 1.0 else "%s x%g" % (name, k)
            ref_scene = with_ms(scene, None)
            text = json.dumps(ref_scene, sort_keys=True)
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
            for vname, ms in variants:
                if a.quick and vname.startswith("screen "):
                    continue
                sp = os.path.join(tmp, "v.json")
                with open(sp, "w") as f:
                    json.dump(with_ms(scene, ms), f)
                img = os.path.join(tmp, "v.exr")
                frame, turn = [], []
                for r in range(a.runs):
                    st = stage_ms(run([a.veil, "render", sp, "-o", img, "--width", str(w), "--height", str(h),
                                       "--stats"]))
                    frame.append(sum(st.values()))
                    turn.append(st.get("render", 0.0) + st.get("spread", 0.0))
                c = json.loads(run([a.veil, "compare", img, ref, "--bin", "4", "--json"]))
                row = {"scene": label, "fitted_on": "yes" if fit else "no", "variant": vname,
                       "frame_ms": statistics.median(frame), "turntable_frame_ms": statistics.median(turn),
                       "rel_rmse_excess_bin4": c["rel_rmse_excess"], "noise_bin4": c["noise"],
                       "mean_bias": c["mean_bias"]}
                rows.append(row)
                print("%-26s %-16s %8.1f ms %8.1f ms  err %6.1f %%  bias %+6.1f %%  (ref noise %.1f %%)" % (
                    label, vname, row["frame_ms"], row["turntable_frame_ms"], 100 * row["rel_rmse_excess_bin4"],
                    100 * row["mean_bias"], 100 * row["noise_bin4"]), flush=True)
    if not rows:
        sys.exit("no scene ran")
    base = os.path.join(a.out, "multiple_scattering" + ("-quick" if a.quick else ""))
    keys = list(rows[0].keys())
    with open(base + ".csv", "w") as f:
        f.write(",".join(keys) + "\n")
        for r in rows:
            f.write(",".join(str(r[k]) for k in keys) + "\n")
    with open(base + ".md", "w") as f:
        f.write("| scene | fitted on | variant | still frame (ms) | turntable frame (ms) | rel. RMSE 4x4, noise out | "
                "mean bias | ref. noise 4x4 |\n|---|---|---|---:|---:|---:|---:|---:|\n")
        for r in rows:
            f.write("| %s | %s | %s | %.0f | %.0f | %.1f %% | %+.1f %% | %.1f %% |\n" % (
                r["scene"], r["fitted_on"], r["variant"], r["frame_ms"], r["turntable_frame_ms"],
                100 * r["rel_rmse_excess_bin4"], 100 * r["mean_bias"], 100 * r["noise_bin4"]))
    print("wrote %s.csv and %s.md" % (base, base), file=sys.stderr)
    try:
        dat = base + ".dat"
        names = [v for v, _ in variants]
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
