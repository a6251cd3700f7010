#!/usr/bin/env bash
# `veil fog` against path-traced truth (Blender Cycles), one command:
#   bash bench/fog_truth/run.sh [OUTDIR]        (default build/fog_truth)
# Renders what is missing in OUTDIR (one Blender at a time; minutes on two
# cores), then runs compare.py (needs build/veil). Never part of make test.
# Environment: SPP_NIGHT, SPP_DAY (truth, per seed), SPP_FRAME (the frame
# without fog), CASES (night,day), BLENDER (blender).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
out=${1:-$root/build/fog_truth}
blender=${BLENDER:-blender}
cases=${CASES:-night,day}
mkdir -p "$out"
command -v "$blender" >/dev/null || { echo "run.sh: no $blender (apt-get install -y blender)" >&2; exit 1; }
render() { # case fog spp seed file
  [ -s "$out/$5" ] && return 0
  echo "rendering $5 ($3 spp) ..." >&2
  local t0=$(date +%s)
  "$blender" -b --factory-startup --python "$here/truth.py" -- "$1" "$2" "$3" "$4" "$out/$5" >"$out/$5.log" 2>&1 \
    || { echo "run.sh: blender failed, see $out/$5.log" >&2; exit 1; }
  [ -s "$out/$5" ] || { echo "run.sh: blender wrote no $out/$5, see $out/$5.log" >&2; exit 1; }
  echo "  $(( $(date +%s) - t0 )) s" >&2
}
for c in ${cases//,/ }; do
  spp=$([ "$c" = day ] && echo "${SPP_DAY:-512}" || echo "${SPP_NIGHT:-1024}")
  render "$c" 0 "${SPP_FRAME:-2048}" 1 "${c}_nofog.exr"
  render "$c" 1 "$spp" 1 "${c}_fog_s1.exr"
  render "$c" 1 "$spp" 2 "${c}_fog_s2.exr"
  render "$c" 2 "$spp" 1 "${c}_black_s1.exr"
  render "$c" 2 "$spp" 2 "${c}_black_s2.exr"
done
exec /usr/bin/python3 "$here/compare.py" "$out" --cases "$cases" --veil "${VEIL:-$root/build/veil}"
