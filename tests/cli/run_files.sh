#!/usr/bin/env bash
# The files of a run checked before any work (issue 22, items 1, 2 and 12,
# and the output folders): every file a command writes -- each frame of a
# range under -o and --png, the contact sheet, the movie and their staging
# names -- against every file it reads -- the scene, its VDB and particle
# files and the environment's map (issue 41), each frame of a sequence,
# through symbolic and hard links -- and
# against each other. A clash is a usage error (exit 2) naming both files,
# with nothing written; so are review outputs that could only fail after
# every frame (a directory, a folder that is a file, over 100 000 frames);
# a folder that cannot be written is exit 1, before any frame. No GPU is
# needed: each case is refused before one is asked for.
#
#   run_files.sh VEIL SCENE VDB
#
# SCENE: a scene without files (its copies are used); VDB: a small VDB.
set -u
veil=$1
scene_src=$2
vdb_src=$3
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
cd "$work" || exit 1
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
# check NAME RC TEXT COMMAND...: the exit status and a fixed string of the output
check() {
    local name=$1 want=$2 text=$3
    shift 3
    timeout 60 "$@" >out.txt 2>&1
    local rc=$?
    if [ "$rc" -ne "$want" ] || ! grep -qF -- "$text" out.txt; then
        fail "$name: exit $rc (expected $want), output: $(head -c 600 out.txt)"
    else
        echo "PASS $name: exit $rc"
    fi
}
# nothing NAME: no frame, staged file, movie or sheet was written
nothing() {
    local left
    left=$(find . -newer stamp \( -name '*.exr' -o -name '*.png' -o -name '*.mp4' -o -name '*veil-*' \) \
        ! -name fifo.exr ! -name 'adir.*' ! -name scene.mp4 | head -3)
    [ -z "$left" ] || fail "$1: written: $left"
}
small=(--width 16 --height 12)
cp "$scene_src" s2.json
cp "$scene_src" s_0001.json
cp "$vdb_src" smoke.vdb
ln smoke.vdb hard.vdb
ln -s smoke.vdb soft.vdb
sum=$(cksum <smoke.vdb)
for f in smoke hard soft; do
    printf '{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "vdb", "file": "%s.vdb"}]}}\n' "$f" >"reads_$f.json"
done
touch -d '2001-01-01' stamp

# --- item 1: a later frame, the review outputs, the scene's files
check "turntable -o 's#.json' --range 1-2: frame 2 is the scene" 2 \
    "-o 's2.json' (frame 2) is the scene 's2.json', which this run reads: it would be overwritten" \
    "$veil" turntable s2.json -o 's#.json' --range 1-2 "${small[@]}"
cmp -s s2.json "$scene_src" || fail "s2.json was changed"
check "render --turntable 2 -o s.json: frame 1 is the scene" 2 \
    "-o 's_0001.json' (frame 1) is the scene 's_0001.json'" \
    "$veil" render s_0001.json -o s.json --turntable 2 "${small[@]}"
cmp -s s_0001.json "$scene_src" || fail "s_0001.json was changed"
check "--contact-sheet naming the scene" 2 "--contact-sheet 's2.json' is the scene 's2.json'" \
    "$veil" turntable s2.json -o 'f#.exr' --range 1-2 --contact-sheet s2.json "${small[@]}"
check "--contact-sheet naming a frame" 2 "--contact-sheet 'f2.exr' and -o 'f2.exr' (frame 2) are one file" \
    "$veil" turntable s2.json -o 'f#.exr' --range 1-2 --contact-sheet f2.exr "${small[@]}"
cp "$scene_src" scene.mp4
check "--movie naming the scene" 2 "--movie 'scene.mp4' is the scene 'scene.mp4'" \
    "$veil" turntable scene.mp4 -o 'f#.exr' --range 1-2 --movie scene.mp4 "${small[@]}"
check "--movie naming a frame" 2 "--movie 'f2.mp4' and -o 'f2.mp4' (frame 2) are one file" \
    "$veil" turntable s2.json -o 'f#.mp4' --range 1-2 --movie f2.mp4 "${small[@]}"
for how in smoke hard soft; do
    text="-o 'smoke.vdb' is medium.sources[0].file '$how.vdb'"
    [ $how = smoke ] || text="$text under another name (a link)"
    check "render -o smoke.vdb, the scene reading $how.vdb" 2 "$text" \
        "$veil" render "reads_$how.json" -o smoke.vdb "${small[@]}"
done
check "render -o soft.vdb (a link to what the scene reads)" 2 "under another name (a link)" \
    "$veil" render reads_smoke.json -o soft.vdb "${small[@]}"
check "reference -o sub/../smoke.vdb" 2 "-o 'sub/../smoke.vdb' is medium.sources[0].file 'smoke.vdb'" \
    "$veil" reference reads_smoke.json -o sub/../smoke.vdb --spp 2
[ ! -e sub ] || fail "reference made the folder sub/ for a refused output"
check "fog -o smoke.vdb" 2 "-o 'smoke.vdb' is medium.sources[0].file 'smoke.vdb'" \
    "$veil" fog frame.exr --scene reads_smoke.json -o smoke.vdb
check "fog -o FRAME" 2 "-o 'frame.exr' is the frame 'frame.exr'" \
    "$veil" fog frame.exr --scene reads_smoke.json -o frame.exr
[ "$(cksum <smoke.vdb)" = "$sum" ] || fail "smoke.vdb was changed"
# a particle file
"$veil" rbf generate -o parts.json --count 3 --seed 1 --bounds 0,0,0,1,1,1 --radius 0.1,0.2 --amplitude 1,2 \
    >/dev/null || fail "rbf generate"
printf '{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "rbf", "file": "parts.json"}]}}\n' >reads_parts.json
check "render -o PARTICLES" 2 "-o 'parts.json' is medium.sources[0].file 'parts.json'" \
    "$veil" render reads_parts.json -o parts.json "${small[@]}"
# every frame of a sequence in the range (frame f reads sm.(f+1))
mkdir seq
for i in 1 2 3 4; do cp "$vdb_src" "seq/sm.000$i.vdb"; done
printf '{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "vdb", "file": "seq/sm.####.vdb", "frame_offset": 1}]}}\n' \
    >seq.json
check "turntable -o the sequence's pattern" 2 \
    "-o 'seq/sm.0002.vdb' (frame 2) is medium.sources[0].file 'seq/sm.0002.vdb' (frame 1)" \
    "$veil" turntable seq.json -o 'seq/sm.####.vdb' --range 1-3
check "turntable --contact-sheet on frame 3's file" 2 \
    "--contact-sheet 'seq/sm.0004.vdb' is medium.sources[0].file 'seq/sm.0004.vdb' (frame 3)" \
    "$veil" turntable seq.json -o 'f#.exr' --range 1-3 --contact-sheet seq/sm.0004.vdb
# a staging name that is an input: the scene reads "out.exr.veil-staged<pid>" (the pid known through exec)
check "a frame's staging name is an input" 2 "-o 'out.exr' is first written as 'out.exr.veil-staged" \
    bash -c 'cp smoke.vdb "out.exr.veil-staged$$"
             printf "{\"camera\": {\"position\": [0, 0, 3], \"look_at\": [0, 0, 0]}, \"medium\": {\"sigma_s\": [1, 1, 1], \"sources\":
                      [{\"type\": \"vdb\", \"file\": \"out.exr.veil-staged$$\"}]}}" >staged.json
             exec "$0" render staged.json -o out.exr --width 16 --height 12' "$veil"
rm -f out.exr.veil-staged*

# --- issue 41, item 1: the environment map is an input of every command (a 2:1 EXR made without a GPU)
"$veil" reference s2.json -o sky.exr --width 8 --height 4 --spp 2 >/dev/null 2>&1 || fail "reference wrote no map"
cp sky.exr m1.exr
ln -s sky.exr sky_link.exr
sky_sum=$(cksum <sky.exr)
for map in sky m1; do
    printf '{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "exponential", "density": 0.3, "falloff": 1,
   "direction": [0, 1, 0], "origin": [0, 0, 0], "bounds": [[-1, -1, -1], [1, 1, 1]]}]},
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]},
   {"type": "environment", "file": "%s.exr"}]}\n' "$map" >"reads_$map.json"
done
text="is lights[1].file 'sky.exr', which this run reads: it would be overwritten"
check "render -o MAP" 2 "-o 'sky.exr' $text" "$veil" render reads_sky.json -o sky.exr
check "render --png MAP" 2 "--png 'sky.exr' $text" "$veil" render reads_sky.json -o x.exr --png sky.exr
check "render --deep MAP" 2 "--deep 'sky.exr' $text" "$veil" render reads_sky.json -o x.exr --deep sky.exr
check "render -o a link to MAP" 2 "-o 'sky_link.exr' is lights[1].file 'sky.exr' under another name (a link)" \
    "$veil" render reads_sky.json -o sky_link.exr
check "render --turntable 2: frame 1 is the map" 2 "-o 'sky_0001.exr' (frame 1) is lights[1].file" \
    bash -c 'cp sky.exr sky_0001.exr && sed s/sky.exr/sky_0001.exr/ reads_sky.json >rt.json &&
             exec "$0" render rt.json -o sky.exr --turntable 2' "$veil"
check "turntable: frame 1 named like the map" 2 "-o 'm1.exr' (frame 1) is lights[1].file 'm1.exr'" \
    "$veil" turntable reads_m1.json -o 'm#.exr' --range 1-2
check "fog -o MAP" 2 "-o 'sky.exr' $text" "$veil" fog frame.exr --scene reads_sky.json -o sky.exr
check "reference -o MAP" 2 "-o 'sky.exr' $text" "$veil" reference reads_sky.json -o sky.exr --spp 2
[ "$(cksum <sky.exr)" = "$sky_sum" ] && cmp -s sky.exr m1.exr || fail "an environment map was changed"
touch -h -d '2000-01-01' sky.exr m1.exr sky_0001.exr sky_link.exr # inputs, older than the stamp: not written

# --- item 2, and two frames of one pattern on one file
check "-o 'f#.exr' --png 'f##.exr' --range 9-10" 2 "-o 'f10.exr' (frame 10) and --png 'f10.exr' (frame 10) are one file" \
    "$veil" turntable s2.json -o 'f#.exr' --png 'f##.exr' --range 9-10 "${small[@]}"
check "frame 10's EXR is frame 1's PNG" 2 "--png 'f10.exr' (frame 1) and -o 'f10.exr' (frame 10) are one file" \
    "$veil" turntable s2.json -o 'f#.exr' --png 'f#0.exr' --range 1-10 "${small[@]}"
mkdir d9 d10
check "two frames of one pattern on one file" 2 "-o 'd9/../x.exr' (frame 9) and -o 'd10/../x.exr' (frame 10) are one file" \
    "$veil" turntable s2.json -o 'd#/../x.exr' --range 9-10 "${small[@]}"
ln -s d9 d11
check "two frames, one folder through a link" 2 "-o 'd9/x.exr' (frame 9) and -o 'd11/x.exr' (frame 11) are one file" \
    "$veil" turntable s2.json -o 'd#/x.exr' --range 9-11x2 "${small[@]}"
mkfifo fifo.exr
check "-o a FIFO" 2 "-o: 'fifo.exr' exists and is not a regular file" "$veil" render s2.json -o fifo.exr "${small[@]}"

# --- item 12: what failed after every frame
mkdir adir.png adir.mp4
check "--contact-sheet a directory" 2 "--contact-sheet: 'adir.png' is a directory" \
    "$veil" turntable s2.json -o 'f#.exr' --frames 2 --contact-sheet adir.png "${small[@]}"
check "--movie a directory" 2 "--movie: 'adir.mp4' is a directory" \
    "$veil" turntable s2.json -o 'f#.exr' --frames 2 --movie adir.mp4 "${small[@]}"
check "a review of 100 001 frames" 2 "--contact-sheet: the range has 100001 frames; a movie or a contact sheet takes at most 100000" \
    "$veil" turntable s2.json -o 'f#.exr' --range 1-100001 --contact-sheet sheet.png "${small[@]}"
touch plain
check "--contact-sheet under a file" 2 "--contact-sheet: 'plain/s.png': its folder 'plain' is a file" \
    "$veil" turntable s2.json -o 'f#.exr' --frames 2 --contact-sheet plain/s.png "${small[@]}"
check "-o under a file" 2 "-o: 'plain/f1.exr' (frame 1): its folder 'plain' is a file" \
    "$veil" turntable s2.json -o 'plain/f#.exr' --frames 2 "${small[@]}"
check "--movie without ffmpeg, before any frame" 1 "needs the ffmpeg program (Debian package ffmpeg)" \
    env PATH=/nonexistent "$veil" turntable s2.json -o 'f#.exr' --frames 2 --movie m.mp4 "${small[@]}"
# a folder that cannot be written: as root, as another user (root writes anywhere)
mkdir ro
chmod 555 ro
as=()
[ "$(id -u)" -eq 0 ] && as=(setpriv --reuid=65534 --regid=65534 --clear-groups)
chmod 755 "$work"
if [ ${#as[@]} -eq 0 ] || command -v setpriv >/dev/null; then
    check "--contact-sheet into a read-only folder" 1 "--contact-sheet: 'ro/s.png': cannot write into the folder 'ro'" \
        "${as[@]}" "$veil" turntable s2.json -o 'f#.exr' --frames 2 --contact-sheet ro/s.png "${small[@]}"
    check "-o into a folder it cannot make" 1 "-o: 'ro/new/f1.exr': cannot make the folder 'ro/new'" \
        "${as[@]}" "$veil" turntable s2.json -o 'ro/new/f#.exr' --frames 2 "${small[@]}"
else
    echo "SKIPPED read-only folders: root here, and no setpriv to run as another user"
fi

# --- the folders: a run that fails before writing anything removes those it made (and only those)
mkdir keep
check "a failed run's folders" 1 "cannot open 'seq/sm.0006.vdb'" \
    "$veil" turntable seq.json -o 'keep/new/deep/f#.exr' --range 5-6
[ -d keep ] && [ ! -e keep/new ] || fail "the folders made for a failed run: $(find keep)"
nothing "all the refusals"
[ $fails -eq 0 ] && echo "PASS: every clash refused, nothing written"
[ $fails -eq 0 ]
