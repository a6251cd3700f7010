#!/usr/bin/env bash
# Progress on a terminal (cli/progress.h, issue 12): `veil render` on a
# pseudo-terminal (util-linux script) draws a status line per stage, with
# the RBF splat's share done, and erases it before it prints; with stderr
# not a terminal it draws nothing. Exit 77 (skipped) when no GL context can
# be made, except under CI=true.
#   progress_tty.sh VEIL SCENE
set -u
veil=$1
scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

if ! "$veil" gpuinfo > /dev/null 2> "$tmp/gpuinfo.err"; then
  cat "$tmp/gpuinfo.err"
  [ "${CI:-}" = true ] && fail "no GL context under CI"
  echo "SKIPPED: no GL 4.5 context"; exit 77
fi
command -v script > /dev/null || fail "script (util-linux) is missing"

# on a terminal: stdout and stderr both go to script's pty, whose bytes are in tty.txt
args=(render "$scene" -o "$tmp/a.exr" --width 64 --height 48 --turntable 2)
script -qec "$(printf '%q ' "$veil" "${args[@]}")" /dev/null > "$tmp/tty.txt" 2>&1 ||
  fail "render on a terminal: $(cat "$tmp/tty.txt")"
esc=$(printf '\r\033[K')
for want in "veil: frame 1/2: inject" "frame 1/2: RBF splat 0%" "frame 1/2: RBF splat 100%" \
            "frame 1/2: propagate" "frame 2/2: march" "frame 2/2: spread"; do
  grep -qF "$want" "$tmp/tty.txt" || fail "no '$want' on the terminal: $(cat -v "$tmp/tty.txt")"
done
# the line is erased before the result is printed
grep -qF "${esc}wrote frames up to" "$tmp/tty.txt" || fail "the status line is not erased: $(cat -v "$tmp/tty.txt")"

# not a terminal: nothing but the result
"$veil" "${args[@]}" > "$tmp/out.txt" 2> "$tmp/err.txt" || fail "render: $(cat "$tmp/err.txt")"
[ ! -s "$tmp/err.txt" ] || fail "stderr not a terminal, yet: $(cat -v "$tmp/err.txt")"
grep -q "^wrote frames up to" "$tmp/out.txt" || fail "stdout: $(cat "$tmp/out.txt")"
echo "PASS: a status line per stage on a terminal, erased before output; none in a pipe"
