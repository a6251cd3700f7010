#!/usr/bin/env bash
# `veil reference` through the CLI: usage errors exit 2, bad scenes exit 1
# naming the file with no output left, and a small render is written,
# complete, and the same bytes for 1 and 2 threads (the path tracer is
# deterministic per pixel).
set -u
veil=$1
scene=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
expect() { # code, then the command
  local want=$1; shift
  "$@" > "$tmp/out" 2> "$tmp/err"; local rc=$?
  [ $rc -eq "$want" ] || fail "'$*' exited $rc, expected $want: $(cat "$tmp/err")"
}

expect 2 "$veil" reference
expect 2 "$veil" reference "$scene" -o "$tmp/r.exr"
grep -q -- "--spp" "$tmp/err" || fail "missing --spp not named: $(cat "$tmp/err")"
expect 2 "$veil" reference "$scene" -o "$tmp/r.exr" --spp 1
expect 2 "$veil" reference "$scene" -o "$tmp/r.exr" --spp 4 --max-order -1
expect 2 "$veil" reference "$scene" -o "$tmp/r.exr" --spp 4 --frobnicate 3
expect 1 "$veil" reference "$tmp/missing.json" -o "$tmp/r.exr" --spp 4
grep -q "$tmp/missing.json" "$tmp/err" || fail "missing scene not named: $(cat "$tmp/err")"
printf '{"camera": {"position": [0,0,1], "look_at": [0,0,0]}, "medium": {"sigma_s": [1,1,"x"]}}' > "$tmp/bad.json"
expect 1 "$veil" reference "$tmp/bad.json" -o "$tmp/r.exr" --spp 4
grep -q "bad.json" "$tmp/err" && grep -q "sigma_s" "$tmp/err" || fail "bad field not named: $(cat "$tmp/err")"
touch "$tmp/plain" # an output's folder that is a file: usage (a missing folder is made)
expect 2 "$veil" reference "$scene" -o "$tmp/plain/dir/r.exr" --spp 4
[ -z "$(ls "$tmp" | grep -v -e '^out$' -e '^err$' -e '^bad.json$' -e '^plain$')" ] || fail "failed runs left files: $(ls "$tmp")"

expect 0 "$veil" reference "$scene" -o "$tmp/made/a.exr" --spp 2 --width 24 --height 18 --threads 1 --seed 5
grep -q "wrote $tmp/made/a.exr (24x18, 2 spp" "$tmp/out" || fail "summary: $(cat "$tmp/out")"
grep -q " 0 cut walks, 0 dropped samples" "$tmp/out" || fail "safeguards fired: $(cat "$tmp/out")"
expect 0 "$veil" reference "$scene" -o "$tmp/b.exr" --spp 2 --width 24 --height 18 --threads 2 --seed 5
cmp -s "$tmp/made/a.exr" "$tmp/b.exr" || fail "1 and 2 threads wrote different files"
expect 0 "$veil" reference "$scene" -o "$tmp/c.exr" --spp 2 --width 24 --height 18 --threads 2 --seed 6
cmp -s "$tmp/made/a.exr" "$tmp/c.exr" && fail "seeds 5 and 6 wrote the same file"
echo "PASS"
