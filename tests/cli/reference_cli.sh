#!/usr/bin/env bash
# `veil reference` through the CLI: usage errors exit 2, bad scenes exit 1
# naming the file with no output left, and a small render is written,
# complete, and the same bytes for 1 and 2 threads (the path tracer is
# deterministic per pixel); --background lights is the white furnace.
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
expect 2 "$veil" reference "$scene" -o "$tmp/r.exr" --spp 4 --background sky
grep -q -- "--background: expected backdrop or lights, got 'sky'" "$tmp/err" || fail "bad --background: $(cat "$tmp/err")"
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

# --background lights, the white furnace: a medium that scatters and absorbs nothing (sigma_a 0) inside
# a constant sky of radiance 1 sends every path out again with its weight, so every pixel's expectation
# is exactly 1, what an empty scene's exact backdrop (T = 1) gives. veil compare puts the furnace's
# mean bias against 1 beside its standard error (from the reference's own stderr channels): within 4 of
# them (a false alarm 6e-5 of the time). As a backdrop the sky lights nothing: the puff (peak optical
# depth 2 sqrt(pi)/2.5 = 1.4) darkens the image by more than 4 of the furnace's standard errors.
cat > "$tmp/ones.json" <<'JSON'
{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": []}, "background": {"color": [1, 1, 1]}}
JSON
sed 's/"sources": \[\]/"sources": [{"type": "rbf", "particles": [{"center": [0, 0, 0], "amplitude": 1, "sharpness": 2.5}]}]/; s/"sigma_s": \[1, 1, 1\]/"sigma_a": [0, 0, 0], "sigma_s": [2, 2, 2], "phase": {"type": "hg", "g": 0.5}/' \
  "$tmp/ones.json" > "$tmp/furnace.json"
grep -q '"rbf"' "$tmp/furnace.json" || fail "the furnace scene was not made"
expect 0 "$veil" reference "$tmp/ones.json" -o "$tmp/ones.exr" --spp 2
expect 0 "$veil" reference "$tmp/furnace.json" -o "$tmp/lit.exr" --spp 64 --background lights
expect 0 "$veil" reference "$tmp/furnace.json" -o "$tmp/backdrop.exr" --spp 64 --background backdrop
field() { sed -n "s/^ *\"$1\": \([-0-9.e+]*\),*$/\1/p" "$2"; }
"$veil" compare "$tmp/ones.exr" "$tmp/lit.exr" --json > "$tmp/lit.json" || fail "compare: furnace"
"$veil" compare "$tmp/ones.exr" "$tmp/backdrop.exr" --json > "$tmp/backdrop.json" || fail "compare: backdrop"
bias=$(field mean_bias "$tmp/lit.json") se=$(field mean_bias_se "$tmp/lit.json") dark=$(field mean_bias "$tmp/backdrop.json")
[ -n "$bias" ] && [ -n "$se" ] && [ -n "$dark" ] || fail "compare's JSON: $(cat "$tmp/lit.json" "$tmp/backdrop.json")"
awk -v b="$bias" -v s="$se" 'BEGIN { exit !(s > 0 && (b < 0 ? -b : b) <= 4 * s) }' ||
  fail "white furnace: mean bias $bias against a sky of 1, standard error $se"
awk -v d="$dark" -v s="$se" 'BEGIN { exit !(d > 4 * s) }' || fail "as a backdrop the sky lit the medium: bias $dark (se $se)"
echo "PASS"
