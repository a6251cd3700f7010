#!/usr/bin/env python3
"""veil against OpenVDB's vdb_render (issue 13): whole-process time against
error, both tools on the same VDB, camera, sun and medium, both measured
against `veil reference` single scattering.

    python3 bench/peers.py [--scenes smoke,sphere,plume] [--runs R] [--bin B]
        [--spp N] [--quick] [--knobs] [--veil build/veil] [--out docs/results]

Scenes (240x320 pixels, one sun, isotropic phase, black background):
- smoke: ../shared/data/smoke.vdb (skipped when absent);
- sphere: a fog sphere made by OpenVDB's own vdb_tool (-sphere -ls2fog);
- plume: the noise plume of tests/support/make_test_vdbs.cpp, faded out at its bottom
  and top (--plume-faded): cut through, its dense faces are a place where
  the two tools' media differ (docs/peers.md).

How one scene maps onto the other (docs/peers.md says why, and which of
these a run confirmed):
- vdb_render's -scatter/-absorb are per voxel length: veil's sigma (1/m)
  is vdb_render's divided by the voxel edge;
- -light X,Y,Z,R,G,B: (X,Y,Z) points towards the light (veil's direction
  is the way light travels: its negative); no phase function, so a colour
  C is veil's irradiance E = 4 pi C with isotropic scattering;
- -fov is horizontal: tan(fov_x / 2) = tan(fov_y / 2) * width / height;
- -cutoff 1e-9 (no early exit that veil does not make) and -gain 0 (no
  scattering along its shadow rays), -cpus 0 (every core, as llvmpipe).

Each tool's settings are swept (veil: the quality rungs, and the
semi-Lagrangian method that was the default before issue 13; vdb_render:
pairs of -step and -shadowstep in voxels). Time: whole-process wall time,
median of --runs (one run when a run takes over 10 s), the runs of all
settings interleaved. Error: `veil compare --bin B --json` against the
reference (cached in build/bench-cache/peers/, keyed by the scene, the spp
and the bytes of the veil binary that renders it: --ref-veil, default
--veil): rel_rmse_excess, the relative RMSE of BxB-pixel means
with the reference's own noise taken out, and, as an upper bound on it,
rel_rmse itself. Ratio at equal error: for each veil point, vdb_render's
time at the same error on its Pareto front (log-log interpolation between
the two points around it); '≥' where veil's error is at or below
vdb_render's best (the ratio is then against that best: a lower bound).
An error of 0 means below the reference's noise: the column with the
noise kept bounds it.

Results: OUT/peers.{csv,md} and, with gnuplot, OUT/peers.png. Python 3
standard library only.
"""
import argparse, csv, hashlib, json, math, os, shutil, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")
BUILD = os.path.join(ROOT, "build")
CACHE = os.path.join(BUILD, "bench-cache", "peers")
W, H = 240, 320
TRAVEL = [-0.5, -0.6, -0.62]  # the sun's travel direction (veil); vdb_render gets the opposite

VEIL_SETTINGS = [("draft", ["--quality", "draft"]), ("default", []), ("high", ["--quality", "high"]),
                 ("max", ["--quality", "max"]),
                 ("semi-lagrangian (the old default)", ["--method", "semi-lagrangian"])]
VDB_SETTINGS = [(2, 1), (1, 0.5), (1, 0.25), (0.5, 0.25), (0.5, 0.125), (0.25, 0.125)]
# --knobs: veil's own knobs one at a time around the default (step, across, along; voxels)
KNOBS = [("semi-lagrangian", 0.5, 0, 0), (None, 0.5, 1, 1), (None, 0.5, 1, 2), (None, 0.5, 1, 4), (None, 0.5, 0.7, 4),
         (None, 0.5, 0.5, 1), (None, 0.5, 0.5, 2), (None, 0.5, 0.5, 4), (None, 0.5, 0.5, 8), (None, 0.5, 0.35, 4),
         (None, 0.5, 0.25, 4), (None, 2, 0.5, 4), (None, 1, 0.5, 4), (None, 0.25, 0.5, 4), (None, 1, 1, 4)]


def run(cmd, capture=True):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("peers: failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    return p.stdout


def timed(cmd):
    t0 = time.perf_counter()
    run(cmd)
    return time.perf_counter() - t0


def vdb_info(veil, path):
    g = json.loads(run([veil, "info", "--json", path]))["grids"]
    g = [x for x in g if x["name"] == "density"] or g
    return g[0]


def make_scenes(a):
    """(name, vdb path, vdb_render scatter, absorb per voxel)"""
    os.makedirs(CACHE, exist_ok=True)
    out = []
    want = a.scenes.split(",")
    smoke = os.path.join(SHARED, "smoke.vdb")
    if "smoke" in want:
        if os.path.exists(smoke):
            out.append(("smoke", smoke, 1.5, 0.1))
        else:
            print("peers: %s absent: the smoke scene is skipped" % smoke, file=sys.stderr)
    if "sphere" in want:
        sphere = os.path.join(CACHE, "fog_sphere.vdb")
        if not os.path.exists(sphere):
            run(["vdb_tool", "-sphere", "dim=128", "radius=1.0", "center=0,0,0", "width=3", "-ls2fog", "name=density",
                 "-write", sphere])
        out.append(("sphere", sphere, 0.04, 0.004))
    if "plume" in want:
        plume = os.path.join(CACHE, "noise_plume_faded.vdb")
        if not os.path.exists(plume):  # faded at the bottom and top: no face cuts dense smoke (docs/peers.md)
            run([os.path.join(BUILD, "tests", "make_test_vdbs"), "--plume-faded", plume])
        out.append(("plume", plume, 0.06, 0.003))
    return out


def setup(a, name, path, scatter, absorb):
    """The veil scene (written to CACHE) and vdb_render's arguments."""
    g = vdb_info(a.veil, path)
    lo, hi = g["world_bbox"]
    voxel = g["voxel_size"][0]
    centre = [(lo[i] + hi[i]) / 2 for i in range(3)]
    half = [(hi[i] - lo[i]) / 2 for i in range(3)]
    fov_y = 40.0
    ty = math.tan(math.radians(fov_y / 2))
    tx = ty * W / H
    # back far enough that the bounding box's front face fits the frame with a margin
    dist = half[2] + 1.15 * max(half[1] / ty, half[0] / tx)
    eye = [centre[0], centre[1], centre[2] + dist]
    sig_s, sig_a = scatter / voxel, absorb / voxel
    e = 4 * math.pi
    scene = {"camera": {"position": eye, "look_at": centre, "fov_y_deg": fov_y, "width": W, "height": H},
             "medium": {"sigma_a": [sig_a] * 3, "sigma_s": [sig_s] * 3, "phase": {"type": "isotropic"},
                        "sources": [{"type": "vdb", "file": path}]},
             "lights": [{"type": "directional", "direction": TRAVEL, "irradiance": [e, e, e]}],
             "background": {"color": [0, 0, 0]},
             "multiple_scattering": {"volumetric": False, "screen_space": False}}
    fov_x = math.degrees(2 * math.atan(tx))
    fmt = lambda v: ",".join("%.9g" % x for x in v)
    vr = ["-res", "%dx%d" % (W, H), "-translate", fmt(eye), "-lookat", fmt(centre), "-up", "0,1,0",
          "-fov", "%.9g" % fov_x, "-light", fmt([-x for x in TRAVEL] + [1, 1, 1]),
          "-scatter", fmt([scatter] * 3), "-absorb", fmt([absorb] * 3), "-cutoff", "1e-9", "-gain", "0",
          "-cpus", "0", "-name", g["name"]]
    path_json = os.path.join(CACHE, name + ".json")
    with open(path_json, "w") as f:
        json.dump(scene, f, indent=1)
    return path_json, vr


def reference(a, name, scene_path):
    with open(scene_path, "rb") as f:
        key = hashlib.sha256(f.read())
    with open(a.ref_veil or a.veil, "rb") as f:
        key.update(f.read())
    key.update(str(a.spp).encode())
    ref = os.path.join(CACHE, "%s_ref_%s.exr" % (name, key.hexdigest()[:16]))
    if not os.path.exists(ref):
        print("peers: %s: reference, %d spp (cached for later runs) ..." % (name, a.spp), file=sys.stderr, flush=True)
        tmp = ref + ".part.exr"
        run([a.ref_veil or a.veil, "reference", scene_path, "-o", tmp, "--spp", str(a.spp), "--max-order", "1", "--seed", "1"])
        os.replace(tmp, ref)
    return ref


def error(a, image, ref):
    d = json.loads(run([a.veil, "compare", image, ref, "--bin", str(a.bin), "--json"]))
    return d["rel_rmse_excess"], d["rel_rmse"], d["noise"], d["mean_bias"]


def front(points):
    """vdb_render's Pareto front: (time, error) by time, each more accurate than all faster ones."""
    out = []
    for t, e in sorted(points):
        if not out or e < out[-1][1]:
            out.append((t, e))
    return out


def time_at(fr, e):
    """(time, relation) for error e on front fr: '=' interpolated, '>' at or below its best error (the
    ratio against its best is a lower bound), '<' above its worst (against its fastest: an upper bound)."""
    if e <= fr[-1][1]:
        return fr[-1][0], ">"
    if e >= fr[0][1]:
        return fr[0][0], "<"
    for (t0, e0), (t1, e1) in zip(fr, fr[1:]):
        if e1 <= e <= e0:
            if e1 <= 0 or e0 == e1:
                return t1, "="
            u = (math.log(e) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + u * (math.log(t1) - math.log(t0))), "="
    return fr[-1][0], ">"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenes", default="smoke,sphere,plume")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--bin", type=int, default=8)
    ap.add_argument("--spp", type=int, default=16384)
    ap.add_argument("--quick", action="store_true", help="1 run, 2048 spp, no finest vdb_render setting")
    ap.add_argument("--knobs", action="store_true",
                    help="veil alone: the march step and the light-space spacing one at a time (OUT/peers-knobs.md)")
    ap.add_argument("--replot", action="store_true", help="rewrite peers.md and peers.png from peers.csv")
    ap.add_argument("--veil", default=os.path.join(BUILD, "veil"))
    ap.add_argument("--ref-veil", default=None,
                    help="the veil that renders (and keys) the references; default --veil")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    if a.quick:
        a.runs, a.spp = 1, 2048
    if not shutil.which("vdb_render"):
        sys.exit("peers: vdb_render not found: install it with  bash scripts/install-bench-deps.sh libopenvdb-tools")
    vdb_settings = VDB_SETTINGS[:-1] if a.quick else VDB_SETTINGS
    if a.knobs:
        return knobs(a)
    if a.replot:  # the tables and the plot again from OUT/peers.csv, nothing run
        with open(os.path.join(a.out, "peers.csv")) as f:
            rows = list(csv.DictReader(f))
        for r in rows:
            for k in ("time_s", "error", "error_raw", "noise", "bias", "vdb_render_s", "ratio"):
                if r.get(k):
                    r[k] = float(r[k])
        return write(a, rows)
    rows = []
    for name, path, scatter, absorb in make_scenes(a):
        scene_path, vr_args = setup(a, name, path, scatter, absorb)
        ref = reference(a, name, scene_path)
        jobs = [("veil", label, [a.veil, "render", scene_path, "-o", os.path.join(CACHE, "%s_veil_%d.exr" % (name, i))]
                 + extra) for i, (label, extra) in enumerate(VEIL_SETTINGS)]
        jobs += [("vdb_render", "-step %g -shadowstep %g" % (s, ss),
                  ["vdb_render", path, os.path.join(CACHE, "%s_vr_%d.exr" % (name, i))] + vr_args +
                  ["-step", "%g" % s, "-shadowstep", "%g" % ss]) for i, (s, ss) in enumerate(vdb_settings)]
        times = {j[1]: [] for j in jobs}
        for r in range(a.runs):
            for tool, label, cmd in jobs:
                if r > 0 and times[label] and times[label][0] > 10:
                    continue  # one run of the slow ones
                print("peers: %s: %s %s (run %d)" % (name, tool, label, r + 1), file=sys.stderr, flush=True)
                times[label].append(timed(cmd))
        for tool, label, cmd in jobs:
            exc, raw, noise, bias = error(a, cmd[4] if tool == "veil" else cmd[2], ref)
            rows.append({"scene": name, "tool": tool, "setting": label, "time_s": statistics.median(times[label]),
                         "runs": len(times[label]), "error": exc, "error_raw": raw, "noise": noise, "bias": bias})
    # ratios at equal error, per scene, from this run's numbers
    for name in sorted({r["scene"] for r in rows}):
        fr = front([(r["time_s"], r["error"]) for r in rows if r["scene"] == name and r["tool"] == "vdb_render"])
        for r in rows:
            if r["scene"] == name and r["tool"] == "veil":
                t, rel = time_at(fr, r["error"])
                r["vdb_render_s"], r["ratio"], r["relation"] = t, t / r["time_s"], rel
    write(a, rows)


def knobs(a):
    """veil's knobs on each scene: time (median of --runs, the stages from --stats) against error."""
    out = ["<!-- bench/peers.py --knobs --runs %d --bin %d --spp %d -->" % (a.runs, a.bin, a.spp)]
    for name, path, scatter, absorb in make_scenes(a):
        scene_path, _ = setup(a, name, path, scatter, absorb)
        ref = reference(a, name, scene_path)
        out += ["", "### %s" % name, "",
                "| method | step | across | along | propagate (ms) | render (ms) | whole process (s) | error | mean bias |",
                "|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for method, step, across, along in KNOBS:
            img = os.path.join(CACHE, "%s_knob.exr" % name)
            cmd = [a.veil, "render", scene_path, "-o", img, "--stats", "--step", "%g" % step]
            cmd += ["--method", method] if method else ["--od-spacing", "%g,%g" % (across, along)]
            walls, prop, march = [], [], []
            for _ in range(a.runs):
                t0 = time.perf_counter()
                text = run(cmd)
                walls.append(time.perf_counter() - t0)
                for line in text.splitlines():
                    f = line.split()
                    if len(f) > 2 and f[2] == "ms" and f[0] in ("propagate", "render"):
                        (prop if f[0] == "propagate" else march).append(float(f[1]))
            exc, raw, noise, bias = error(a, img, ref)
            out.append("| %s | %g | %s | %s | %.0f | %.0f | %.2f | %.2f %% | %+.2f %% |" % (
                method or "light-space", step, "%g" % across if not method else "", "%g" % along if not method else "",
                statistics.median(prop), statistics.median(march), statistics.median(walls), 100 * exc, 100 * bias))
            print(out[-1], file=sys.stderr, flush=True)
        out.append("\n(reference noise %.2f %% at %dx%d-pixel means)" % (100 * noise, a.bin, a.bin))
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "peers-knobs.md"), "w") as f:
        f.write("\n".join(out) + "\n")
    print("\n".join(out))


def write(a, rows):
    os.makedirs(a.out, exist_ok=True)
    base = os.path.join(a.out, "peers")
    keys = ["scene", "tool", "setting", "time_s", "runs", "error", "error_raw", "noise", "bias", "vdb_render_s",
            "ratio", "relation"]
    with open(base + ".csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    with open(base + ".md", "w") as f:
        f.write("<!-- bench/peers.py --runs %d --bin %d --spp %d: whole-process time against error, "
                "both tools against veil reference -->\n" % (a.runs, a.bin, a.spp))
        for name in dict.fromkeys(r["scene"] for r in rows):
            noise = next(r["noise"] for r in rows if r["scene"] == name)
            f.write("\n### %s (reference noise %.2f %% at %dx%d-pixel means)\n\n" % (name, 100 * noise, a.bin, a.bin))
            f.write("| tool | setting | time (s) | error | error, noise kept (bound) | mean bias |"
                    " vdb_render at that error (s) | ratio |\n|---|---|---:|---:|---:|---:|---:|---:|\n")
            for r in rows:
                if r["scene"] != name:
                    continue
                ratio = "" if r["tool"] != "veil" else "%s%.1f×" % ({"=": "", ">": "≥ ", "<": "≤ "}[r["relation"]],
                                                                    r["ratio"])
                at = "" if r["tool"] != "veil" else "%s%.2f" % ({"=": "", ">": "≥ ", "<": "≤ "}[r["relation"]],
                                                               r["vdb_render_s"])
                f.write("| %s | %s | %.2f | %.2f %% | %.2f %% | %+.2f %% | %s | %s |\n" %
                        (r["tool"], r["setting"], r["time_s"], 100 * r["error"], 100 * r["error_raw"],
                         100 * r["bias"], at, ratio))
    print(open(base + ".md").read())
    if shutil.which("gnuplot"):
        scenes = list(dict.fromkeys(r["scene"] for r in rows))
        data = base + ".dat"
        with open(data, "w") as f:
            for name in scenes:
                for tool in ("veil", "vdb_render"):
                    for r in sorted((r for r in rows if r["scene"] == name and r["tool"] == tool),
                                    key=lambda r: r["time_s"]):
                        if not r["setting"].startswith("semi"):  # the bound: never 0, whatever the noise
                            f.write("%g %g\n" % (r["time_s"], 100 * r["error_raw"]))
                    f.write("\n\n")
        plots = []
        for i, name in enumerate(scenes):
            dat = os.path.basename(data)  # gnuplot runs in OUT: the files name each other by their names
            plots.append("'%s' index %d with linespoints lw 2 pt 7 title 'veil, %s'" % (dat, 2 * i, name))
            plots.append("'%s' index %d with linespoints lw 2 pt 5 dt 2 title 'vdb\\_render, %s'" % (dat, 2 * i + 1,
                                                                                                 name))
        gp = ("set terminal pngcairo size 900,600\nset output '%s.png'\nset logscale xy\nset grid\n"
              "set xlabel 'whole-process time (s), 2 cores, llvmpipe'\n"
              "set ylabel 'rel. RMSE of %dx%d means vs reference, noise in (%%)'\n"
              "set key outside right\nplot %s\n" % (os.path.basename(base), a.bin, a.bin, ", ".join(plots)))
        with open(base + ".gp", "w") as f:
            f.write(gp)
        subprocess.run(["gnuplot", os.path.basename(base) + ".gp"], cwd=a.out, check=False)


if __name__ == "__main__":
    main()
