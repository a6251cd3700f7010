#!/usr/bin/env bash
# Output paths (issue 12, defects 3 and 10): no run overwrites its input,
# writes two outputs to one file, takes an empty or directory path, or
# loses an existing output when a later file of the same run fails; and
# (issue 22) a run's outputs' folders are made, --skip-existing takes only
# an EXR for a frame done. tests/cli/run_files.sh has the clashes that are
# refused before a GPU is asked for.
#
#   output_paths.sh VEIL SCENE
#
# SCENE: a small scene that renders (its copy in a temporary folder is used).
# Prints PASS or FAIL lines; exits 0 when all pass.
set -u
veil=$1
scene_src=$2
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
cp "$scene_src" "$work/scene.json"
scene=$work/scene.json
fails=0
if ! "$veil" gpuinfo >/dev/null 2>&1; then
    [ "${CI:-}" = true ] && { echo "FAIL: no GL 4.5 context under CI"; exit 1; }
    echo "SKIPPED: no GL 4.5 context"
    exit 77
fi
check() { # name, expected rc, expected text, command...
    local name=$1 want=$2 text=$3
    shift 3
    timeout 120 "$@" >"$work/out" 2>&1
    local rc=$?
    if [ "$rc" -ne "$want" ] || ! grep -qF -- "$text" "$work/out"; then
        echo "FAIL $name: exit $rc (expected $want), output: $(head -c 600 "$work/out")"
        fails=$((fails + 1))
    else
        echo "PASS $name: exit $rc, '$text'"
    fi
}
small=(--width 16 --height 12)

# -o naming the scene itself: usage error, the scene untouched
cp "$scene" "$work/scene.orig"
check "render -o SCENE" 2 "-o '$scene' is the scene '$scene', which this run reads" "$veil" render "$scene" -o "$scene" "${small[@]}"
cmp -s "$scene" "$work/scene.orig" || { echo "FAIL: the scene was changed"; fails=$((fails + 1)); }
# the same file under another name (a symbolic link) too
ln -s "$scene" "$work/link.exr"
check "render -o LINK-TO-SCENE" 2 "is the scene '$scene' under another name (a link), which this run reads" \
    "$veil" render "$scene" -o "$work/link.exr" "${small[@]}"
cmp -s "$scene" "$work/scene.orig" || { echo "FAIL: the scene was changed through a link"; fails=$((fails + 1)); }
# both outputs one file
check "render -o X --png X" 2 "-o '$work/x.exr' and --png '$work/x.exr' are one file" \
    "$veil" render "$scene" -o "$work/x.exr" --png "$work/x.exr" "${small[@]}"
# every frame of a run, not only the first (issue 22, items 1 and 2): a later frame's name that is
# the scene, and a frame whose EXR and PNG are one file, are usage errors before any frame is written
mkdir "$work/frames"
cp "$scene" "$work/frames/s2.json"
cp "$scene" "$work/frames/s_0001.json"
check "turntable -o 's#.json', frame 2 is the scene" 2 "-o '$work/frames/s2.json' (frame 2) is the scene" \
    "$veil" turntable "$work/frames/s2.json" -o "$work/frames/s#.json" --range 1-2 "${small[@]}"
cmp -s "$work/frames/s2.json" "$scene" || { echo "FAIL: s2.json was changed"; fails=$((fails + 1)); }
check "render --turntable 2 -o s.json, frame 1 is the scene" 2 "-o '$work/frames/s_0001.json' (frame 1) is the scene" \
    "$veil" render "$work/frames/s_0001.json" -o "$work/frames/s.json" --turntable 2 "${small[@]}"
cmp -s "$work/frames/s_0001.json" "$scene" || { echo "FAIL: s_0001.json was changed"; fails=$((fails + 1)); }
check "turntable -o 'f#.exr' --png 'f##.exr', frame 10's two files are one" 2 \
    "-o '$work/frames/f10.exr' (frame 10) and --png '$work/frames/f10.exr' (frame 10) are one file" \
    "$veil" turntable "$work/frames/s2.json" -o "$work/frames/f#.exr" --png "$work/frames/f##.exr" --range 9-10 "${small[@]}"
[ ! -e "$work/frames/f9.exr" ] || { echo "FAIL: frame 9 was written before the clash was found"; fails=$((fails + 1)); }
# empty and directory paths: usage errors before any work
check "render -o ''" 2 "-o: an empty path" "$veil" render "$scene" -o "" "${small[@]}"
mkdir "$work/dir"
check "render -o DIR" 2 "-o: '$work/dir' is a directory" "$veil" render "$scene" -o "$work/dir" "${small[@]}"
check "reference -o SCENE" 2 "-o '$scene' is the scene" "$veil" reference "$scene" -o "$scene" --spp 2
# the PNG cannot be written after the EXR was: exit 1, and the existing OUT.exr is the one that was
# there, byte for byte; nothing staged is left. The PNG's staging name is made a directory beforehand
# (its name holds the pid: known through exec), since a FIFO as the target is now refused before any
# work (issue 22)
printf 'the old image' >"$work/out.exr"
check "render, the PNG fails" 1 "out.png" bash -c 'mkdir "$1.veil-staged$$" && exec "$2" render "$3" -o "$4" --png "$1" \
    --width 16 --height 12' _ "$work/out.png" "$veil" "$scene" "$work/out.exr"
[ "$(cat "$work/out.exr")" = "the old image" ] || { echo "FAIL: the existing out.exr was lost or changed"; fails=$((fails + 1)); }
rmdir "$work"/out.png.veil-staged*
left=$(find "$work" -name '*.veil-staged*' -o -name '*.tmp*' | head -3)
[ -z "$left" ] || { echo "FAIL: left behind: $left"; fails=$((fails + 1)); }
# a FIFO as the PNG: refused before any work
mkfifo "$work/out.png"
check "render --png FIFO" 2 "--png: '$work/out.png' exists and is not a regular file" \
    "$veil" render "$scene" -o "$work/out.exr" --png "$work/out.png" "${small[@]}"
# and a good run replaces both
rm "$work/out.png"
check "render, both written" 0 "wrote" "$veil" render "$scene" -o "$work/out.exr" --png "$work/out.png" "${small[@]}"
[ "$(head -c 4 "$work/out.exr" | od -An -tx1 | tr -d ' ')" = "762f3101" ] || { echo "FAIL: out.exr is not an EXR"; fails=$((fails + 1)); }
# the outputs' folders are made (issue 22: film tools make frames/), for every command
check "render into folders not made yet" 0 "wrote" "$veil" render "$scene" -o "$work/new/deep/x.exr" \
    --png "$work/new/p/x.png" "${small[@]}"
[ -f "$work/new/deep/x.exr" ] && [ -f "$work/new/p/x.png" ] || { echo "FAIL: render's folders"; fails=$((fails + 1)); }
check "turntable into folders not made yet" 0 "wrote the contact sheet" "$veil" turntable "$scene" \
    -o "$work/tt/frames/f.####.exr" --png "$work/tt/png/f.####.png" --frames 2 --contact-sheet "$work/tt/sheet/s.png" \
    "${small[@]}"
[ -f "$work/tt/frames/f.0002.exr" ] && [ -f "$work/tt/png/f.0002.png" ] && [ -f "$work/tt/sheet/s.png" ] ||
    { echo "FAIL: turntable's folders: $(find "$work/tt")"; fails=$((fails + 1)); }
# --skip-existing counts a frame done only when its file is an EXR (issue 22, item 2: a clash of names
# once left a PNG under the EXR's name): frame 2 replaced by a PNG is rendered again
cp "$work/tt/png/f.0002.png" "$work/tt/frames/f.0002.exr"
check "--skip-existing, frame 2 a PNG" 0 "1 frames rendered, 1 already there" "$veil" turntable "$scene" \
    -o "$work/tt/frames/f.####.exr" --frames 2 --skip-existing "${small[@]}"
[ "$(head -c 4 "$work/tt/frames/f.0002.exr" | od -An -tx1 | tr -d ' ')" = "762f3101" ] ||
    { echo "FAIL: f.0002.exr is not an EXR again"; fails=$((fails + 1)); }
# interrupted (issue 12, defect 6): SIGINT exits 130, SIGTERM 143, nothing written, nothing left
for sig in INT TERM; do
    "$veil" reference "$scene" -o "$work/long.exr" --spp 1000000 --width 32 --height 24 >/dev/null 2>&1 &
    pid=$!
    sleep 1
    kill -s "$sig" "$pid"
    wait "$pid"
    rc=$?
    want=$([ "$sig" = INT ] && echo 130 || echo 143)
    left=$(find "$work" -name 'long.exr*' | head -3)
    if [ "$rc" -ne "$want" ] || [ -n "$left" ]; then
        echo "FAIL SIG$sig: exit $rc (expected $want), left: $left"
        fails=$((fails + 1))
    else
        echo "PASS SIG$sig: exit $rc, nothing left"
    fi
done
[ $fails -eq 0 ] && echo "PASS: all output-path checks"
[ $fails -eq 0 ]
