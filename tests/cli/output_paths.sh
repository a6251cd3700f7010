#!/usr/bin/env bash
# Output paths (issue 12, defects 3 and 10): no run overwrites its input,
# writes two outputs to one file, takes an empty or directory path, or
# loses an existing output when a later file of the same run fails.
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
check "render -o SCENE" 2 "-o: '$scene' is an input of this run" "$veil" render "$scene" -o "$scene" "${small[@]}"
cmp -s "$scene" "$work/scene.orig" || { echo "FAIL: the scene was changed"; fails=$((fails + 1)); }
# the same file under another name (a symbolic link) too
ln -s "$scene" "$work/link.exr"
check "render -o LINK-TO-SCENE" 2 "is an input of this run" "$veil" render "$scene" -o "$work/link.exr" "${small[@]}"
cmp -s "$scene" "$work/scene.orig" || { echo "FAIL: the scene was changed through a link"; fails=$((fails + 1)); }
# both outputs one file
check "render -o X --png X" 2 "-o and --png: both are '$work/x.exr'" \
    "$veil" render "$scene" -o "$work/x.exr" --png "$work/x.exr" "${small[@]}"
# every frame of a run, not only the first (issue 22, items 1 and 2): a later frame's name that is
# the scene, and a frame whose EXR and PNG are one file, are usage errors before any frame is written
mkdir "$work/frames"
cp "$scene" "$work/frames/s2.json"
cp "$scene" "$work/frames/s_0001.json"
check "turntable -o 's#.json', frame 2 is the scene" 2 "-o: '$work/frames/s2.json' is an input of this run" \
    "$veil" turntable "$work/frames/s2.json" -o "$work/frames/s#.json" --range 1-2 "${small[@]}"
cmp -s "$work/frames/s2.json" "$scene" || { echo "FAIL: s2.json was changed"; fails=$((fails + 1)); }
check "render --turntable 2 -o s.json, frame 1 is the scene" 2 "is an input of this run" \
    "$veil" render "$work/frames/s_0001.json" -o "$work/frames/s.json" --turntable 2 "${small[@]}"
cmp -s "$work/frames/s_0001.json" "$scene" || { echo "FAIL: s_0001.json was changed"; fails=$((fails + 1)); }
check "turntable -o 'f#.exr' --png 'f##.exr', frame 10's two files are one" 2 \
    "-o and --png: both are '$work/frames/f10.exr'" \
    "$veil" turntable "$work/frames/s2.json" -o "$work/frames/f#.exr" --png "$work/frames/f##.exr" --range 9-10 "${small[@]}"
[ ! -e "$work/frames/f9.exr" ] || { echo "FAIL: frame 9 was written before the clash was found"; fails=$((fails + 1)); }
# empty and directory paths: usage errors before any work
check "render -o ''" 2 "-o: an empty path" "$veil" render "$scene" -o "" "${small[@]}"
mkdir "$work/dir"
check "render -o DIR" 2 "-o: '$work/dir' is a directory" "$veil" render "$scene" -o "$work/dir" "${small[@]}"
check "reference -o SCENE" 2 "-o: '$scene' is an input of this run" "$veil" reference "$scene" -o "$scene" --spp 2
# the PNG cannot be written after the EXR was (its target is a FIFO): exit 1, and the
# existing OUT.exr is the one that was there, byte for byte; nothing staged is left
printf 'the old image' >"$work/out.exr"
mkfifo "$work/out.png"
check "render, the PNG fails" 1 "out.png" "$veil" render "$scene" -o "$work/out.exr" --png "$work/out.png" "${small[@]}"
[ "$(cat "$work/out.exr")" = "the old image" ] || { echo "FAIL: the existing out.exr was lost or changed"; fails=$((fails + 1)); }
left=$(find "$work" -name '*.veil-staged*' -o -name '*.tmp*' | head -3)
[ -z "$left" ] || { echo "FAIL: left behind: $left"; fails=$((fails + 1)); }
# and a good run replaces both
rm "$work/out.png"
check "render, both written" 0 "wrote" "$veil" render "$scene" -o "$work/out.exr" --png "$work/out.png" "${small[@]}"
[ "$(head -c 4 "$work/out.exr" | od -An -tx1 | tr -d ' ')" = "762f3101" ] || { echo "FAIL: out.exr is not an EXR"; fails=$((fails + 1)); }
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
