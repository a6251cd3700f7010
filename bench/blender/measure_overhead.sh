#!/usr/bin/env bash
# The veil add-on's overhead against `veil render` of the scene it exports (issue 25's measure):
# the shared smoke at WxH, whole-process wall time, median of RUNS each, on the same machine:
#   blender   blender -b --factory-startup --python bench/blender/smoke_overhead.py -- ... render WxH
#             (Blender's start, the scene built, F12 with engine VEIL, the EXR written)
#   cli       veil render smoke.json -o cli.exr (the scene the add-on exported)
#   start     blender -b --factory-startup with an empty script (Blender's own start and exit)
# and the add-on's in-process share (VEIL_BLENDER_TIMES=1: export, veil.render, passes) of the last run.
#
#   bench/blender/measure_overhead.sh [VEIL_CLI] [VEIL_LIBRARY] [SMOKE.vdb] [WxH] [RUNS]
# Defaults: build/veil, build/libveil.so, ../shared/data/smoke.vdb, 640x480, 5. Not a test.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cli=${1:-$root/build/veil} lib=${2:-$root/build/libveil.so} smoke=${3:-$root/../shared/data/smoke.vdb}
size=${4:-640x480} runs=${5:-5}
[ -f "$smoke" ] || { echo "measure_overhead: no $smoke (the shared smoke, ../shared/data/README.md)" >&2; exit 2; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
export VEIL_LIBRARY=$lib PYTHONPATH=$root/python${PYTHONPATH:+:$PYTHONPATH}
py="$root/bench/blender/smoke_overhead.py"
blender -b --factory-startup --python-exit-code 1 --python "$py" -- "$smoke" "$out" export "$size" > "$out/export.log" 2>&1 ||
  { cat "$out/export.log"; exit 1; }
wall() { local t0 t1; t0=$(date +%s.%N); "$@" > "$out/run.log" 2>&1 || { cat "$out/run.log"; exit 1; }; t1=$(date +%s.%N)
  echo "$t1 - $t0" | bc; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
for k in $(seq "$runs"); do
  wall blender -b --factory-startup --python-expr "import bpy" >> "$out/start.t"
  wall "$cli" render "$out/smoke.json" -o "$out/cli.exr" >> "$out/cli.t"
  VEIL_BLENDER_TIMES=1 wall blender -b --factory-startup --python-exit-code 1 --python "$py" -- "$smoke" "$out" render "$size" >> "$out/blender.t"
done
b=$(median < "$out/blender.t") c=$(median < "$out/cli.t") s=$(median < "$out/start.t")
echo "smoke $size, median of $runs, whole process (s): blender+add-on $b, veil render $c, blender start alone $s"
echo "overhead: $(echo "$b - $c" | bc) s, of which Blender's start $s s"
grep "^veil_blender:" "$out/run.log" || true
[ -f "$out/blender.exr" ] && /usr/bin/python3 - "$out/blender.exr" "$out/cli.exr" <<'PY' || true
import sys, numpy as np, OpenImageIO as oiio
a, b = (oiio.ImageInput.open(p).read_image(oiio.FLOAT) for p in sys.argv[1:3])
print("same pixels (RGBA, bit for bit):", bool(np.array_equal(a[..., :4], b[..., :4])), "max |diff| %.3g" % float(np.abs(a[..., :4] - b[..., :4]).max()))
PY
