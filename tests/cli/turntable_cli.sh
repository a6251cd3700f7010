#!/usr/bin/env bash
# veil turntable end to end: a range rendered in two shards is the same,
# byte for byte, as in one run (each frame depends only on the scene and
# its number); --skip-existing renders only the missing frames and leaves
# the others' bytes alone; bad ranges, shards and patterns are usage errors.
# Usage: turntable_cli.sh VEIL SCENE
set -u
veil=$1
scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

for bad in "--range 5-1" "--range 1-4x0" "--shard 3/2" "--shard 0/2" "--frames 0" "--frames 3 --range 1-3" \
           "--elevation 90" "--axis 0,0,0" "--movie out.avi" "--fps 0"; do
  "$veil" turntable "$scene" -o "$tmp/f.####.exr" $bad 2> "$tmp/usage.err"; rc=$?
  [ $rc -eq 2 ] || fail "'$bad': exit $rc, expected 2"
done
"$veil" turntable "$scene" -o "$tmp/nonumber.exr" --frames 2 2> "$tmp/usage.err"; [ $? -eq 2 ] || fail "no frame number in -o"
grep -q "needs the frame number once" "$tmp/usage.err" || fail "the message: $(cat "$tmp/usage.err")"
"$veil" turntable "$scene" -o "$tmp/f.##.%04d.exr" --frames 2 2> /dev/null; [ $? -eq 2 ] || fail "two frame numbers in -o"

# no GPU needed so far; the renders need one
if ! "$veil" gpuinfo > /dev/null 2>&1; then # skipped (exit 77) without a GL 4.5 context, except under CI=true
  if [ "${CI:-}" = "true" ]; then fail "no GL context under CI"; fi
  echo "SKIPPED: no GL 4.5 context"; exit 77
fi
args=(--range 1001-1007x2 --width 48 --height 36 --degrees 120 --elevation 15 --seed 9)
mkdir -p "$tmp/one" "$tmp/two"
"$veil" turntable "$scene" -o "$tmp/one/t.####.exr" --png "$tmp/one/t.####.png" "${args[@]}" > "$tmp/one.txt" ||
  fail "one run: $(cat "$tmp/one.txt")"
grep -q "4 frames rendered, 0 already there" "$tmp/one.txt" || fail "one run: $(cat "$tmp/one.txt")"
for shard in 2/2 1/2; do
  "$veil" turntable "$scene" -o "$tmp/two/t.%04d.exr" --png "$tmp/two/t.%04d.png" "${args[@]}" --shard $shard \
    > "$tmp/two.txt" || fail "shard $shard: $(cat "$tmp/two.txt")"
  grep -q "2 frames rendered" "$tmp/two.txt" || fail "shard $shard: $(cat "$tmp/two.txt")"
done
for f in 1001 1003 1005 1007; do
  cmp -s "$tmp/one/t.$f.exr" "$tmp/two/t.$f.exr" || fail "frame $f differs between one run and two shards"
  cmp -s "$tmp/one/t.$f.png" "$tmp/two/t.$f.png" || fail "frame $f's PNG differs between one run and two shards"
done
ls "$tmp/one" | grep -q '1002' && fail "a frame off the range's step was written"
# the header a compositor reads (test_frames checks the values; here, that the command writes them)
for attr in frame worldToCamera worldToNDC veil:sceneHash veil:settings software; do
  head -c 4096 "$tmp/one/t.1003.exr" | grep -a -q "$attr" || fail "frame 1003's header lacks $attr"
done
cmp -s "$tmp/one/t.1001.exr" "$tmp/one/t.1003.exr" && fail "frames 1001 and 1003 are the same image"

# --stats: each frame's stages, and the run's total: inject once, the march on every frame
"$veil" turntable "$scene" -o "$tmp/st.####.exr" --frames 3 --width 24 --height 18 --stats > "$tmp/stats.txt" ||
  fail "--stats: $(cat "$tmp/stats.txt")"
grep -q "^total over 3 frames" "$tmp/stats.txt" && grep -q "^inject .*(ran on 1 of 3 frames)" "$tmp/stats.txt" &&
  grep -q "^render .*(ran on 3 of 3 frames)" "$tmp/stats.txt" || fail "--stats totals: $(cat "$tmp/stats.txt")"

# the status line: none in a pipe by default, one with --progress (frames, then the time left)
"$veil" turntable "$scene" -o "$tmp/st.####.exr" --frames 3 --width 24 --height 18 2> "$tmp/plain.err" > /dev/null
[ ! -s "$tmp/plain.err" ] || fail "a status line into a pipe: $(cat "$tmp/plain.err")"
"$veil" turntable "$scene" -o "$tmp/st.####.exr" --frames 3 --width 24 --height 18 --progress 2> "$tmp/prog.err" > /dev/null
grep -q "veil: frame 1 (1 of 3)" "$tmp/prog.err" && grep -q "veil: frame 3 (3 of 3, about [0-9]* s left)" "$tmp/prog.err" ||
  fail "--progress: $(tr '\r' '\n' < "$tmp/prog.err")"

# --skip-existing: remove one frame, rerun: only it is rendered, the others keep their bytes and times
touch -d '2001-01-01' "$tmp/one/t.1001.exr"
rm "$tmp/one/t.1005.exr"
"$veil" turntable "$scene" -o "$tmp/one/t.####.exr" --png "$tmp/one/t.####.png" "${args[@]}" --skip-existing \
  > "$tmp/skip.txt" || fail "skip run: $(cat "$tmp/skip.txt")"
grep -q "1 frames rendered, 3 already there" "$tmp/skip.txt" || fail "skip run: $(cat "$tmp/skip.txt")"
[ "$(stat -c %Y "$tmp/one/t.1001.exr")" = "$(date -d '2001-01-01' +%s)" ] || fail "--skip-existing rewrote a frame"
cmp -s "$tmp/one/t.1005.exr" "$tmp/two/t.1005.exr" || fail "the re-rendered frame differs"
ls "$tmp/one" | grep -q 'veil-staged' && fail "a staging file was left behind"
# review outputs, from the frames on disk: a contact sheet (4 frames: 2 x 2 thumbnails of 48 x 36, 2 pixels
# apart: 102 x 78), and a movie through ffmpeg -- or, without ffmpeg, the exact error and no movie file
"$veil" turntable "$scene" -o "$tmp/one/t.####.exr" "${args[@]}" --skip-existing --contact-sheet "$tmp/sheet.png" \
  > "$tmp/sheet.txt" || fail "contact sheet: $(cat "$tmp/sheet.txt")"
size=$(od -An -tu1 -j16 -N8 "$tmp/sheet.png" | awk '{print (($1 * 256 + $2) * 256 + $3) * 256 + $4 "x" (($5 * 256 + $6) * 256 + $7) * 256 + $8}')
[ "$size" = "102x78" ] || fail "contact sheet of $size, expected 102x78"
"$veil" turntable "$scene" -o "$tmp/one/t.####.exr" "${args[@]}" --skip-existing --movie "$tmp/t.mp4" \
  > "$tmp/movie.txt" 2> "$tmp/movie.err"; rc=$?
if command -v ffmpeg > /dev/null; then
  [ $rc -eq 0 ] && [ -s "$tmp/t.mp4" ] || fail "movie: exit $rc: $(cat "$tmp/movie.err")"
  grep -q "wrote the movie .* 4 frames at 24 fps" "$tmp/movie.txt" || fail "$(cat "$tmp/movie.txt")"
else
  [ $rc -eq 1 ] && grep -q "needs the ffmpeg program (Debian package ffmpeg)" "$tmp/movie.err" || fail "no ffmpeg: exit $rc: $(cat "$tmp/movie.err")"
  [ ! -e "$tmp/t.mp4" ] || fail "a movie file without ffmpeg"
fi
ls "$tmp" | grep -q 'veil-frames\|veil-staged' && fail "the movie's scratch files were left behind"
# a review output whose folder is a file is refused before any frame (a missing folder is made)
touch "$tmp/plain"
"$veil" turntable "$scene" -o "$tmp/none.####.exr" --frames 2 --movie "$tmp/plain/dir/t.mp4" 2> "$tmp/dir.err" > /dev/null
[ $? -eq 2 ] && grep -q "its folder '$tmp/plain' is a file" "$tmp/dir.err" || fail "a movie under a file: $(cat "$tmp/dir.err")"
ls "$tmp" | grep -q '^none\.' && fail "frames were rendered before the movie's folder was checked"
# a shard alone cannot make the movie of the whole range
rm "$tmp/two/t.1007.exr"
"$veil" turntable "$scene" -o "$tmp/two/t.%04d.exr" "${args[@]}" --shard 1/2 --skip-existing --contact-sheet "$tmp/s2.png" \
  > /dev/null 2> "$tmp/shard.err"
[ $? -eq 1 ] && grep -q "1 of the range's 4 frames are not written yet (frame 1007 first)" "$tmp/shard.err" ||
  fail "a sheet over missing frames: $(cat "$tmp/shard.err")"
# frames are written on a thread of their own while the next renders (cli/frame_out.h): a write that
# fails (a file size limit under a frame's size, SIGXFSZ ignored so the write fails with EFBIG) ends
# the run naming the frame, with no frame after it rendered to the end and no temporary left
mkdir -p "$tmp/limited"
bash -c 'trap "" XFSZ; ulimit -f 4; exec "$@"' _ "$veil" turntable "$scene" -o "$tmp/limited/t.####.exr" \
  --frames 6 --width 96 --height 72 > "$tmp/limited.txt" 2> "$tmp/limited.err"; rc=$?
[ $rc -eq 1 ] && grep -q "t.0001.exr" "$tmp/limited.err" || fail "a failed write: exit $rc: $(cat "$tmp/limited.err")"
grep -q "frames rendered" "$tmp/limited.txt" && fail "a failed write still reported: $(cat "$tmp/limited.txt")"
[ -z "$(ls "$tmp/limited")" ] || fail "a failed write left files: $(ls "$tmp/limited")"
# SIGINT while frames render and write: exit 130, the frames finished before it whole, no temporary left
mkdir -p "$tmp/int"
"$veil" turntable "$scene" -o "$tmp/int/t.####.exr" --frames 400 --width 64 --height 48 > /dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do [ -e "$tmp/int/t.0003.exr" ] && break; sleep 0.05; done
kill -INT $pid; wait $pid; rc=$?
[ $rc -eq 130 ] || fail "SIGINT during a turntable: exit $rc, expected 130"
ls "$tmp/int" | grep -q -e 'veil-staged' -e '\.tmp' && fail "SIGINT left temporaries: $(ls "$tmp/int")"
n=0
for f in "$tmp/int"/t.*.exr; do
  "$veil" compare "$f" "$f" > /dev/null 2>&1 || fail "SIGINT left $f unreadable"
  n=$((n + 1))
done
[ $n -ge 3 ] && [ $n -lt 400 ] || fail "SIGINT: $n frames written"
echo "PASS"
