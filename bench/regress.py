#!/usr/bin/env python3
"""The regression benchmark: this tree's veil against a commit's, stage by stage.

    make bench-regress BASE=<commit> [REGRESS_ARGS="--runs 7 --scenes demo,cloud"]
    python3 bench/regress.py --base COMMIT [--new COMMIT] [--runs N] [--scenes a,b] [--veil build/veil]
                             [--out FILE]

COMMIT is built from its own sources in a git worktree under
build/regress/ (kept: a second run against the same commit reuses its
binary), with the build type of this tree's build/, beside build/veil
(or, with --new, a second commit built the same way: to bisect). Both render the same scene files,
those of this tree, in turn (base new, new base, base new, ...), --runs
times each (at least 5), with `veil render --stats --seed i`: the stages' times as
`--stats` prints them and the whole process's wall and CPU time (user +
system of the process and its threads: llvmpipe's work included).

Scenes (one that a binary refuses, e.g. a key the base does not know, is
reported and skipped; one whose data is absent is skipped):
- demo, fog_lights, cloud, pyro: data/scenes/ (pyro needs `make data`);
- smoke dense, smoke sparse: ../shared/data/smoke.vdb at its own voxels,
  "representation" dense and sparse, a sun and a point light;
- demo 1080p: the demo at 1920x1080.

Per scene and measure: each binary's median, and the median of the
pairs' ratios new / base with their range. The spread is the ratios'
median absolute deviation from their median. A measure is flagged SLOWER
when three things hold:
- its median ratio exceeds 1 by more than the spread and more than FLOOR
  (3 %);
- the pairs say so beyond chance: a one-sided sign test, P(at least k of
  n pairs slower | no change) <= 0.05 (with 5 runs: all 5 pairs slower;
  with 8: 7 of them);
- the base's median is at least MIN_MS (100 ms): a stage of tens of
  milliseconds (writing a small EXR) moves by a tenth between pairs here.
A flag is a reason to look, not a verdict: with 7 measures on 7 scenes,
one measure in twenty passes the sign test by chance. Machines here are
shared: quote ratios from one run, never from two.

It is a benchmark, never a test: it asserts nothing and its exit status is
0 whatever it measures (2 for bad arguments, 1 when a build fails).
"""
import argparse, json, math, os, re, resource, statistics, subprocess, sys, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(os.path.dirname(ROOT), "shared", "data")
STAGES = ("inject", "propagate", "volumetric", "render", "spread", "write")
FLOOR = 0.03    # a slowdown under 3 % is not flagged, whatever the spread
MIN_MS = 100.0  # nor a measure whose base median is under 100 ms
ALPHA = 0.05    # the sign test's level


def scenes():
    """(name, scene path or dict, extra render arguments); None for the path: skipped, with why."""
    out = []
    for name in ("demo", "fog_lights", "cloud", "pyro"):
        out.append((name, os.path.join(ROOT, "data", "scenes", name + ".json"), []))
    smoke = os.path.join(SHARED, "smoke.vdb")
    for rep in ("dense", "sparse"):
        # index (1,2,1)..(111,223,112), voxel 0.476: about 53 x 106 x 53 m
        sc = {"camera": {"position": [26.0, 45.0, 150.0], "look_at": [26.0, 52.0, 26.0], "fov_y_deg": 45,
                         "width": 640, "height": 480},
              "medium": {"sigma_a": [0.007, 0.007, 0.007], "sigma_s": [0.093, 0.093, 0.093],
                         "phase": {"type": "hg", "g": 0.3}, "representation": rep,
                         "sources": [{"type": "vdb", "file": smoke}]},
              "lights": [{"type": "directional", "direction": [0.45, -0.7, -0.55], "irradiance": [2.6, 2.5, 2.3]},
                         {"type": "point", "position": [26.0, 30.0, 26.0], "intensity": [900.0, 500.0, 200.0]}],
              "background": {"color": [0.0, 0.0, 0.0]}}
        out.append(("smoke " + rep, sc if os.path.exists(smoke) else None, []))
    out.append(("demo 1080p", os.path.join(ROOT, "data", "scenes", "demo.json"), ["--width", "1920", "--height", "1080"]))
    return out


def git(*args):
    return subprocess.run(["git", "-C", ROOT] + list(args), check=True, capture_output=True, text=True).stdout.strip()


def build_type():
    """The build type of this tree's build/ (the Makefile's RelWithDebInfo), so both are compiled alike."""
    try:
        with open(os.path.join(ROOT, "build", "CMakeCache.txt")) as f:
            for line in f:
                if line.startswith("CMAKE_BUILD_TYPE:"):
                    return line.split("=", 1)[1].strip() or "RelWithDebInfo"
    except OSError:
        pass
    return "RelWithDebInfo"


def build_base(commit):
    """Builds commit's veil in build/regress/ (once); returns the binary's path."""
    sha = git("rev-parse", "--verify", commit + "^{commit}")
    top = os.path.join(ROOT, "build", "regress")
    src, bld = os.path.join(top, "src-" + sha[:12]), os.path.join(top, "build-" + sha[:12])
    binary = os.path.join(bld, "veil")
    if os.path.exists(binary):
        return sha, binary
    os.makedirs(top, exist_ok=True)
    if not os.path.exists(src):
        subprocess.run(["git", "-C", ROOT, "worktree", "prune"], check=True)
        subprocess.run(["git", "-C", ROOT, "worktree", "add", "--detach", src, sha], check=True,
                       stdout=subprocess.DEVNULL)
    print("building %s in %s" % (sha[:12], bld), file=sys.stderr, flush=True)
    subprocess.run(["cmake", "-S", src, "-B", bld, "-DCMAKE_BUILD_TYPE=" + build_type()], check=True,
                   stdout=subprocess.DEVNULL)
    jobs = str(os.cpu_count() or 2)
    r = subprocess.run(["cmake", "--build", bld, "-j", jobs, "--target", "veil_cli"], stdout=subprocess.DEVNULL)
    if r.returncode != 0:  # an older tree may name its targets otherwise: everything
        subprocess.run(["cmake", "--build", bld, "-j", jobs], check=True, stdout=subprocess.DEVNULL)
    if not os.path.exists(binary):
        raise RuntimeError("the build of %s made no %s" % (sha[:12], binary))
    return sha, binary


def run_once(veil, scene, extra, seed, out):
    """One render: ({stage: ms, 'wall': ms, 'cpu': ms}, None) or (None, what it said)."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.monotonic()
    p = subprocess.run([veil, "render", scene, "-o", out, "--stats", "--seed", str(seed)] + extra,
                       stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    wall = (time.monotonic() - t0) * 1000.0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode != 0:
        return None, p.stdout.strip().splitlines()[-1] if p.stdout.strip() else "exit %d" % p.returncode
    m = {"wall": wall, "cpu": 1000.0 * (r1.ru_utime + r1.ru_stime - r0.ru_utime - r0.ru_stime)}
    for line in p.stdout.splitlines():
        f = re.match(r"^(\w+)\s+([\d.]+) ms", line)
        if f and f.group(1) in STAGES:
            m[f.group(1)] = float(f.group(2))
    return m, None


def summarise(name, base_runs, new_runs):
    rows, flagged = [], []
    for key in STAGES + ("wall", "cpu"):
        b = [r[key] for r in base_runs if key in r]
        n = [r[key] for r in new_runs if key in r]
        if len(b) != len(n) or not b:
            continue
        mb, mn = statistics.median(b), statistics.median(n)
        if mb < 1.0 and mn < 1.0:
            continue  # skipped in both (a stage that did not run prints 0 ms)
        ratios = [y / x for x, y in zip(b, n) if x > 0.0]
        if not ratios:
            rows.append("| %s | %.1f | %.1f | new only | | |" % (key, mb, mn))
            continue
        med = statistics.median(ratios)
        spread = statistics.median([abs(r - med) for r in ratios])
        k, n_pairs = sum(r > 1.0 for r in ratios), len(ratios)
        p_sign = sum(math.comb(n_pairs, j) for j in range(k, n_pairs + 1)) / 2.0 ** n_pairs
        slower = med - 1.0 > max(spread, FLOOR) and p_sign <= ALPHA and mb >= MIN_MS
        label = {"wall": "whole process, wall", "cpu": "whole process, CPU"}.get(key, key)
        rows.append("| %s | %.1f | %.1f | %.3f (%.2f–%.2f, spread %.3f) | %d of %d | %s |" % (
            label, mb, mn, med, min(ratios), max(ratios), spread, k, n_pairs, "**SLOWER**" if slower else ""))
        if slower:
            flagged.append("%s: %s %.3f" % (name, label, med))
    return rows, flagged


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--base", required=True, help="the commit to compare with (anything git rev-parse takes)")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--scenes", default="", help="comma-separated names (default: all)")
    ap.add_argument("--veil", default=os.path.join(ROOT, "build", "veil"))
    ap.add_argument("--new", default="", help="a commit to build and measure in place of --veil")
    ap.add_argument("--out", default="", help="also write the report here (default build/regress/report-BASE.md)")
    a = ap.parse_args()
    if a.runs < 5:
        ap.error("--runs: at least 5 (medians of fewer runs do not separate this machine's noise)")
    if not a.new and not os.path.exists(a.veil):
        ap.error("--veil %s: no such binary (make build)" % a.veil)
    wanted = [s for s in a.scenes.split(",") if s]
    known = [s[0] for s in scenes()]
    for w in wanted:
        if w not in known:
            ap.error("--scenes: no scene '%s' (%s)" % (w, ", ".join(known)))
    for opt, commit in (("--base", a.base), ("--new", a.new)):
        if commit and subprocess.run(["git", "-C", ROOT, "rev-parse", "--verify", "--quiet", commit + "^{commit}"],
                                     stdout=subprocess.DEVNULL).returncode != 0:
            ap.error("%s %s: not a commit of this repository" % (opt, commit))
    try:
        sha, base = build_base(a.base)
        if a.new:
            new_sha, a.veil = build_base(a.new)
    except (subprocess.CalledProcessError, RuntimeError) as e:
        print("bench/regress.py: could not build %s: %s" % (a.new or a.base, e), file=sys.stderr)
        return 1
    if a.new:
        head = new_sha[:12]
    else:
        head = git("rev-parse", "--short=12", "HEAD") + (" + changes" if git("status", "--porcelain", "-uno") else "")
    lines = ["# veil regression benchmark: %s (base) against %s (new)" % (sha[:12], head), "",
             "`python3 bench/regress.py --base %s%s --runs %d%s`, %s; base %s, new %s." % (
                 a.base, " --new " + a.new if a.new else "", a.runs, " --scenes '%s'" % a.scenes if a.scenes else "",
                 time.strftime("%Y-%m-%d"),
                 os.path.relpath(base, ROOT), os.path.relpath(a.veil, ROOT)), ""]
    flagged = []
    tmp = tempfile.mkdtemp(prefix="veil-regress-")
    for name, scene, extra in scenes():
        if wanted and name not in wanted:
            continue
        if scene is None:
            lines += ["## %s: skipped (../shared/data/smoke.vdb is absent)" % name, ""]
            continue
        if isinstance(scene, dict):
            path = os.path.join(tmp, name.replace(" ", "_") + ".json")
            with open(path, "w") as f:
                json.dump(scene, f)
            scene = path
        elif not os.path.exists(scene):
            lines += ["## %s: skipped (%s is absent)" % (name, os.path.relpath(scene, ROOT)), ""]
            continue
        runs = {"base": [], "new": []}
        refused = None
        for i in range(a.runs):
            # A B, then B A: whatever favours a pair's first run (a warm page cache, the clock) falls on each alike
            order = (("base", base), ("new", a.veil)) if i % 2 == 0 else (("new", a.veil), ("base", base))
            for who, veil in order:
                m, why = run_once(veil, scene, extra, i + 1, os.path.join(tmp, "out.exr"))
                if m is None:
                    refused = "%s refused it: %s" % (who, why)
                    break
                runs[who].append(m)
            if refused:
                break
            print("%s: round %d of %d" % (name, i + 1, a.runs), file=sys.stderr, flush=True)
        if refused:
            lines += ["## %s: skipped (%s)" % (name, refused), ""]
            continue
        rows, f = summarise(name, runs["base"], runs["new"])
        flagged += f
        lines += ["## %s" % name, "",
                  "| measure | base (ms) | new (ms) | new / base: median (range, spread) | pairs slower | |",
                  "|---|---:|---:|---:|---:|---|"] + rows + [""]
    lines += ["Flagged: " + ("; ".join(flagged) if flagged else "nothing slower by more than its spread"), ""]
    report = "\n".join(lines)
    print(report)
    out = a.out or os.path.join(ROOT, "build", "regress", "report-%s-%s.md" % (sha[:12], head[:12]))
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    with open(out, "w") as f:
        f.write(report)
    print("wrote %s" % out, file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
