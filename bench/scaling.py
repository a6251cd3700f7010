#!/usr/bin/env python3
"""How each stage's cost grows (issue 13): pixels, voxels, lights, frames,
each swept alone around one base scene, with the fitted exponent of each
stage (least squares of log time against log size).

    python3 bench/scaling.py [--runs R] [--veil build/veil] [--out docs/results]

Base scene: OpenVDB's fog sphere (vdb_tool -sphere -ls2fog, as bench/peers.py
makes it) resampled to max_resolution 128 (128^3 voxels), one sun, single
scattering, 320x240, quality default. Sweeps:
- pixels: 160x120, 320x240, 640x480, 1280x960;
- voxels: max_resolution 64, 128, 256, 512 (N^3 voxels);
- lights: 1, 4, 16 suns (directions spread over a cone), and 1, 4, 16 point
  lights around the sphere;
- frames: a turntable of 1, 4, 16 frames (`--turntable N`: the volume and
  the optical depths once, the march every frame).
Times: each stage's wall time from `veil render --stats` (summed over the
frames of a turntable) and the whole process, medians of --runs. Results:
OUT/scaling.md. Needs OpenVDB's vdb_tool (Debian libopenvdb-tools, as
`make peers` installs it). Python 3 standard library only.
"""
import argparse, json, math, os, shutil, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.join(ROOT, "build")
CACHE = os.path.join(BUILD, "bench-cache", "scaling")
STAGES = ("inject", "propagate", "render")


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("scaling: failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    return p.stdout


def scene(sphere, res=128, width=320, height=240, suns=1, points=0):
    lights = []
    for i in range(suns):
        a = 2 * math.pi * i / max(suns, 1)
        lights.append({"type": "directional", "direction": [0.5 * math.cos(a), -1.0, 0.5 * math.sin(a)],
                       "irradiance": [12.0 / suns] * 3})
    for i in range(points):
        a = 2 * math.pi * i / points
        lights.append({"type": "point", "position": [2.0 * math.cos(a), 1.5, 2.0 * math.sin(a)],
                       "intensity": [20.0 / points] * 3})
    return {"camera": {"position": [0.3, 0.4, 4.0], "look_at": [0, 0, 0], "fov_y_deg": 40, "width": width,
                       "height": height},
            "medium": {"sigma_a": [0.25] * 3, "sigma_s": [2.5] * 3, "phase": {"type": "isotropic"},
                       "max_resolution": res, "sources": [{"type": "vdb", "file": sphere}]},
            "lights": lights, "background": {"color": [0, 0, 0]},
            "multiple_scattering": {"volumetric": False, "screen_space": False}}


def measure(a, name, s, frames=1):
    path = os.path.join(CACHE, name + ".json")
    with open(path, "w") as f:
        json.dump(s, f)
    cmd = [a.veil, "render", path, "-o", os.path.join(CACHE, "out.exr"), "--stats"]
    if frames > 1:
        cmd += ["--turntable", str(frames)]
    per = {k: [] for k in STAGES + ("whole",)}
    for _ in range(a.runs):
        t0 = time.perf_counter()
        text = run(cmd)
        per["whole"].append(time.perf_counter() - t0)
        sums = dict.fromkeys(STAGES, 0.0)
        for line in text.splitlines():
            f = line.split()
            if len(f) > 2 and f[2] == "ms" and f[0] in STAGES:
                sums[f[0]] += float(f[1])
        for k in STAGES:
            per[k].append(sums[k])
    out = {k: statistics.median(v) for k, v in per.items()}
    out["whole"] *= 1000.0
    print("scaling: %s: %s" % (name, ", ".join("%s %.0f ms" % (k, v) for k, v in out.items())), file=sys.stderr,
          flush=True)
    return out


def exponent(xs, ys):
    """least-squares slope of log y against log x (None where a time is ~0)"""
    if any(y <= 0.5 for y in ys):
        return None
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((u - mx) * (v - my) for u, v in zip(lx, ly)) / sum((u - mx) ** 2 for u in lx)


def table(title, unit, xs, labels, results):
    rows = ["", "### " + title, "", "| %s | inject (ms) | propagate (ms) | render (ms) | whole process (ms) |" % unit,
            "|---|---:|---:|---:|---:|"]
    for x, r in zip(labels, results):
        rows.append("| %s | %.0f | %.0f | %.0f | %.0f |" % (x, r["inject"], r["propagate"], r["render"], r["whole"]))
    fits = []
    for k in STAGES + ("whole",):
        e = exponent(xs, [r[k] for r in results])
        fits.append("—" if e is None else "%.2f" % e)
    rows.append("| **fitted exponent** (of %s) | %s |" % (unit, " | ".join(fits)))
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--veil", default=os.path.join(BUILD, "veil"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    os.makedirs(CACHE, exist_ok=True)
    sphere = os.path.join(BUILD, "bench-cache", "peers", "fog_sphere.vdb")
    if not os.path.exists(sphere):
        if not shutil.which("vdb_tool"):
            sys.exit("scaling: vdb_tool not found: install it with  bash scripts/install-bench-deps.sh libopenvdb-tools")
        os.makedirs(os.path.dirname(sphere), exist_ok=True)
        run(["vdb_tool", "-sphere", "dim=128", "radius=1.0", "center=0,0,0", "width=3", "-ls2fog", "name=density",
             "-write", sphere])
    out = ["<!-- bench/scaling.py --runs %d: medians; stage times from veil render --stats -->" % a.runs]
    sizes = [(160, 120), (320, 240), (640, 480), (1280, 960)]
    res = [measure(a, "px%d" % w, scene(sphere, width=w, height=h)) for w, h in sizes]
    out += table("Pixels (128³ voxels, one sun)", "pixels", [w * h for w, h in sizes],
                 ["%d×%d" % s for s in sizes], res)
    grids = [64, 128, 256, 512]
    res = [measure(a, "vox%d" % n, scene(sphere, res=n)) for n in grids]
    out += table("Voxels (320×240, one sun)", "voxels", [n ** 3 for n in grids], ["%d³" % n for n in grids], res)
    counts = [1, 4, 16]
    res = [measure(a, "suns%d" % n, scene(sphere, suns=n)) for n in counts]
    out += table("Suns (128³, 320×240; the first 4 in light-space grids, the rest semi-Lagrangian)", "lights",
                 counts, [str(n) for n in counts], res)
    res = [measure(a, "points%d" % n, scene(sphere, suns=0, points=n)) for n in counts]
    out += table("Point lights (128³, 320×240)", "lights", counts, [str(n) for n in counts], res)
    res = [measure(a, "frames%d" % n, scene(sphere), frames=n) for n in counts]
    out += table("Turntable frames (128³, 320×240, one sun; stage times summed over the frames)", "frames", counts,
                 [str(n) for n in counts], res)
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write("\n".join(out) + "\n")
    print("\n".join(out))


if __name__ == "__main__":
    main()
