#!/bin/bash
# veil fog end to end: good frames (Z, depth.Z, sky) give an EXR whose
# values are finite and whose surfaces are attenuated (no lights: R is at
# most exp(-sigma_a d) 2 = 1.56 plus rounding, and above T 2 = 0.9);
# bad ones (no depth channel, NaN or negative depth, a size that is not the
# camera's, a missing file, usage errors) exit 1 or 2 with a message naming
# the file and the field, and write nothing, not even over an existing file.
VEIL=$1; MAKE=$2; STATS=$3
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
"$MAKE" "$dir" || exit 1
cat > "$dir/fog_scene.json" <<'JSON'
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_y_deg": 30, "width": 32, "height": 24},
 "medium": {"sigma_a": [0.05, 0.05, 0.05], "sigma_s": [0.3, 0.3, 0.3], "phase": {"type": "hg", "g": 0.3},
  "sources": [{"type": "exponential", "density": 1, "falloff": 0, "direction": [0, 1, 0], "origin": [0, 0, 0],
               "bounds": [[-20, -20, -20], [20, 20, 20]]}]}}
JSON
fail=0
check() { # expected-exit, pattern, args...
    local want=$1 pat=$2; shift 2
    out=$("$VEIL" fog "$@" 2>&1); rc=$?
    if [ "$rc" != "$want" ] || ! grep -q -- "$pat" <<<"$out"; then
        echo "FAIL: veil fog $* -> exit $rc (want $want), output: $out (want /$pat/)"; fail=1
    fi
}
check 0 "depth from channel Z, as Z" "$dir/good.exr" --scene "$dir/fog_scene.json" -o "$dir/out.exr" --png "$dir/out.png"
[ -s "$dir/out.exr" ] && [ -s "$dir/out.png" ] || { echo "FAIL: no output for a good frame"; fail=1; }
"$STATS" "$dir/out.exr" > "$dir/stats.txt" || fail=1
grep -q "non-finite 0" "$dir/stats.txt" || { echo "FAIL: non-finite values"; cat "$dir/stats.txt"; fail=1; }
rmax=$(awk '$1 == "R" {print $5}' "$dir/stats.txt")
awk -v m="$rmax" 'BEGIN { exit !(m > 0.9 && m < 1.57) }' || { echo "FAIL: R max $rmax: expected the surface (R = 2) attenuated"; fail=1; }
check 0 "channel depth.Z" "$dir/depthz.exr" --scene "$dir/fog_scene.json" -o "$dir/out2.exr"
check 0 "as distance along the ray" "$dir/sky.exr" --scene "$dir/fog_scene.json" -o "$dir/out3.exr" --depth-is distance
# the wall (Z = 5) shadows the fog before it from a sun beyond it (scene/solid.h): R on the axis is the
# surface, exp(-0.35 x 5) 2 = 0.348, and the fog adds nearly nothing; with --no-occluders the lit fog adds
# sigma_s E p(1) 5 exp(-0.35 x 5.2) = 0.3 x 5 x 0.211 x 5 x 0.162 = 0.256 (the sun's path to the box's far
# face is 5.2 - t, the camera's t: their sum is constant)
cat > "$dir/sun_scene.json" <<'JSON'
{"camera": {"position": [0, 0, 0], "look_at": [0, 0, -1], "fov_y_deg": 30, "width": 32, "height": 24},
 "medium": {"sigma_a": [0.05, 0.05, 0.05], "sigma_s": [0.3, 0.3, 0.3], "phase": {"type": "hg", "g": 0.3},
  "sources": [{"type": "exponential", "density": 1, "falloff": 0, "direction": [0, 1, 0], "origin": [0, 0, 0],
               "bounds": [[-20, -20, -5.2], [20, 20, 1]]}]},
 "lights": [{"type": "directional", "direction": [0, 0, 1], "irradiance": [5, 5, 5]}],
 "multiple_scattering": {"screen_space": false, "volumetric": false}}
JSON
check 0 "depth from channel Z" "$dir/good.exr" --scene "$dir/sun_scene.json" -o "$dir/shadowed.exr"
check 0 "depth from channel Z" "$dir/good.exr" --scene "$dir/sun_scene.json" -o "$dir/lit.exr" --no-occluders
r_dark=$("$STATS" "$dir/shadowed.exr" | awk '$1 == "R" {print $5}')
r_lit=$("$STATS" "$dir/lit.exr" | awk '$1 == "R" {print $5}')
awk -v d="$r_dark" -v l="$r_lit" 'BEGIN { exit !(d < 0.36 && l > 0.55) }' ||
    { echo "FAIL: R max $r_dark shadowed by the wall (want < 0.36), $r_lit with --no-occluders (want > 0.55)"; fail=1; }
echo keep > "$dir/keep.exr"
check 1 "no depth channel" "$dir/noz.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
# issue 22: a depth channel of uint is named as such, not "no depth channel"
check 1 "channel Z has pixel type uint" "$dir/uintz.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
check 1 "pixel (1, 1) channel R is 3e+38: expected finite radiance <= 1e+38" "$dir/hugergb.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
# negative radiance behind the fog is read as 0 (a note says so): no negative value comes out
check 0 "1 value of negative radiance" "$dir/negrgb.exr" --scene "$dir/fog_scene.json" -o "$dir/neg.exr"
"$STATS" --rgba "$dir/neg.exr" > "$dir/negstats.txt" || { echo "FAIL: negative radiance through the fog: $(cat "$dir/negstats.txt")"; fail=1; }
check 1 "pixel (7, 3) is not a number" "$dir/nanz.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
check 1 "pixel (0, 0) is -1" "$dir/negz.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
check 1 "camera.width" "$dir/small.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
check 1 "no channel 'Q'" "$dir/good.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr" --depth-channel Q
check 1 "missing.exr" "$dir/missing.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr"
check 2 "missing --scene" "$dir/good.exr" -o "$dir/keep.exr"
check 2 "expected z or distance" "$dir/good.exr" --scene "$dir/fog_scene.json" -o "$dir/keep.exr" --depth-is w
[ "$(cat "$dir/keep.exr")" = keep ] || { echo "FAIL: an existing output was overwritten on error"; fail=1; }
for f in out4 out5; do [ -e "$dir/$f.exr" ] && { echo "FAIL: $f written"; fail=1; }; done
ls "$dir" | grep -q "tmp" && { echo "FAIL: a temporary file was left: $(ls "$dir")"; fail=1; }
[ $fail = 0 ] && echo "veil fog: all checks passed"
exit $fail
