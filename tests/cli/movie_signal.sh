#!/usr/bin/env bash
# SIGTERM and SIGINT during a turntable's --movie (issue 22, item 7): the
# movie's folder of PNG frames (OUT.veil-framesPID/), its staged file and
# ffmpeg itself were left behind, ffmpeg running on. Now the signal ends
# ffmpeg's process group and reaps it, removes the folder and the staged
# movie, and veil exits 130 / 143; the frames rendered stay (complete).
#
#   movie_signal.sh VEIL SCENE
#
# ffmpeg is a stand-in on PATH (no package needed, and deterministic): it
# records its pid, writes a partial movie to its last argument, starts a
# child of its own (so that its whole group must end) and waits. The signal
# is sent once it runs.
set -u
veil=$1
scene_src=$2
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
if ! "$veil" gpuinfo >/dev/null 2>&1; then
    [ "${CI:-}" = true ] && { echo "FAIL: no GL 4.5 context under CI"; exit 1; }
    echo "SKIPPED: no GL 4.5 context"
    exit 77
fi
cp "$scene_src" "$work/scene.json"
mkdir "$work/bin"
cat >"$work/bin/ffmpeg" <<'STUB'
#!/bin/sh
for last; do :; done
printf 'part of a movie' >"$last"
sleep 300 &
echo $$ >"$STUB_PID.tmp" && mv "$STUB_PID.tmp" "$STUB_PID"
exec sleep 301
STUB
chmod +x "$work/bin/ffmpeg"
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
for sig in TERM INT; do
    out=$work/$sig
    mkdir "$out"
    export STUB_PID=$work/stub.$sig
    PATH=$work/bin:$PATH "$veil" turntable "$work/scene.json" -o "$out/f.####.exr" --frames 3 --width 16 --height 12 \
        --movie "$out/m.mp4" >"$work/log.$sig" 2>&1 &
    pid=$!
    for _ in $(seq 600); do # up to 60 s for the frames, then ffmpeg
        [ -s "$STUB_PID" ] && break
        kill -0 "$pid" 2>/dev/null || break
        sleep 0.1
    done
    if [ ! -s "$STUB_PID" ]; then
        fail "SIG$sig: ffmpeg never ran: $(head -c 600 "$work/log.$sig")"
        kill "$pid" 2>/dev/null
        wait "$pid"
        continue
    fi
    stub=$(cat "$STUB_PID")
    [ -d "$out/m.mp4.veil-frames$pid" ] || fail "SIG$sig: no folder of frames while ffmpeg runs (the test tests nothing)"
    kill -s "$sig" "$pid"
    wait "$pid"
    rc=$?
    want=$([ "$sig" = INT ] && echo 130 || echo 143)
    [ "$rc" -eq "$want" ] || fail "SIG$sig: exit $rc (expected $want)"
    left=$(cd "$out" && ls -d -- *veil-frames* *veil-staged* m.mp4 2>/dev/null | head -3)
    [ -z "$left" ] || fail "SIG$sig: left behind: $left"
    # ffmpeg and its child: neither runs (a zombie reparented to init does not), nor anything in its group
    alive=$(ps -e -o pid=,ppid=,pgid=,stat=,args= | awk -v s="$stub" '($1 == s || $2 == s || $3 == s) && $4 !~ /^Z/')
    if [ -n "$alive" ]; then
        fail "SIG$sig: ffmpeg still runs: $alive"
        echo "$alive" | while read -r p _; do kill -9 "$p" 2>/dev/null; done
    fi
    n=$(ls "$out" | grep -c '^f\.000[123]\.exr$')
    [ "$n" -eq 3 ] || fail "SIG$sig: $n of the 3 rendered frames are there"
    [ $fails -eq 0 ] && echo "PASS SIG$sig: exit $rc, ffmpeg ended, nothing of the movie left"
done
[ $fails -eq 0 ] && echo "PASS: a movie interrupted leaves nothing"
[ $fails -eq 0 ]
