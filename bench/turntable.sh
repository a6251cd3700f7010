#!/usr/bin/env bash
# A turntable's cost against single renders (issue 14):
#   bench/turntable.sh SCENE FRAMES [veil turntable options...]
# 1. one `veil render` of the scene: whole-process time (and its render pass);
# 2. `veil turntable --frames FRAMES --stats`: whole-process time, and the sum
#    of the per-frame render passes (the camera-dependent work, which no
#    caching can save);
# 3. the movie from those frames (--skip-existing --movie, through ffmpeg when
#    installed): its time and size.
# Prints: total / (FRAMES x one render) and total / (sum of render passes).
set -euo pipefail
veil=${VEIL:-build/veil}
scene=$1 frames=$2
shift 2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
now() { date +%s.%N; }
calc() { awk "BEGIN { print $1 }"; }
t0=$(now)
"$veil" render "$scene" -o "$tmp/one.exr" --stats "$@" > "$tmp/one.txt"
t1=$(now)
one=$(calc "$t1 - $t0")
one_pass=$(awk '$1 == "render" {print $2}' "$tmp/one.txt")
t0=$(now)
"$veil" turntable "$scene" -o "$tmp/t.####.exr" --frames "$frames" --stats "$@" > "$tmp/tt.txt"
t1=$(now)
total=$(calc "$t1 - $t0")
passes=$(awk '$1 == "render" {s += $2} END {print s / 1000}' "$tmp/tt.txt")
static=$(awk '($1 == "inject" || $1 == "propagate" || $1 == "volumetric") && $3 == "ms" {s += $2} END {print s / 1000}' "$tmp/tt.txt")
printf 'scene %s, %s frames\n' "$scene" "$frames"
printf '  one render: %.2f s whole process (render pass %.0f ms)\n' "$one" "$one_pass"
printf '  turntable: %.2f s whole process; %.2f s of render passes, %.2f s of inject, propagate and volumetric (all frames)\n' \
  "$total" "$passes" "$static"
printf '  turntable / (%s x one render) = %.3f;  turntable / (sum of render passes) = %.3f\n' "$frames" \
  "$(calc "$total / ($frames * $one)")" "$(calc "$total / $passes")"
if command -v ffmpeg > /dev/null; then
  t0=$(now)
  "$veil" turntable "$scene" -o "$tmp/t.####.exr" --frames "$frames" --skip-existing --movie "$tmp/t.mp4" "$@" > /dev/null
  t1=$(now)
  printf '  movie: %.2f s (frames read back, PNGs, ffmpeg H.264), %s bytes\n' "$(calc "$t1 - $t0")" \
    "$(stat -c %s "$tmp/t.mp4")"
else
  echo "  movie: no ffmpeg (Debian package ffmpeg)"
fi
