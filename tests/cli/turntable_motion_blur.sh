#!/usr/bin/env bash
# veil turntable of a moving sequence with motion blur: make_test_vdbs's
# moving.0001.vdb .. moving.0003.vdb hold a puff that moves 4 voxels (0.5 m)
# a frame along +x, and a "vel" grid of 12 m/s saying so (at the default 24
# fps, 0.5 m a frame). With the camera's shutter [-0.5, 0.5] each frame is
# blurred along x (N = 4 samples over 4 voxels); with --shutter off it is
# not. Asserted per frame, on the alpha's extent (exr_stats --extent): the
# blurred puff is wider along x than the sharp one and as tall along y, and
# the frames follow the puff (its extent moves right frame by frame).
# Then the option and the velocity refused: --shutter 1,0 (exit 2), a
# velocity grid that is not a vector (exit 1, naming file and grid).
# Usage: turntable_motion_blur.sh VEIL EXR_STATS VDB_DATA
set -u
veil=$1
stats=$2
data=$3
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat > "$tmp/scene.json" <<JSON
{"camera": {"position": [0, 0, 9], "look_at": [0, 0, 0], "fov_y_deg": 20, "width": 64, "height": 40,
            "shutter": [-0.5, 0.5]},
 "medium": {"sigma_a": [2, 2, 2], "sigma_s": [1, 1, 1],
            "sources": [{"type": "vdb", "file": "$data/moving.####.vdb", "velocity": {}}]},
 "lights": [{"type": "directional", "direction": [0.3, -1, -0.4], "irradiance": [3, 3, 3]}],
 "multiple_scattering": {"volumetric": false, "screen_space": false}}
JSON
"$veil" turntable "$tmp/scene.json" -o "$tmp/blur.####.exr" --frames 3 --degrees 0 --stats > "$tmp/out.txt" 2> "$tmp/err.txt"
rc=$?
if [ $rc -eq 3 ]; then
  if [ "${CI:-}" = "true" ]; then fail "no GL context under CI"; fi
  echo "SKIPPED: no GL 4.5 context"; exit 77
fi
[ $rc -eq 0 ] || fail "the blurred turntable: exit $rc: $(cat "$tmp/err.txt")"
grep -q "blurred by 'vel': 4 samples, 4 voxels over the shutter" "$tmp/out.txt" ||
  fail "--stats does not say what the blur did: $(cat "$tmp/out.txt")"
"$veil" turntable "$tmp/scene.json" -o "$tmp/sharp.####.exr" --frames 3 --degrees 0 --shutter off > /dev/null 2> "$tmp/err.txt" ||
  fail "--shutter off: $(cat "$tmp/err.txt")"
prev=-1
for f in 0001 0002 0003; do
  b=$("$stats" --extent "$tmp/blur.$f.exr" 0.02) && s=$("$stats" --extent "$tmp/sharp.$f.exr" 0.02) ||
    fail "exr_stats on frame $f"
  echo "frame $f: blurred $b, sharp $s"
  read -r _ bx0 bx1 by0 by1 _ <<< "$b"
  read -r _ sx0 sx1 sy0 sy1 _ <<< "$s"
  [ "$bx0" != none ] && [ "$sx0" != none ] || fail "frame $f: no medium in sight"
  # 0.5 m of motion is ~6 pixels here; the outermost of the 4 samples carries a quarter of the
  # density, so the contour at alpha 0.02 grows by less: at least 2 pixels
  [ $((bx1 - bx0)) -ge $((sx1 - sx0 + 2)) ] || fail "frame $f: blurred width $((bx1 - bx0)) vs sharp $((sx1 - sx0))"
  dy=$(( (by1 - by0) - (sy1 - sy0) ))
  [ ${dy#-} -le 1 ] || fail "frame $f: the blur changed the height (by $dy pixels): it is along x only"
  [ "$sx0" -gt "$prev" ] || fail "frame $f: the sharp puff did not move right (left edge $sx0 after $prev)"
  prev=$sx0
done
# the option's value, and a velocity that is not a vector
"$veil" turntable "$tmp/scene.json" -o "$tmp/x.####.exr" --shutter 1,0 > /dev/null 2> "$tmp/err.txt"
[ $? -eq 2 ] && grep -q -- "--shutter: expected OPEN,CLOSE" "$tmp/err.txt" || fail "--shutter 1,0: $(cat "$tmp/err.txt")"
sed -e "s|moving.####.vdb\", \"velocity\": {}|blur.vdb\", \"velocity\": {\"grid\": \"speed\"}|" "$tmp/scene.json" > "$tmp/bad.json"
"$veil" render "$tmp/bad.json" -o "$tmp/bad.exr" > /dev/null 2> "$tmp/err.txt"
[ $? -eq 1 ] && grep -q "medium.sources\[0\].velocity.grid: .*blur.vdb: grid 'speed' has value type float, not a vector" "$tmp/err.txt" ||
  fail "a float velocity grid: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/bad.exr" ] || fail "a refused scene wrote its image"
echo PASS
