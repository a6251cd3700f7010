#!/usr/bin/env bash
# Motion blur's cost per frame (volume/motion_blur.h; docs/performance.md, "Motion blur"):
#   bench/motion_blur.sh [RUNS] [SHUTTER...]
# on a generated smoke with velocity (make_test_vdbs --smoke-vel: the plume 128 voxels tall, a
# swirl and an updraft up to ~3 m/s), rendered at 320x240 with one sun: RUNS (default 5) renders
# with --shutter off, then RUNS with each SHUTTER (default -0.25,0.25 and -0.5,0.5), alternating;
# prints the medians of the inject stage (where the blur runs: the grid read, blurred and put on
# the GPU) and of the whole process, and what --stats says the blur did.
set -euo pipefail
veil=${VEIL:-build/veil}
make_vdbs=${MAKE_TEST_VDBS:-build/tests/make_test_vdbs}
runs=${1:-5}
shift || true
shutters=("$@")
[ ${#shutters[@]} -gt 0 ] || shutters=(-0.25,0.25 -0.5,0.5)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$make_vdbs" --smoke-vel "$tmp/smoke_vel.vdb" > /dev/null
cat > "$tmp/scene.json" <<JSON
{"camera": {"position": [0, 1.3, 6], "look_at": [0, 1.3, 0], "fov_y_deg": 35, "width": 320, "height": 240},
 "medium": {"sigma_a": [0.5, 0.5, 0.5], "sigma_s": [8, 8, 8],
            "sources": [{"type": "vdb", "file": "smoke_vel.vdb", "velocity": {}}]},
 "lights": [{"type": "directional", "direction": [0.4, -1, -0.3], "irradiance": [3, 3, 3]}]}
JSON
now() { date +%s.%N; }
median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }
modes=(off "${shutters[@]}")
for ((i = 0; i < runs; ++i)); do
  for m in "${modes[@]}"; do
    t0=$(now)
    "$veil" render "$tmp/scene.json" -o "$tmp/out.exr" --stats --shutter "$m" > "$tmp/stats.txt"
    t1=$(now)
    awk -v m="$m" '$1 == "inject" { print m, $2 }' "$tmp/stats.txt" >> "$tmp/inject.txt"
    awk -v m="$m" -v a="$t0" -v b="$t1" 'BEGIN { print m, (b - a) * 1000 }' >> "$tmp/wall.txt"
    [ "$i" -gt 0 ] || grep -o "blurred by [^;)]*" "$tmp/stats.txt" | sed "s/^/  $m: /" || true
  done
done
printf '%-14s %14s %14s  (medians of %d, ms)\n' shutter inject "whole process" "$runs"
for m in "${modes[@]}"; do
  printf '%-14s %14.0f %14.0f\n' "$m" "$(awk -v m="$m" '$1 == m { print $2 }' "$tmp/inject.txt" | median)" \
    "$(awk -v m="$m" '$1 == m { print $2 }' "$tmp/wall.txt" | median)"
done
