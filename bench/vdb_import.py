#!/usr/bin/env python3
"""veil VDB import benchmark (issue 11): time, GPU memory and error of how a
VDB is held, against `veil reference`.

    python3 bench/vdb_import.py [--size WxH] [--spp N] [--runs R] [--rows a,b]
        [--veil build/veil] [--out docs/results]

Rows (each a scene and its variants; time: the median over --runs of the
sum of the stages' wall times from `veil render --stats`; memory: the
extinction volume's and the optical depths' MiB that --stats reports;
error: `veil compare --bin 4 --json`, rel_rmse_excess (relative RMSE of
4x4-pixel means, the reference's noise taken out) and mean_bias):

- smoke: ../shared/data/smoke.vdb (skipped when absent), a sun and a point
  light, single scattering: native (the default), resampled to 128 and 256
  voxels, and sparse; the reference at native resolution, --max-order 1.
  Then all orders (the default estimate) dense and sparse.
- rotated: ../shared/data/dragon_with_xform.vdb (rotated transform, skipped
  when absent), single scattering: the default (resampled at its own voxel
  edge, the field at each centre), 128 and 1.5x finer; the reference on a
  grid of half that edge (max_resolution twice the default's longest side).
- two sources: two overlapping plumes with voxels of 0.02 and 0.03 m, the
  second off the first's lattice (make_test_vdbs --pair): the default
  (the finest voxel; the second resampled onto it) and 64; the reference on
  a grid of half the finest edge.
- puffs: tests' sparse_puffs.vdb (a 4096^3 box, 1.2e-6 of it active):
  sparse by itself; time and memory only (no dense copy exists), beside
  sparse_crop.vdb dense.
- pyro: data/generated/pyro_plume.vdb (`make data`), all orders:
  multiple_scattering.emission_lights 0, 8 (the default) and 15; 8 sparse.

References are cached in build/bench-cache/vdb/ keyed by the scene text,
size, spp, flags and the bytes of the veil binary that renders them
(--ref-veil, default --veil). Results:
docs/results/vdb_import.{csv,md}. Python 3 standard library only.
"""
import argparse, hashlib, json, os, re, statistics, subprocess, sys, tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")
BUILD = os.path.join(ROOT, "build")


def run(cmd):
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if p.returncode != 0:
        sys.exit("failed (%d): %s\n%s" % (p.returncode, " ".join(cmd), p.stdout))
    return p.stdout


def stats_of(text):
    ms, mib = {}, 0.0
    for line in text.splitlines():
        parts = line.split()
        if len(parts) >= 3 and parts[2] == "ms" and parts[0] in ("inject", "propagate", "volumetric", "render", "spread"):
            ms[parts[0]] = float(parts[1])
            if parts[0] in ("inject", "propagate"):
                m = re.search(r"([0-9.]+) MiB on the GPU|; ([0-9.]+) MiB\)", line)
                if m:
                    mib += float(m.group(1) or m.group(2))
    return ms, mib


def scene(camera, sources, lights, sigma_a, sigma_s, g, medium_extra=None, ms=None):
    s = {"camera": camera,
         "medium": {"sigma_a": sigma_a, "sigma_s": sigma_s, "phase": {"type": "hg", "g": g}, "sources": sources},
         "lights": lights, "background": {"color": [0, 0, 0]}}
    s["medium"].update(medium_extra or {})
    if ms is not None:
        s["multiple_scattering"] = ms
    return s


SINGLE = {"volumetric": False, "screen_space": False}


def rows(a, tmp):
    """(row, variant, scene, reference scene, reference flags)"""
    out = []
    smoke = os.path.join(SHARED, "smoke.vdb")
    if os.path.exists(smoke):
        cam = {"position": [26.0, 45.0, 150.0], "look_at": [26.0, 52.0, 26.0], "fov_y_deg": 45}
        lights = [{"type": "directional", "direction": [0.45, -0.7, -0.55], "irradiance": [2.6, 2.5, 2.3]},
                  {"type": "point", "position": [26.0, 30.0, 26.0], "intensity": [900.0, 500.0, 200.0]}]
        src = [{"type": "vdb", "file": smoke}]
        args = (cam, src, lights, [0.007] * 3, [0.093] * 3, 0.3)
        ref = scene(*args, ms=SINGLE)
        for name, extra in (("native (default)", {}), ("128", {"max_resolution": 128}),
                            ("256", {"max_resolution": 256}), ("sparse", {"representation": "sparse"})):
            out.append(("smoke, single", name, scene(*args, medium_extra=extra, ms=SINGLE), ref, ["--max-order", "1"]))
        ref_all = scene(*args)
        for name, extra in (("native (default)", {}), ("sparse", {"representation": "sparse"})):
            out.append(("smoke, all orders", name, scene(*args, medium_extra=extra), ref_all, []))
    dragon = os.path.join(SHARED, "dragon_with_xform.vdb")
    if os.path.exists(dragon):
        cam = {"position": [0.0, 1.0, 9.0], "look_at": [0.0, 0.0, 0.0], "fov_y_deg": 40}
        # lights and medium as bench/multiple_scattering.py's dragon, single scattering
        lights = [{"type": "directional", "direction": [0.4, -0.7, -0.6], "irradiance": [3.0, 2.9, 2.7]}]
        args = (cam, [{"type": "vdb", "file": dragon}], lights, [0.02] * 3, [2.0] * 3, 0.6)
        # the default grid's longest side, read from --stats, doubled for the reference
        probe = os.path.join(tmp, "probe.json")
        with open(probe, "w") as f:
            json.dump(scene(*args, ms=SINGLE), f)
        text = run([a.veil, "render", probe, "--explain"])
        dims = [int(v) for v in re.search(r"grid (\d+)x(\d+)x(\d+)", text).groups()]
        ref = scene(*args, medium_extra={"max_resolution": min(2 * max(dims), 2048)}, ms=SINGLE)
        for name, extra in (("own voxel edge (default)", {}), ("128", {"max_resolution": 128}),
                            ("1.5x finer", {"max_resolution": (3 * max(dims)) // 2})):
            out.append(("rotated (dragon)", name, scene(*args, medium_extra=extra, ms=SINGLE), ref,
                        ["--max-order", "1"]))
    # a stable place, so that the cached reference's key (the scene text) holds
    pa, pb = (os.path.join(BUILD, "bench-cache", "vdb", n) for n in ("pair_a.vdb", "pair_b.vdb"))
    run([os.path.join(BUILD, "tests", "make_test_vdbs"), "--pair", pa, pb])
    cam = {"position": [0.2, 1.2, 4.5], "look_at": [0.1, 1.1, 0.0], "fov_y_deg": 40}
    lights = [{"type": "directional", "direction": [0.4, -0.8, -0.45], "irradiance": [3.0, 3.0, 3.0]},
              {"type": "point", "position": [-0.6, 0.6, 0.8], "intensity": [2.0, 1.5, 1.0]}]
    args = (cam, [{"type": "vdb", "file": pa}, {"type": "vdb", "file": pb}], lights, [2.0] * 3, [10.0] * 3, 0.3)
    probe = os.path.join(tmp, "probe.json")
    with open(probe, "w") as f:
        json.dump(scene(*args, ms=SINGLE), f)
    dims = [int(v) for v in re.search(r"grid (\d+)x(\d+)x(\d+)", run([a.veil, "render", probe, "--explain"])).groups()]
    ref = scene(*args, medium_extra={"max_resolution": 2 * max(dims)}, ms=SINGLE)
    for name, extra in (("finest voxel (default)", {}), ("64", {"max_resolution": 64})):
        out.append(("two sources", name, scene(*args, medium_extra=extra, ms=SINGLE), ref, ["--max-order", "1"]))
    vdata = os.path.join(BUILD, "tests", "vdb_data")
    puffs = os.path.join(vdata, "sparse_puffs.vdb")
    if os.path.exists(puffs):
        cam = {"position": [100.03, 100.22, -6.0], "look_at": [100.03, 100.22, 0.55], "fov_y_deg": 4}
        lights = [{"type": "directional", "direction": [0.3, -0.9, 0.3], "irradiance": [3, 3, 3]}]
        for name, f in (("4096^3 box, sparse (default)", puffs),
                        ("the crop, dense (default)", os.path.join(vdata, "sparse_crop.vdb"))):
            out.append(("puffs", name, scene(cam, [{"type": "vdb", "file": f}], lights, [2] * 3, [8] * 3, 0.3),
                        None, None))
    pyro = os.path.join(ROOT, "data", "generated", "pyro_plume.vdb")
    if os.path.exists(pyro):
        with open(os.path.join(ROOT, "data", "scenes", "pyro.json")) as f:
            base = json.load(f)
        base["medium"]["sources"][0]["file"] = pyro
        for k in (0, 8, 15):
            s = json.loads(json.dumps(base))
            s["multiple_scattering"] = {"emission_lights": k}
            out.append(("pyro, all orders", "emission_lights %d%s" % (k, " (default)" if k == 8 else ""), s, base, []))
        s = json.loads(json.dumps(base))
        s["medium"]["representation"] = "sparse"
        out.append(("pyro, all orders", "emission_lights 8, sparse", s, base, []))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--rows", default="")
    ap.add_argument("--veil", default=os.path.join(BUILD, "veil"))
    ap.add_argument("--ref-veil", default="", help="the veil that renders the references (default: --veil)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    cache = os.path.join(BUILD, "bench-cache", "vdb")
    os.makedirs(cache, exist_ok=True)
    os.makedirs(a.out, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="veil-vdb-")
    wanted = [r for r in a.rows.split(",") if r]
    ref_veil = a.ref_veil or a.veil
    with open(ref_veil, "rb") as fh:
        binary = hashlib.sha1(fh.read()).hexdigest()
    results = []
    for row, variant, sc, ref, flags in rows(a, tmp):
        if wanted and not any(row.startswith(x) for x in wanted):
            continue
        sp = os.path.join(tmp, "v.json")
        with open(sp, "w") as f:
            json.dump(sc, f)
        img = os.path.join(tmp, "v.exr")
        times, mib = [], 0.0
        for _ in range(a.runs):
            ms, mib = stats_of(run([a.veil, "render", sp, "-o", img, "--width", str(w), "--height", str(h), "--stats"]))
            times.append(sum(ms.values()))
        r = {"row": row, "variant": variant, "frame_ms": statistics.median(times), "gpu_mib": mib,
             "rel_rmse_excess_bin4": "", "mean_bias": "", "noise_bin4": ""}
        if ref is not None:
            text = json.dumps(ref, sort_keys=True)
            key = hashlib.sha1(("%s %dx%d %d %s %s" % (text, w, h, a.spp, flags, binary)).encode()).hexdigest()[:16]
            rp = os.path.join(cache, key + ".exr")
            if not os.path.exists(rp):
                rs = os.path.join(tmp, "ref.json")
                with open(rs, "w") as f:
                    f.write(text)
                print("reference %s: %dx%d, %d spp %s ..." % (row, w, h, a.spp, " ".join(flags)), file=sys.stderr,
                      flush=True)
                run([ref_veil, "reference", rs, "-o", rp + ".part.exr", "--spp", str(a.spp), "--width", str(w),
                     "--height", str(h)] + flags)
                os.replace(rp + ".part.exr", rp)
            c = json.loads(run([a.veil, "compare", img, rp, "--bin", "4", "--json"]))
            r["rel_rmse_excess_bin4"], r["mean_bias"], r["noise_bin4"] = c["rel_rmse_excess"], c["mean_bias"], c["noise"]
        results.append(r)
        err = ("%5.1f %%  bias %+6.1f %%" % (100 * r["rel_rmse_excess_bin4"], 100 * r["mean_bias"])
               if ref is not None else "      (no reference)")
        print("%-20s %-30s %9.1f ms %8.1f MiB  %s" % (row, variant, r["frame_ms"], mib, err), flush=True)
    if not results:
        sys.exit("no row ran")
    base = os.path.join(a.out, "vdb_import")
    keys = list(results[0].keys())
    with open(base + ".csv", "w") as f:
        f.write(",".join(keys) + "\n")
        for r in results:
            f.write(",".join(str(r[k]) for k in keys) + "\n")
    with open(base + ".md", "w") as f:
        f.write("| scene | variant | still frame (ms) | GPU MiB (EV + optical depth) | rel. RMSE 4x4, noise out | "
                "mean bias |\n|---|---|---:|---:|---:|---:|\n")
        for r in results:
            has = r["rel_rmse_excess_bin4"] != ""
            f.write("| %s | %s | %.0f | %.1f | %s | %s |\n" % (
                r["row"], r["variant"], r["frame_ms"], r["gpu_mib"],
                "%.1f %%" % (100 * r["rel_rmse_excess_bin4"]) if has else "–",
                "%+.1f %%" % (100 * r["mean_bias"]) if has else "–"))
    print("wrote %s.csv and %s.md" % (base, base), file=sys.stderr)


if __name__ == "__main__":
    main()
