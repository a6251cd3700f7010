#!/usr/bin/env bash
# The light cache from the command line (issue 23; volumetric/cache.h):
#   - one medium, one image: the same VDB held dense and held sparse gives
#     the same image within 1 % rel. RMSE (the issue's goal; both trace the
#     same photons from the same seed through the same voxel values, so
#     what differs is float rounding of the two lookups: measured 0.09 %);
#     so does a sequence of that file against the file alone, frame by
#     frame (the cache is made again per frame there, from the same seed);
#   - determinism: the same scene twice gives the same bytes; another
#     cache_seed gives other bytes;
#   - --stats reports the cache (photons, noise, memory), --explain plans it;
#   - a turntable computes it once (frames after the first say "cached");
#   - emission is one of its sources (no emission lights then), and the
#     light it carries reaches the image.
#
#   cache_cli.sh VEIL VDB_DIR
set -u
veil=$1 vdbs=$2
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# scene FILE REPRESENTATION SEED: the crop's three puffs, a sun and a point light among them
scene() {
    printf '{"camera": {"position": [100.1, 100.2, 4.5], "look_at": [100.1, 100.2, 0.5], "fov_y_deg": 30,
  "width": 64, "height": 48},
 "medium": {"sigma_a": [0.1, 0.1, 0.1], "sigma_s": [20, 20, 20], "phase": {"type": "hg", "g": 0.5},
  "representation": "%s", "sources": [{"type": "vdb", "file": "%s/sparse_crop.vdb"}]},
 "lights": [{"type": "directional", "direction": [0.4, -0.5, -0.77], "irradiance": [2, 2, 2]},
            {"type": "point", "position": [100.1, 100.2, 0.5], "intensity": [1, 1, 1]}],
 "multiple_scattering": {"volumetric_method": "cache", "screen_space": false, "cache_seed": %s}}\n' \
        "$2" "$vdbs" "$3" >"$1"
}

scene "$work/dense.json" dense 1
"$veil" render "$work/dense.json" -o "$work/dense.exr" --stats >"$work/log" 2>&1
rc=$?
if [ $rc = 3 ] && [ "${CI:-}" != true ]; then echo "skipped: no GL 4.5 context"; exit 77; fi
[ $rc = 0 ] || fail "dense render: exit $rc: $(head -c 600 "$work/log")"
for want in "the light cache: " " photons from 2 sources" "noise " " MiB kept"; do
    grep -q -- "$want" "$work/log" || fail "--stats does not say '$want': $(grep volumetric "$work/log")"
done

scene "$work/sparse.json" sparse 1
"$veil" render "$work/sparse.json" -o "$work/sparse.exr" >"$work/log" 2>&1 || fail "sparse render: $(head -c 600 "$work/log")"
"$veil" compare "$work/sparse.exr" "$work/dense.exr" --json >"$work/cmp.json" || fail "compare"
rel=$(sed -n 's/.*"rel_rmse":[[:space:]]*\([0-9.eE+-]*\).*/\1/p' "$work/cmp.json")
awk -v r="$rel" 'BEGIN { exit !(r != "" && r <= 0.01) }' || fail "sparse against dense: rel. RMSE $rel > 1 %"
echo "sparse against dense: rel. RMSE $rel (at most 0.01)"

# the same scene again: the same bytes; another seed: other bytes
"$veil" render "$work/dense.json" -o "$work/again.exr" >/dev/null 2>&1 || fail "second dense render"
cmp -s "$work/dense.exr" "$work/again.exr" || fail "the same scene rendered twice differs"
scene "$work/seed2.json" dense 2
"$veil" render "$work/seed2.json" -o "$work/seed2.exr" >/dev/null 2>&1 || fail "seed 2 render"
cmp -s "$work/dense.exr" "$work/seed2.exr" && fail "cache_seed 2 gave the same bytes as cache_seed 1"
echo "determinism: the same seed twice byte-identical, another seed differs"

# --explain plans it; a turntable computes it once
"$veil" render "$work/dense.json" --explain >"$work/explain" 2>&1 || fail "--explain: $(head -c 600 "$work/explain")"
grep -q "the light cache, 262144 photons from 2 sources" "$work/explain" || fail "--explain: $(grep -i volumetric "$work/explain")"
"$veil" render "$work/dense.json" -o "$work/turn.exr" --turntable 3 --stats >"$work/log" 2>&1 ||
    fail "turntable: $(head -c 600 "$work/log")"
n_ran=$(grep -c "^volumetric .*(ran: the light cache" "$work/log")
n_cached=$(grep -c "^volumetric .*(cached" "$work/log")
[ "$n_ran" = 1 ] && [ "$n_cached" = 2 ] || fail "turntable: the cache ran $n_ran times, was kept $n_cached times"
echo "turntable: the cache made once, kept for 2 frames"

# a sequence (the same file as frames 1 and 2) against the one file: the volume is read again each frame,
# so the cache is made again, from the same seed: the same image as the static medium's, frame by frame
mkdir -p "$work/seq" "$work/st"
cp "$vdbs/sparse_crop.vdb" "$work/seq/crop.0001.vdb"
cp "$vdbs/sparse_crop.vdb" "$work/seq/crop.0002.vdb"
sed "s|$vdbs/sparse_crop.vdb|$work/seq/crop.####.vdb|" "$work/dense.json" >"$work/seq.json"
"$veil" turntable "$work/seq.json" -o "$work/seq/f.####.exr" --frames 2 --degrees 0 --stats >"$work/log" 2>&1 ||
    fail "sequence turntable: $(head -c 600 "$work/log")"
n_ran=$(grep -c "^volumetric .*(ran: the light cache" "$work/log")
[ "$n_ran" = 2 ] || fail "sequence: the cache ran $n_ran times for 2 frames of new volumes"
"$veil" turntable "$work/dense.json" -o "$work/st/f.####.exr" --frames 2 --degrees 0 >/dev/null 2>&1 ||
    fail "static turntable"
for f in 0001 0002; do
    "$veil" compare "$work/seq/f.$f.exr" "$work/st/f.$f.exr" --json >"$work/cmp.json" || fail "compare frame $f"
    rel=$(sed -n 's/.*"rel_rmse":[[:space:]]*\([0-9.eE+-]*\).*/\1/p' "$work/cmp.json")
    awk -v r="$rel" 'BEGIN { exit !(r != "" && r <= 0.01) }' || fail "sequence frame $f against the static medium: rel. RMSE $rel > 1 %"
    echo "sequence frame $f against the static medium: rel. RMSE $rel (at most 0.01)"
done

# a medium too thick for photons (fog growing as exp(1.2 depth) below its origin, capped at e^60):
# no cache, said why, and the octaves stand in
printf '{"camera": {"position": [0, 1.6, 7.5], "look_at": [0, 0.7, 0], "width": 32, "height": 24},
 "medium": {"sigma_a": [0.02, 0.02, 0.02], "sigma_s": [0.5, 0.55, 0.65], "sources": [{"type": "exponential",
  "density": 0.35, "falloff": 1.2, "direction": [0, 1, 0], "origin": [0, 0, 0]}]},
 "lights": [{"type": "directional", "direction": [0.3, -0.8, 0.5], "irradiance": [2, 2, 2]}]}\n' >"$work/thick.json"
"$veil" render "$work/thick.json" -o "$work/thick.exr" --stats >"$work/log" 2>&1 || fail "thick render: $(head -c 600 "$work/log")"
grep -q "^volumetric .*skipped: no light cache: the medium is too thick for photons.*octaves, gated by the legs, stand in" \
    "$work/log" || fail "thick medium: $(grep volumetric "$work/log")"
echo "a medium too thick for photons: no cache, the octaves stand in"
# the same under a sky: the environment's rest (the cache's source) still scatters once, the octaves stand
# in for the higher orders, and the sky lights the medium beyond what the sun alone does
sed 's/"lights": \[/"lights": [{"type": "environment", "color": [0.4, 0.5, 0.8]}, /' "$work/thick.json" >"$work/thick_sky.json"
"$veil" render "$work/thick_sky.json" -o "$work/thick_sky.exr" --stats >"$work/log" 2>&1 ||
    fail "thick render under a sky: $(head -c 600 "$work/log")"
grep -q "^volumetric .*ran: the light cache holds the environment's rest alone, [0-9]* photons each to its first scattering.*octaves, gated by the legs, stand in" \
    "$work/log" || fail "thick medium under a sky: $(grep volumetric "$work/log")"
/usr/bin/python3 - "$work/thick.exr" "$work/thick_sky.exr" <<'PY' || fail "thick medium under a sky: the image"
import sys, numpy as np, OpenImageIO as oiio
a, b = (oiio.ImageBuf(p).get_pixels(oiio.FLOAT)[..., :3] for p in sys.argv[1:3])
assert np.isfinite(b).all(), "not finite"
# the sky is also seen behind (T x sky): only pixels the medium hides (T < 1e-3 in the sun-only image's
# terms is not known here) are compared as a whole: the sky adds light everywhere, never takes it
assert (b >= a - 1e-6 * np.abs(a)).all() and b.mean() > 1.05 * a.mean(), (a.mean(), b.mean())
print("thick medium under a sky: image mean %.4g with the sky, %.4g without" % (b.mean(), a.mean()))
PY
echo "a medium too thick for photons under a sky: the rest's first scattering, the octaves for the rest"

# an absurd grid: 512 cells along a cube's side would be 2^27 cells (7.5 GB); made coarser by 1.25 at a
# time until under 2^22 cells: 512 / 1.25^6 = 134.2, so 135 cells a side (1.25^5 gives 168^3 = 4.7e6)
printf '{"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "exponential", "density": 1, "falloff": 0,
  "direction": [0, 1, 0], "origin": [0, 0, 0], "bounds": [[-1, -1, -1], [1, 1, 1]]}]},
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}],
 "multiple_scattering": {"cache_cells": 512, "cache_photons": 4096}}\n' >"$work/big.json"
"$veil" render "$work/big.json" -o "$work/big.exr" --stats >"$work/log" 2>&1 || fail "big grid: $(head -c 600 "$work/log")"
grep -q "^volumetric .*the light cache: 4096 photons from 1 source, 135x135x135 cells" "$work/log" ||
    fail "a 512-cell grid was not made coarser to 135^3: $(grep volumetric "$work/log")"
echo "cache_cells 512: made coarser, 135^3 cells"

# emission: a source of the cache, its light in the image
emission() {
    printf '{"camera": {"position": [0.95, 0.95, 6], "look_at": [0.95, 0.95, 0.45], "fov_y_deg": 30,
  "width": 32, "height": 24},
 "medium": {"sigma_a": [0.5, 0.5, 0.5], "sigma_s": [3, 3, 3], "sources": [{"type": "vdb",
  "file": "%s/emissive_slab.vdb", "emission": {"grid": "heat", "scale": 2, "color": [1, 0.5, 0.25]}}]},
 "multiple_scattering": {"volumetric_method": "%s", "screen_space": false}}\n' "$vdbs" "$2" >"$1"
}
emission "$work/emit.json" cache
"$veil" render "$work/emit.json" --explain >"$work/explain" 2>&1 || fail "emission --explain"
grep -q "the light cache, .* from 1 source (the emission one of them)" "$work/explain" ||
    fail "emission --explain: $(grep -i volumetric "$work/explain")"
"$veil" render "$work/emit.json" -o "$work/emit.exr" --stats >"$work/log" 2>&1 || fail "emission render: $(head -c 600 "$work/log")"
grep -q "^propagate .*skipped" "$work/log" || fail "emission lights were propagated: $(grep propagate "$work/log")"
emission "$work/emit_off.json" octave
sed -i 's/"volumetric_method": "octave"/"volumetric": false/' "$work/emit_off.json"
"$veil" render "$work/emit_off.json" -o "$work/emit_off.exr" >/dev/null 2>&1 || fail "emission render without the cache"
"$veil" compare "$work/emit.exr" "$work/emit_off.exr" --json >"$work/cmp.json" || fail "compare emission"
bias=$(sed -n 's/.*"mean_bias":[[:space:]]*\([0-9.eE+-]*\).*/\1/p' "$work/cmp.json")
# the slab scatters 3 / 3.5 of what meets it: its own light scattered is a large part of what leaves it
awk -v b="$bias" 'BEGIN { exit !(b != "" && b > 0.1) }' || fail "the cache added no emitted light (mean bias $bias)"
echo "emission: a source of the cache (no emission lights), +$bias of the image over emission alone"
