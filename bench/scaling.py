#!/usr/bin/env python3
"""How each stage's cost, in time and memory, grows (issues 13 and 24): pixels, voxels, lights, frames and a sparse
box, each swept alone around one base scene, with the fitted exponent of each stage (least squares of log cost
against log size).

    python3 bench/scaling.py [--runs R] [--veil build/veil] [--out docs/results]

Base scene: OpenVDB's fog sphere (vdb_tool -sphere -ls2fog, as bench/peers.py
makes it) resampled to max_resolution 128 (128^3 voxels), one sun, single
scattering, 320x240, quality default. Sweeps:
- pixels: 160x120, 320x240, 640x480, 1280x960, 1920x1080;
- voxels: max_resolution 64, 128, 256, 512 (N^3 voxels);
- lights: 1, 4, 16 suns (directions spread over a cone), and 1, 4, 16 point
  lights around the sphere;
- frames: a turntable of 1, 4, 16 frames (`--turntable N`: the volume and
  the optical depths once, the march every frame);
- sparse box: 16 fog puffs (32 voxels across, 17 256 active voxels each: the
  same puffs, so the same active voxels, in every box) scattered over an index
  box of 128^3, 256^3, 512^3 and 1024^3 voxels (10^9), 1/64 m voxels, held
  `"representation": "sparse"` at the VDB's own voxels (no max_resolution,
  as bench/regress.py's smoke sparse); the camera and the sun frame the box
  as the base scene frames the sphere. Made with pyopenvdb and numpy (Debian
  python3-openvdb: `bash scripts/install-bench-deps.sh python3-openvdb`),
  by /usr/bin/python3 when this interpreter lacks them, once, under
  build/bench-cache/scaling/.
Measured per run: each stage's wall time as `veil render --stats` prints it
(every stage: inject, propagate, volumetric, render, spread, write; a skipped
stage counts 0; a turntable's frames summed), the GPU MiB a stage's --stats
line names (the figure "on the GPU" or "kept" where it says so, else its first
MiB figure; a turntable's largest; blank where the stage names none: on
llvmpipe that memory is the process's), the whole process's wall time, its
CPU time (user + system, llvmpipe's threads included) and its peak resident
set (ru_maxrss from wait4). Reported: medians of --runs (fewer for a size
whose first run took over 3 minutes: the table says so). Results:
OUT/scaling.md. Needs OpenVDB's vdb_tool (Debian libopenvdb-tools, as
`make peers` installs it). Python 3 standard library only, but for the
sparse VDBs.
"""
import argparse, json, math, os, re, shutil, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.join(ROOT, "build")
CACHE = os.path.join(BUILD, "bench-cache", "scaling")
STAGES = ("inject", "propagate", "volumetric", "render", "spread", "write")
SLOW_RUN_S = 180.0  # a size whose first run takes longer is run once

# the sparse box: PUFFS puffs of radius PUFF_R voxels on a 13-step lattice of the box, the same in every box
PUFFS, PUFF_R, PUFF_SEED, PUFF_VOXEL = 16, 16, 24, 1.0 / 64.0


def fail(msg):
    sys.exit("scaling: " + msg)


def run_checked(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        fail("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    return p.stdout


def run_measured(cmd):
    """(output, wall s, cpu s, peak RSS KiB) of one process; its own rusage through wait4."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    out = p.stdout.read()
    p.stdout.close()
    _, status, ru = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    p.returncode = os.waitstatus_to_exitcode(status)  # reaped here: Popen must not wait again
    if p.returncode != 0:
        fail("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), out))
    return out, wall, ru.ru_utime + ru.ru_stime, ru.ru_maxrss


# ---- the scenes ------------------------------------------------------------------------------------------------

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


def sparse_scene(vdb, n):
    """The base scene's framing, scaled to a box n voxels (n/64 m) wide; the VDB at its own voxels, held sparse."""
    s = n * PUFF_VOXEL / 2.0  # the sphere's box is 2 m wide
    return {"camera": {"position": [0.3 * s, 0.4 * s, 4.0 * s], "look_at": [0, 0, 0], "fov_y_deg": 40,
                       "width": 320, "height": 240},
            "medium": {"sigma_a": [1.0] * 3, "sigma_s": [10.0] * 3, "phase": {"type": "isotropic"},
                       "representation": "sparse", "sources": [{"type": "vdb", "file": vdb}]},
            "lights": [{"type": "directional", "direction": [0.5, -1.0, 0.0], "irradiance": [12.0] * 3}],
            "background": {"color": [0, 0, 0]},
            "multiple_scattering": {"volumetric": False, "screen_space": False}}


def puff_cells():
    """PUFFS lattice cells (0..12 a side): two at opposite corners (so the box is the whole index box), the rest
    drawn with a fixed seed, each 4 cells from every other along some axis (32 voxels in the 128 box: no shared
    voxel or 8^3 brick)."""
    import random
    rng = random.Random(PUFF_SEED)
    cells = [(0, 0, 0), (12, 12, 12)]
    while len(cells) < PUFFS:
        c = tuple(rng.randrange(13) for _ in range(3))
        if all(max(abs(a - b) for a, b in zip(c, d)) >= 4 for d in cells):
            cells.append(c)
    return cells


def make_sparse_vdb(n, path):
    """The box's VDB: a float grid 'density' (fog volume), index box -n/2 .. n/2-1, each puff a 32^3 block of
    1 - (d/16)^2 (d < 16 voxels from the block's centre), its low corner on the 8-voxel lattice."""
    import numpy as np
    import pyopenvdb as vdb
    c = np.arange(2 * PUFF_R) - (PUFF_R - 0.5)
    d2 = c[:, None, None] ** 2 + c[None, :, None] ** 2 + c[None, None, :] ** 2
    block = np.where(d2 < PUFF_R * PUFF_R, 1.0 - d2 / (PUFF_R * PUFF_R), 0.0).astype(np.float32)
    g = vdb.FloatGrid()
    g.name = "density"
    g.gridClass = vdb.GridClass.FOG_VOLUME
    g.transform = vdb.createLinearTransform(voxelSize=PUFF_VOXEL)
    span = (n - 2 * PUFF_R) / 8.0  # lattice steps of 8 voxels from the first block corner to the last
    for cell in puff_cells():
        g.copyFromArray(block, ijk=tuple(-n // 2 + 8 * round(i * span / 12.0) for i in cell))
    tmp = path + ".tmp"
    vdb.write(tmp, grids=[g])
    os.replace(tmp, path)
    return g.activeVoxelCount()


def sparse_vdb(n):
    path = os.path.join(CACHE, "puffs%d_r%d_s%d_%d.vdb" % (PUFFS, PUFF_R, PUFF_SEED, n))
    if os.path.exists(path):
        return path
    try:
        import numpy, pyopenvdb  # noqa: F401
        make_sparse_vdb(n, path)
    except ImportError:
        py = "/usr/bin/python3"
        if not os.path.exists(py) or os.path.realpath(py) == os.path.realpath(sys.executable):
            fail("pyopenvdb and numpy not found: install them with  bash scripts/install-bench-deps.sh "
                 "python3-openvdb python3-numpy")
        r = subprocess.run([py, os.path.abspath(__file__), "--make-sparse", str(n), path])
        if r.returncode != 0 or not os.path.exists(path):
            fail("making %s with %s failed: install pyopenvdb with  bash scripts/install-bench-deps.sh "
                 "python3-openvdb python3-numpy" % (path, py))
    return path


# ---- one size: its runs, the medians -----------------------------------------------------------------------

LINE = re.compile(r"^(\w+)\s+([\d.]+) ms(?:\s+\((\w+)(.*)\))?\s*$")
MIB = re.compile(r"([\d.]+) MiB")


def stage_mib(text):
    """The GPU MiB a stage's --stats parenthesis names: 'X MiB on the GPU', else 'X MiB kept', else the first
    'X MiB' that is not a what-if ('dense: X MiB'); None where it names none."""
    for tail in (" MiB on the GPU", " MiB kept"):
        m = re.search(r"([\d.]+)" + re.escape(tail), text)
        if m:
            return float(m.group(1))
    for m in MIB.finditer(text):
        if not text[:m.start()].rstrip().endswith("dense:"):
            return float(m.group(1))
    return None


def parse_stats(text):
    """{stage: ms summed over frames}, {stage: largest MiB or None}, {stage: 'ran'/'cached'/'skipped'}, notes."""
    lines = text.splitlines()
    for i, line in enumerate(lines):  # `veil turntable` ends with its own totals: those alone
        if line.startswith("total over "):
            lines = lines[i + 1:]
            break
    ms, mib, status = dict.fromkeys(STAGES, 0.0), dict.fromkeys(STAGES), {}
    for line in lines:
        m = LINE.match(line)
        if not m or m.group(1) not in STAGES:
            continue
        k = m.group(1)
        ms[k] += float(m.group(2))
        if m.group(3) and (status.get(k) != "ran"):
            status[k] = m.group(3)
        v = stage_mib(m.group(4) or "")
        if v is not None and (mib[k] is None or v > mib[k]):
            mib[k] = v
    notes = {}
    for pat, key in ((r"grid (\d+)x(\d+)x(\d+)", "grid"), (r"(\d+) VDB voxels", "vdb_voxels"),
                     (r"(\d+) bricks kept of (\d+)", "bricks"), (r"([\d.]+) voxels apart across", "across"),
                     (r"(\d+) passes", "passes")):
        m = re.search(pat, text)
        if m:
            notes[key] = m.groups() if len(m.groups()) > 1 else m.group(1)
    return ms, mib, status, notes


def measure(a, name, s, frames=1):
    path = os.path.join(CACHE, name + ".json")
    with open(path, "w") as f:
        json.dump(s, f)
    cmd = [a.veil, "render", path, "-o", os.path.join(CACHE, "out.exr"), "--stats"]
    if frames > 1:
        cmd += ["--turntable", str(frames)]
    per = {k: [] for k in STAGES + ("whole", "cpu", "rss")}
    mibs = {k: [] for k in STAGES}
    status, notes, runs = {}, {}, a.runs
    i = 0
    while i < runs:
        text, wall, cpu, rss = run_measured(cmd)
        if i == 0:
            with open(os.path.join(CACHE, name + ".stats.txt"), "w") as f:
                f.write(text)
            if wall > SLOW_RUN_S and runs > 1:
                runs = 1
                print("scaling: %s: the first run took %.0f s (over %.0f s): one run" % (name, wall, SLOW_RUN_S),
                      file=sys.stderr, flush=True)
        ms, mib, st, nt = parse_stats(text)
        for k in STAGES:
            per[k].append(ms[k])
            if mib[k] is not None:
                mibs[k].append(mib[k])
            if st.get(k) == "ran" or k not in status:
                status[k] = st.get(k, status.get(k))
        notes = notes or nt
        per["whole"].append(wall * 1000.0)
        per["cpu"].append(cpu * 1000.0)
        per["rss"].append(rss / 1024.0)
        i += 1
    out = {k: statistics.median(v) for k, v in per.items()}
    out["mib"] = {k: (statistics.median(v) if v else None) for k, v in mibs.items()}
    out["status"], out["notes"], out["runs"] = status, notes, runs
    print("scaling: %s: %s; peak RSS %.0f MiB" % (
        name, ", ".join("%s %.0f ms" % (k, out[k]) for k in STAGES + ("whole",)), out["rss"]), file=sys.stderr,
        flush=True)
    return out


# ---- the report --------------------------------------------------------------------------------------------------

def exponent(xs, ys):
    """least-squares slope of log y against log x (None where a value is ~0 or absent)"""
    if len(xs) < 2 or any(y is None or y <= 0.5 for y in ys):
        return None
    lx, ly = [math.log(x) for x in xs], [math.log(y) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((u - mx) * (v - my) for u, v in zip(lx, ly)) / sum((u - mx) ** 2 for u in lx)


def fit(xs, ys):
    e = exponent(xs, ys)
    return "—" if e is None else "%.2f" % e


def label(lbl, r, a):
    return lbl if r["runs"] == a.runs else "%s (%d run%s)" % (lbl, r["runs"], "s" if r["runs"] > 1 else "")


def mib_stages(results):
    return [k for k in STAGES if any(r["mib"][k] is not None for r in results)]


def table(a, title, unit, xs, labels, results, extra=None):
    """The sweep's times and memory, each with its fitted exponent; extra: (heading, [cell per size])."""
    rows = ["", "### " + title, ""]
    head = ["%s (ms)" % k for k in STAGES] + ["whole process (ms)", "CPU (ms)"]
    rows.append("| %s | %s |" % (unit, " | ".join(head)))
    rows.append("|---|" + "---:|" * len(head))
    keys = STAGES + ("whole", "cpu")
    for x, r in zip(labels, results):
        rows.append("| %s | %s |" % (label(x, r, a), " | ".join("%.0f" % r[k] for k in keys)))
    rows.append("| **fitted exponent** (of %s) | %s |" % (unit, " | ".join(fit(xs, [r[k] for r in results])
                                                                            for k in keys)))
    ms = mib_stages(results)
    head = ["peak RSS (MiB)"] + ["%s GPU (MiB)" % k for k in ms] + ([extra[0]] if extra else [])
    rows += ["", "| %s | %s |" % (unit, " | ".join(head)), "|---|" + "---:|" * len(head)]
    for i, (x, r) in enumerate(zip(labels, results)):
        cells = ["%.0f" % r["rss"]] + ["" if r["mib"][k] is None else "%.1f" % r["mib"][k] for k in ms]
        rows.append("| %s | %s |" % (label(x, r, a), " | ".join(cells + ([extra[1][i]] if extra else []))))
    fits = [fit(xs, [r["rss"] for r in results])] + [fit(xs, [r["mib"][k] for r in results]) for k in ms]
    rows.append("| **fitted exponent** (of %s) | %s |" % (unit, " | ".join(fits + ([""] if extra else []))))
    none = [k for k in STAGES if k not in ms]
    skipped = [k for k in STAGES if all(r["status"].get(k) == "skipped" for r in results)]
    said = []
    if none:
        said.append("no MiB in --stats: %s" % ", ".join(none))
    if skipped:
        said.append("skipped at every size (0 ms): %s" % ", ".join(skipped))
    if said:
        rows += ["", "(" + "; ".join(said) + ".)"]
    return rows


def span(vals, fmt="%.0f", sep=" … "):
    return fmt % vals[0] + sep + fmt % vals[-1] if len(vals) > 2 else ", ".join(fmt % v for v in vals)


def summary_row(name, xs, results):
    cells = []
    for k in ("inject", "propagate", "render", "write", "whole"):
        v = [r[k] for r in results]
        cells.append("%s ms (%s)" % (span(v), fit(xs, v)))
    v = [r["rss"] for r in results]
    cells.append("%s MiB (%s)" % (span(v), fit(xs, v)))
    gpu = []
    for k in mib_stages(results):
        v = [r["mib"][k] for r in results]
        gpu.append("%s %s MiB (%s)" % (k, span([x or 0.0 for x in v], "%.1f"), fit(xs, v)))
    cells.append("; ".join(gpu) or "—")
    return "| %s | %s |" % (name, " | ".join(cells))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--veil", default=os.path.join(BUILD, "veil"))
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    ap.add_argument("--make-sparse", nargs=2, metavar=("N", "PATH"), help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.make_sparse:  # the child that makes one sparse VDB where the caller's Python has no pyopenvdb
        make_sparse_vdb(int(a.make_sparse[0]), a.make_sparse[1])
        return
    if a.runs < 1:
        ap.error("--runs must be at least 1")
    a.veil = os.path.abspath(a.veil)
    os.makedirs(CACHE, exist_ok=True)
    sphere = os.path.join(BUILD, "bench-cache", "peers", "fog_sphere.vdb")
    if not os.path.exists(sphere):
        if not shutil.which("vdb_tool"):
            fail("vdb_tool not found: install it with  bash scripts/install-bench-deps.sh libopenvdb-tools")
        os.makedirs(os.path.dirname(sphere), exist_ok=True)
        run_checked(["vdb_tool", "-sphere", "dim=128", "radius=1.0", "center=0,0,0", "width=3", "-ls2fog",
                     "name=density", "-write", sphere])
    boxes = [128, 256, 512, 1024]
    vdbs = [sparse_vdb(n) for n in boxes]  # first: a missing pyopenvdb stops the script before the sweeps
    load0, t0 = os.getloadavg(), time.time()
    out = ["<!-- bench/scaling.py --runs %d: medians; stage times and GPU MiB from veil render --stats, peak RSS "
           "from wait4 -->" % a.runs]
    summary = []
    body = []

    sizes = [(160, 120), (320, 240), (640, 480), (1280, 960), (1920, 1080)]
    res = [measure(a, "px%dx%d" % (w, h), scene(sphere, width=w, height=h)) for w, h in sizes]
    xs = [w * h for w, h in sizes]
    body += table(a, "Pixels (128³ voxels, one sun)", "pixels", xs, ["%d×%d" % s for s in sizes], res)
    summary.append(summary_row("pixels: 160×120 … 1920×1080", xs, res))

    grids = [64, 128, 256, 512]
    res = [measure(a, "vox%d" % n, scene(sphere, res=n)) for n in grids]
    xs = [n ** 3 for n in grids]
    across = ["%s voxels" % r["notes"].get("across", "?") for r in res]
    body += table(a, "Voxels (320×240, one sun)", "voxels", xs, ["%d³" % n for n in grids], res,
                  ("light-space grid spacing across (--stats)", across))
    summary.append(summary_row("voxels: 64³ … 512³ (dense)", xs, res))

    counts = [1, 4, 16]
    res = [measure(a, "suns%d" % n, scene(sphere, suns=n)) for n in counts]
    body += table(a, "Suns (128³, 320×240; the first 4 in light-space grids, the rest semi-Lagrangian)", "lights",
                  counts, [str(n) for n in counts], res)
    summary.append(summary_row("suns: 1, 4, 16", counts, res))
    res = [measure(a, "points%d" % n, scene(sphere, suns=0, points=n)) for n in counts]
    body += table(a, "Point lights (128³, 320×240)", "lights", counts, [str(n) for n in counts], res)
    summary.append(summary_row("point lights: 1, 4, 16", counts, res))
    res = [measure(a, "frames%d" % n, scene(sphere), frames=n) for n in counts]
    body += table(a, "Turntable frames (128³, 320×240, one sun; stage times summed over the frames, GPU MiB the "
                  "largest frame's)", "frames", counts, [str(n) for n in counts], res)
    summary.append(summary_row("turntable frames: 1, 4, 16", counts, res))

    res = [measure(a, "sparse%d" % n, sparse_scene(v, n)) for n, v in zip(boxes, vdbs)]
    grid = [tuple(int(d) for d in r["notes"].get("grid", (n, n, n))) for n, r in zip(boxes, res)]
    xs = [g[0] * g[1] * g[2] for g in grid]
    kept = ["%s of %s; %s passes" % (r["notes"]["bricks"] + (r["notes"].get("passes", "?"),)) if "bricks" in r["notes"]
            else "?" for r in res]
    labels = ["%d³ (grid %s, %.2g voxels; %s active)" % (n, "×".join(map(str, g)), x, r["notes"].get("vdb_voxels", "?"))
              for n, g, x, r in zip(boxes, grid, xs, res)]
    body += table(a, "Sparse box (%d puffs of radius %d voxels, the same in every box; 1/64 m voxels, "
                  "representation sparse, native voxels; 320×240, one sun; fitted against the grid's voxels)"
                  % (PUFFS, PUFF_R), "box", xs, labels, res, ("8³ bricks kept; propagate's passes (--stats)", kept))
    summary.append(summary_row("sparse box: 128³ … 1024³ (%s active voxels)" % res[0]["notes"].get("vdb_voxels", "?"),
                               xs, res))

    load1 = os.getloadavg()
    out += ["", "%s; %.0f min; load average (1, 5, 15 min) %.2f %.2f %.2f at the start, %.2f %.2f %.2f at the end."
            % (time.strftime("%Y-%m-%d", time.localtime(t0)), (time.time() - t0) / 60.0, *load0, *load1),
            "", "### Summary (first … last size, fitted exponent in brackets)", "",
            "| sweep | inject | propagate | render | write | whole process | peak RSS | GPU MiB (--stats) |",
            "|---|---:|---:|---:|---:|---:|---:|---|"] + summary + body
    os.makedirs(a.out, exist_ok=True)
    with open(os.path.join(a.out, "scaling.md"), "w") as f:
        f.write("\n".join(out) + "\n")
    print("\n".join(out))


if __name__ == "__main__":
    main()
