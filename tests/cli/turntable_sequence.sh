#!/usr/bin/env bash
# veil turntable over an animated source: a vdb source whose file holds
# #### is read per frame (frame + frame_offset), so each frame shows its
# own file; a missing frame file is an error naming the frame, or, with
# --skip-missing, a skipped frame; a bad pattern is refused by name.
# Usage: turntable_sequence.sh VEIL VDB_DATA (make_test_vdbs's folder)
set -u
veil=$1
data=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

mkdir -p "$tmp/seq" "$tmp/out"
cp "$data/smoke_plume.vdb" "$tmp/seq/puff.0011.vdb"
cp "$data/fog_sphere.vdb" "$tmp/seq/puff.0012.vdb"
cp "$data/smoke_plume.vdb" "$tmp/seq/puff.0014.vdb" # frame 13 (file 0013) is missing
scene() { # $1: the file entry, $2: extra source keys
  cat > "$tmp/scene.json" <<JSON
{"camera": {"position": [0, 0.4, 5], "look_at": [0, 0.4, 0], "fov_y_deg": 50, "width": 40, "height": 30},
 "medium": {"sigma_s": [3, 3, 3], "sigma_a": [0.2, 0.2, 0.2],
            "sources": [{"type": "vdb", "file": "$1"$2}]},
 "lights": [{"type": "directional", "direction": [0.3, -1, -0.4], "irradiance": [3, 3, 3]}],
 "multiple_scattering": {"volumetric": false, "screen_space": false}}
JSON
}
scene "seq/puff.%04d.vdb" ', "frame_offset": 10'
# the plan says that every frame runs every stage, and which frame lacks its file (no GPU)
"$veil" turntable "$tmp/scene.json" --explain --frames 4 > "$tmp/plan.txt" || fail "--explain: $(cat "$tmp/plan.txt")"
grep -q "^frame 1: runs every stage" "$tmp/plan.txt" && grep -q "^frame 3: .*frame 3: cannot open .*puff.0013.vdb.*(an error)" "$tmp/plan.txt" ||
  fail "the plan of a sequence: $(cat "$tmp/plan.txt")"
# frame 3 needs puff.0013.vdb: an error naming the frame and the file, and frames 1-2 written
"$veil" turntable "$tmp/scene.json" -o "$tmp/out/f.####.exr" --frames 4 --degrees 0 2> "$tmp/err.txt" > /dev/null
rc=$?
if [ $rc -eq 3 ]; then
  if [ "${CI:-}" = "true" ]; then fail "no GL context under CI"; fi
  echo "SKIPPED: no GL 4.5 context"; exit 77
fi
[ $rc -eq 1 ] || fail "a missing frame file: exit $rc, expected 1: $(cat "$tmp/err.txt")"
grep -q "medium.sources\[0\].file: frame 3: cannot open '.*puff.0013.vdb'" "$tmp/err.txt" ||
  fail "the message: $(cat "$tmp/err.txt")"
[ -f "$tmp/out/f.0001.exr" ] && [ -f "$tmp/out/f.0002.exr" ] && [ ! -e "$tmp/out/f.0003.exr" ] ||
  fail "frames before the missing one: $(ls "$tmp/out")"
rm -f "$tmp/out"/*
"$veil" turntable "$tmp/scene.json" -o "$tmp/out/f.####.exr" --frames 4 --degrees 0 --skip-missing \
  > "$tmp/out.txt" 2> "$tmp/err.txt" || fail "--skip-missing: $(cat "$tmp/err.txt")"
grep -q "3 frames rendered, 0 already there, 1 without their source files" "$tmp/out.txt" || fail "$(cat "$tmp/out.txt")"
grep -q "frame 3: cannot open .*(skipped)" "$tmp/err.txt" || fail "no word of the skipped frame: $(cat "$tmp/err.txt")"
[ ! -e "$tmp/out/f.0003.exr" ] || fail "a frame without its source was written"
# the camera stands still (--degrees 0) and the seeds differ per frame, so frames 1 and 4 (the same file)
# differ only by the march's jitter, frame 2 (another volume) by far more: compare the rel. RMSE of each
# against frame 1 (veil compare) -- the jitter moves a pixel by a fraction of a step's light, the sphere
# replaces the plume
r14=$("$veil" compare "$tmp/out/f.0004.exr" "$tmp/out/f.0001.exr" --json | sed -n 's/.*"rel_rmse": *\([0-9.e+-]*\).*/\1/p')
r12=$("$veil" compare "$tmp/out/f.0002.exr" "$tmp/out/f.0001.exr" --json | sed -n 's/.*"rel_rmse": *\([0-9.e+-]*\).*/\1/p')
echo "frame 4 vs 1: $r14, frame 2 vs 1: $r12"
[ -n "$r14" ] && [ -n "$r12" ] || fail "veil compare gave no rel_rmse"
awk -v a="$r14" -v b="$r12" 'BEGIN { exit !(a < 0.05 && b > 0.5 && b > 10 * a) }' ||
  fail "frame 4 (same file as 1) differs from 1 by $r14, frame 2 (another file) by $r12"
# a bad pattern and frame_offset without a sequence are refused, naming the field
scene "seq/puff.##.%04d.vdb" ''
"$veil" turntable "$tmp/scene.json" -o "$tmp/out/g.####.exr" 2> "$tmp/err.txt" > /dev/null
[ $? -eq 1 ] && grep -q "medium.sources\[0\].file: .*frame number once" "$tmp/err.txt" || fail "bad pattern: $(cat "$tmp/err.txt")"
scene "seq/puff.0011.vdb" ', "frame_offset": 3'
"$veil" turntable "$tmp/scene.json" -o "$tmp/out/g.####.exr" 2> "$tmp/err.txt" > /dev/null
[ $? -eq 1 ] && grep -q "medium.sources\[0\].frame_offset: only for a sequence" "$tmp/err.txt" ||
  fail "frame_offset without a sequence: $(cat "$tmp/err.txt")"
echo PASS
