#!/usr/bin/env bash
# Per-stage wall time of `veil render --stats` on a scene, median of N runs.
#   bench/demo_stages.sh [SCENE] [RUNS] [RENDER OPTIONS...]   (defaults: data/scenes/demo.json, 5)
# e.g. bench/demo_stages.sh data/scenes/demo.json 3 --method jacobi
# Prints one line per stage: median, min, max in milliseconds.
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-data/scenes/demo.json}
runs=${2:-5}
shift $(( $# < 2 ? $# : 2 ))
veil=${VEIL:-build/veil}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$veil" gpuinfo | grep -E 'renderer|version'
for i in $(seq "$runs"); do
  "$veil" render "$scene" -o "$tmp/o.exr" --png "$tmp/o.png" --stats --seed "$i" "$@" > "$tmp/run$i.txt"
done
head -4 "$tmp/run1.txt" | sed 's/^[a-z]* *[0-9.]* ms *//' | sed 's/^/# /'
for stage in inject propagate volumetric render spread write; do
  grep -h "^$stage " "$tmp"/run*.txt | awk '{print $2}' | sort -g |
    awk -v s="$stage" -v n="$runs" '{v[NR]=$1} END {
      m = (n % 2) ? v[(n+1)/2] : (v[n/2] + v[n/2+1]) / 2;
      printf "%-10s median %9.1f ms   min %9.1f   max %9.1f   (%d runs)\n", s, m, v[1], v[n], n }'
done
