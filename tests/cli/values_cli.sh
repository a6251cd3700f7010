#!/usr/bin/env bash
# Issue 22, items 5 and 6, as a user meets them: `veil render` of a scene
# whose grid values or medium numbers the float pipeline cannot carry
# (values.vdb of make_test_vdbs; scene/limits.h). Each must exit 1 with the
# message naming the field (the file and grid for a voxel), write nothing,
# and do so quickly: under 10 s (they took 153-203 s, or ran past 60 s, and
# then wrote NaN pixels with exit 0) and 200 MB (the issue's goal; a
# refusal takes ~0.1 s and ~115 MB, most of it the GL and OpenVDB
# libraries). Negative heat renders, with no pixel below 0 (it made
# negative radiance).
#   values_cli.sh VEIL EXR_STATS VDB_DATA
set -u
veil=$1
exr_stats=$2
data=$3
vdb=$data/values.vdb
tmp=$(mktemp -d /tmp/veil-values.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
# the goal's 200 MB resident holds for veil as built; under AddressSanitizer its shadow memory and
# quarantine add ~110 MB to every process, so there only the time and the message are checked
asan=0
ldd "$veil" 2>/dev/null | grep -q libasan && asan=1
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# scene NAME SOURCE_EXTRA MEDIUM_EXTRA ROOT_EXTRA: a 16x16 view of the 8^3 box
scene() {
  cat >"$tmp/$1.json" <<EOF
{"camera": {"position": [0.35, 0.35, 3], "look_at": [0.35, 0.35, 0.35], "width": 16, "height": 16},
 "medium": {"sigma_a": [0.5, 0.5, 0.5], "sigma_s": [1, 1, 1]$3,
  "sources": [{"type": "vdb", "file": "$vdb"$2}]},
 "lights": [{"type": "point", "position": [0.35, 2, 0.35], "intensity": [1, 1, 1]}]$4}
EOF
}

# refused NAME EXPECTED: exit 1, EXPECTED on stderr, no file, < 10 s, < 200 MB
refused() {
  local out=$tmp/out_$1
  mkdir -p "$out"
  local t0 t1 rc kb
  t0=$(date +%s.%N)
  /usr/bin/time -f "%M" -o "$tmp/$1.mem" timeout 60 "$veil" render "$tmp/$1.json" -o "$out/x.exr" --png "$out/x.png" \
    >"$tmp/$1.out" 2>"$tmp/$1.err"
  rc=$?
  t1=$(date +%s.%N)
  kb=$(tail -1 "$tmp/$1.mem")
  local secs
  secs=$(awk -v a="$t0" -v b="$t1" 'BEGIN { printf "%.2f", b - a }')
  [ "$rc" -eq 1 ] || fail "$1: exit $rc, expected 1: $(head -c 400 "$tmp/$1.err")"
  grep -qF -- "$2" "$tmp/$1.err" || fail "$1: stderr lacks '$2': $(head -c 400 "$tmp/$1.err")"
  grep -qiE '\bnan\b|\binf\b' "$tmp/$1.err" && fail "$1: prints a C spelling of a value: $(head -c 400 "$tmp/$1.err")"
  [ -z "$(ls -A "$out")" ] || fail "$1: wrote $(ls -A "$out" | tr '\n' ' ')"
  awk -v s="$secs" 'BEGIN { exit !(s < 10) }' || fail "$1: took $secs s"
  [ "$asan" = 1 ] || [ "${kb:-0}" -lt 204800 ] || fail "$1: $kb KB resident"
  echo "$1: exit $rc in $secs s, $kb KB: $(head -c 300 "$tmp/$1.err")"
}

# item 5: one +inf heat voxel; a 3e38 temperature voxel; emission.scale and temperature.scale of 3e38
scene inf_heat ', "emission": {"grid": "heat_inf"}' '' ''
refused inf_heat "medium.sources[0].emission.grid: $vdb: grid 'heat_inf': 1 voxel is not a number or infinite (at index [3, 3, 3]: infinity)"
scene hot ', "temperature": {"grid": "temperature_big"}' '' ''
refused hot "medium.sources[0].temperature.grid: $vdb: grid 'temperature_big': 1 voxel is too hot"
scene emission_scale ', "emission": {"grid": "heat", "scale": 3e38}' '' ''
refused emission_scale "medium.sources[0].emission.scale: expected a number in [0, 1e21] (scene/limits.h), got 3e+38 (too large: at most 1e+21)"
scene temperature_scale ', "temperature": {"grid": "temperature", "scale": 3e38}' '' ''
refused temperature_scale "medium.sources[0].temperature.scale: expected a number in [-1e5, 1e5] (K: scene/limits.h), got 3e+38"
# item 6: a -inf density voxel, copied and resampled; sigma_a 1e20, sigma_s 3e38
scene neg_inf ', "grid": "density_neg_inf"' '' ''
refused neg_inf "medium.sources[0]: $vdb: grid 'density_neg_inf': 1 voxel is not a number or infinite (at index [3, 3, 3]: -infinity)"
scene neg_inf_resampled ', "grid": "density_neg_inf"' ', "max_resolution": 5' ''
refused neg_inf_resampled "grid 'density_neg_inf': 1 voxel is not a number or infinite"
scene neg_inf_sparse ', "grid": "density_neg_inf"' ', "representation": "sparse"' ''
refused neg_inf_sparse "grid 'density_neg_inf': 1 voxel is not a number or infinite"
scene nan_nvdb '' '' ''
sed -i "s|$vdb|$data/values_nan.nvdb|" "$tmp/nan_nvdb.json"
refused nan_nvdb "values_nan.nvdb: grid 'density_nan': 1 voxel is not a number or infinite"
scene sigma_a '' '' ''
sed -i 's/"sigma_a": \[0.5, 0.5, 0.5\]/"sigma_a": [1e20, 0.5, 0.5]/' "$tmp/sigma_a.json"
refused sigma_a "medium.sigma_a[0]: expected a number in [0, 1e10] (m^-1: scene/limits.h), got 1e+20 (too large: at most 1e+10)"
scene sigma_s '' '' ''
sed -i 's/"sigma_s": \[1, 1, 1\]/"sigma_s": [1, 1, 3e38]/' "$tmp/sigma_s.json"
refused sigma_s "medium.sigma_s[2]: expected a number in [0, 1e10] (m^-1: scene/limits.h), got 3e+38 (too large: at most 1e+10)"
scene density_big ', "grid": "density_big"' '' ''
refused density_big "grid 'density_big': 1 voxel is too large: value x density_scale up to 3e+38"
# item 11, this part: a number too large for a field says so and gives the bound
scene ms_c '' '' ', "multiple_scattering": {"c": 3e38}'
refused ms_c "multiple_scattering.c: expected a number in (0, 1e30] (scene/limits.h), got 3e+38 (too large: at most 1e+30)"

# negative heat (and density): rendered, no pixel below 0, every value finite, and --stats says how
# many voxels read 0
stats_case() { # NAME SOURCE_EXTRA NOTE
  scene "$1" "$2" '' ''
  if "$veil" render "$tmp/$1.json" -o "$tmp/$1.exr" --stats >"$tmp/$1.out" 2>"$tmp/$1.err"; then
    local before=$fails
    "$exr_stats" --rgba "$tmp/$1.exr" >"$tmp/$1.stats" || fail "$1: $(cat "$tmp/$1.stats")"
    grep -qF "$3" "$tmp/$1.out" || fail "$1: --stats does not say '$3': $(head -1 "$tmp/$1.out")"
    [ "$fails" -eq "$before" ] && echo "$1: rendered, R, G, B >= 0 and finite; --stats: $3"
  else
    local rc=$?
    if [ "$rc" -eq 3 ] && [ "${CI:-}" != "true" ]; then echo "SKIPPED $1: no GL context"; else
      fail "$1: exit $rc: $(head -c 400 "$tmp/$1.err")"; fi
  fi
}
stats_case negative_heat ', "emission": {"grid": "heat_negative"}' "grid 'heat_negative': 512 voxels below 0 read as 0"
stats_case negative_density ', "grid": "density_negative"' "grid 'density_negative': 64 voxels below 0 read as 0"

[ "$fails" -eq 0 ] && echo "PASS: every value beyond scene/limits.h refused by name, quickly; negative heat >= 0"
exit $((fails > 0))
