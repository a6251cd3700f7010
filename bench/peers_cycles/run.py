#!/usr/bin/env python3
"""veil against Blender 3.4 Cycles at all orders (issue 24): whole-process time against error, both
measured against `veil reference` at every scattering order with the same metric.

    /usr/bin/python3 bench/peers_cycles/run.py [--scene smoke|cloud] [--size 160x120]
        [--spp-list 4,16,64,256] [--runs 3] [--ref-spp 4096] [--veil build/veil] [--out docs/results]

Needs `blender` (Debian package, CPU Cycles), numpy with OpenImageIO for /usr/bin/python3, and for
--scene cloud pyopenvdb (python3-openvdb: `bash scripts/install-bench-deps.sh python3-openvdb`) (the
Cycles render is a multilayer EXR: its combined pass is copied to a plain RGBA one). Not part of
`make test`.

Scenes (--scene): `smoke`, the shared smoke (../shared/data/smoke.vdb, at its own voxels, held dense),
a sun and a point light, sigma_s 0.093, sigma_a 0.007, HG g 0.3, black background: bench/regress.py's
smoke at --size. `cloud`, a cumulus made by cloud.py (a VDB of Gaussian puffs, 5 cm voxels, written
to build/bench-cache/peers_cycles/), the medium and lights of data/scenes/cloud.json (sigma_s 1.6,
sigma_a 0.004: albedo 0.9975, HG g 0.6; a sun, and a point light inside the cloud), black
background. Blender reads the same file (blender_scene.py says how each part maps).

veil: each quality rung, whole-process wall time (median of --runs). Cycles: each --spp-list entry,
one seed, the `blender -b` process's wall time (median of --runs; Blender's own start-up, about 2-3 s,
included as veil's is), and Cycles' own render time as it prints it. Error: `veil compare --json`
against the reference per pixel (--bin 1) and on 4x4 blocks (--bin 4): rel_rmse_excess, the relative
RMSE with the reference's own noise taken out. Ratio at equal error: Cycles' time at veil's error
on Cycles' curve (log-log between its two points around it; bench/peers.py's front and time_at);
'>' where veil's error is below Cycles' best (a lower bound), '<' where it is above Cycles' fewest
samples (an upper bound).

Results: OUT/peers_cycles.{md,csv} (smoke), OUT/peers_cycles_cloud.{md,csv} (cloud)."""
import argparse, csv, hashlib, json, os, statistics, subprocess, sys, tempfile, time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))
import peers  # noqa: E402  (front, time_at, run)
import regress  # noqa: E402  (the smoke scene)

CACHE = os.path.join(ROOT, "build", "bench-cache", "peers_cycles")
RUNGS = ("draft", "default", "high", "max")


def smoke_scene(w, h):
    for name, sc, _ in regress.scenes():
        if name == "smoke dense":
            if sc is None:
                sys.exit("peers_cycles: ../shared/data/smoke.vdb is absent")
            sc = json.loads(json.dumps(sc))
            sc["camera"]["width"], sc["camera"]["height"] = w, h
            return sc
    sys.exit("peers_cycles: bench/regress.py has no smoke scene")


def cloud_scene(w, h):
    vdb = os.path.join(CACHE, "cloud.vdb")
    if not os.path.exists(vdb):
        peers.run(["/usr/bin/python3", os.path.join(HERE, "cloud.py"), vdb])
    return {"camera": {"position": [0.0, 1.0, 7.5], "look_at": [0.0, 0.8, 0.0], "fov_y_deg": 40, "width": w,
                       "height": h},
            "medium": {"sigma_a": [0.004] * 3, "sigma_s": [1.6] * 3, "phase": {"type": "hg", "g": 0.6},
                       "representation": "dense", "sources": [{"type": "vdb", "file": vdb}]},
            "lights": [{"type": "directional", "direction": [0.5, -0.6, -0.62], "irradiance": [3.0, 2.9, 2.7]},
                       {"type": "point", "position": [0.4, 0.7, 0.1], "intensity": [3.0, 1.6, 0.6]}],
            "background": {"color": [0.0, 0.0, 0.0]}}


def reference(a, scene_path):
    with open(scene_path, "rb") as f:
        key = hashlib.sha256(f.read())
    with open(a.veil, "rb") as f:
        key.update(f.read())
    key.update(str(a.ref_spp).encode())
    ref = os.path.join(CACHE, "%s_ref_%s.exr" % (a.scene, key.hexdigest()[:16]))
    if not os.path.exists(ref):
        print("peers_cycles: reference, all orders, %d spp (cached for later runs) ..." % a.ref_spp, file=sys.stderr,
              flush=True)
        tmp = ref + ".part.exr"
        peers.run([a.veil, "reference", scene_path, "-o", tmp, "--spp", str(a.ref_spp), "--seed", "7"])
        os.replace(tmp, ref)
    return ref


def errors(a, image, ref):
    out = []
    for b in (1, 4):
        d = json.loads(peers.run([a.veil, "compare", image, ref, "--bin", str(b), "--json"]))
        out.append(d["rel_rmse_excess"])
    d = json.loads(peers.run([a.veil, "compare", image, ref, "--json"]))
    return out + [d["mean_bias"]]


def combined_to_rgba(src, dst):
    """The Cycles EXR's combined pass as a plain R, G, B, A EXR (what veil compare reads)."""
    code = ("import OpenImageIO as oiio, numpy as np, sys\n"
            "b = oiio.ImageBuf(sys.argv[1]); names = list(b.spec().channelnames)\n"
            "px = b.get_pixels(oiio.FLOAT)\n"
            "idx = [names.index('ViewLayer.Combined.' + c) for c in 'RGBA']\n"
            "out = np.ascontiguousarray(px[..., idx])\n"
            "spec = oiio.ImageSpec(out.shape[1], out.shape[0], 4, oiio.FLOAT); spec.channelnames = ('R', 'G', 'B', 'A')\n"
            "o = oiio.ImageOutput.create(sys.argv[2]); o.open(sys.argv[2], spec); o.write_image(out); o.close()\n")
    peers.run(["/usr/bin/python3", "-c", code, src, dst])


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scene", choices=("smoke", "cloud"), default="smoke")
    ap.add_argument("--size", default="160x120")
    ap.add_argument("--spp-list", default="4,16,64,256")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--blender", default="blender")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "results"))
    a = ap.parse_args()
    w, h = (int(v) for v in a.size.split("x"))
    os.makedirs(CACHE, exist_ok=True)
    tmp = tempfile.mkdtemp(prefix="peers_cycles.")
    scene_path = os.path.join(tmp, a.scene + ".json")
    with open(scene_path, "w") as f:
        json.dump(smoke_scene(w, h) if a.scene == "smoke" else cloud_scene(w, h), f)
    ref = reference(a, scene_path)
    rows = []
    for rung in RUNGS:
        img = os.path.join(tmp, "veil_%s.exr" % rung)
        cmd = [a.veil, "render", scene_path, "-o", img, "--quality", rung]
        times = []
        for _ in range(a.runs):
            t0 = time.perf_counter()
            peers.run(cmd)
            times.append(time.perf_counter() - t0)
        e1, e4, bias = errors(a, img, ref)
        rows.append({"tool": "veil", "setting": rung, "wall_s": statistics.median(times), "own_s": "",
                     "err_pixel": e1, "err_4x4": e4, "bias": bias})
        print("veil %-8s %6.2f s  pixel %.4f  4x4 %.4f  bias %+.4f" % (rung, rows[-1]["wall_s"], e1, e4, bias),
              file=sys.stderr, flush=True)
    for spp in (int(v) for v in a.spp_list.split(",")):
        raw, img = os.path.join(tmp, "cycles_%d_raw.exr" % spp), os.path.join(tmp, "cycles_%d.exr" % spp)
        cmd = [a.blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_scene.py"), "--",
               scene_path, str(spp), "1", raw]
        times, own = [], []
        for _ in range(a.runs if spp <= 64 else 1):
            t0 = time.perf_counter()
            log = peers.run(cmd)
            times.append(time.perf_counter() - t0)
            own += [float(l.split("Time: ")[1].split(" ")[0].split(":")[-1]) + 60.0 * float(
                l.split("Time: ")[1].split(" ")[0].split(":")[-2]) for l in log.splitlines() if l.startswith(" Time: ")]
        combined_to_rgba(raw, img)
        e1, e4, bias = errors(a, img, ref)
        rows.append({"tool": "cycles", "setting": "%d spp" % spp, "wall_s": statistics.median(times),
                     "own_s": statistics.median(own) if own else "", "err_pixel": e1, "err_4x4": e4, "bias": bias})
        print("cycles %5d spp %6.2f s  pixel %.4f  4x4 %.4f  bias %+.4f" % (spp, rows[-1]["wall_s"], e1, e4, bias),
              file=sys.stderr, flush=True)
    write(a, rows, w, h)


def write(a, rows, w, h):
    os.makedirs(a.out, exist_ok=True)
    stem = "peers_cycles" if a.scene == "smoke" else "peers_cycles_" + a.scene
    with open(os.path.join(a.out, stem + ".csv"), "w", newline="") as f:
        cw = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        cw.writeheader()
        cw.writerows(rows)
    cyc = [r for r in rows if r["tool"] == "cycles"]
    what = "The shared smoke" if a.scene == "smoke" else "The cloud (cloud.py)"
    lines = ["%s at %dx%d, all orders, against `veil reference` at %d spp: `/usr/bin/python3 "
             "bench/peers_cycles/run.py --scene %s --size %dx%d --spp-list %s --runs %d --ref-spp %d` (%s). Errors are "
             "relative RMSE with the reference's noise taken out." % (what, w, h, a.ref_spp, a.scene, w, h, a.spp_list,
                                                                     a.runs, a.ref_spp, time.strftime("%Y-%m-%d")), "",
             "| tool | setting | wall (s) | Cycles' own (s) | error, pixel | error, 4x4 | bias | Cycles at equal "
             "error, pixel | 4x4 |", "|---|---|---:|---:|---:|---:|---:|---:|---:|"]
    fronts = {k: peers.front([(r["wall_s"], r[k]) for r in cyc]) for k in ("err_pixel", "err_4x4")}
    for r in rows:
        ratios = []
        for k in ("err_pixel", "err_4x4"):
            if r["tool"] != "veil":
                ratios.append("")
                continue
            t, rel = peers.time_at(fronts[k], r[k])
            ratios.append("%s%.1fx" % ("" if rel == "=" else rel, t / r["wall_s"]))
        own = "%.2f" % r["own_s"] if r["own_s"] != "" else ""
        lines.append("| %s | %s | %.2f | %s | %.2f %% | %.2f %% | %+.2f %% | %s | %s |" % (
            r["tool"], r["setting"], r["wall_s"], own, 100 * r["err_pixel"], 100 * r["err_4x4"], 100 * r["bias"],
            ratios[0], ratios[1]))
    with open(os.path.join(a.out, stem + ".md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
