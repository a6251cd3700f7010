#!/usr/bin/env bash
# veil render --explain: the plan of a run without rendering, and the stage
# reports of --stats agreeing with it.
#   cli_explain.sh VEIL SCENE_DIR
set -uo pipefail
veil=$1 scenes=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
passed=0
ok() { passed=$((passed + 1)); }

# a 5-frame turntable of the demo: inject and propagate on frame 0 only
"$veil" render "$scenes/demo.json" --explain --turntable 5 > "$tmp/plan.txt" 2>&1 || fail "explain: $(cat "$tmp/plan.txt")"
grep -q '^inject     frame 0: runs, key [0-9a-f]\{16\}: 700 particles' "$tmp/plan.txt" || fail "no inject plan: $(cat "$tmp/plan.txt")"
grep -q '^           frames 1-4: cached' "$tmp/plan.txt" || fail "frames 1-4 not cached: $(cat "$tmp/plan.txt")"
grep -q '^propagate  frame 0: runs, 3 lights' "$tmp/plan.txt" || fail "no propagate plan"
grep -q '^render     every frame: runs' "$tmp/plan.txt" || fail "no render plan"
[ -z "$(ls "$tmp" | grep -v plan.txt)" ] || fail "explain wrote files: $(ls "$tmp")"
ok

# an environment light: by default its bright part is the median cut's and the light cache's photons carry
# the rest; a constant sky has no bright part, so it adds no light to propagate
sed 's/"lights": \[/"lights": [{"type": "environment", "color": [0.2, 0.3, 0.5]},/' "$scenes/demo.json" > "$tmp/rest.json"
"$veil" render "$tmp/rest.json" --explain > "$tmp/env.txt" 2>&1 || fail "explain, rest: $(cat "$tmp/env.txt")"
grep -q "^light 0    environment (a constant sky): its bright part (above 8 times its mean luminance: 0 % of its light) as 0 directional lights of its median cut into at most 8 (the quality's); the rest, 100 %, by the light cache's photons" "$tmp/env.txt" ||
  fail "the split not explained: $(cat "$tmp/env.txt")"
grep -q "^propagate  frame 0: runs, 3 lights" "$tmp/env.txt" || fail "the constant sky's rest propagated: $(cat "$tmp/env.txt")"
grep -q "^volumetric frame 0: runs, .* from 4 sources (the environment's rest one of them)" "$tmp/env.txt" ||
  fail "the cache does not carry the rest: $(cat "$tmp/env.txt")"
ok

# "remainder": "lights": the whole map as its median cut into the quality rung's count (draft 4, default
# 8, high 16), or into its own "lights", at most the room the scene's other lights leave
sed 's/"lights": \[/"lights": [{"type": "environment", "color": [0.2, 0.3, 0.5], "remainder": "lights"},/' "$scenes/demo.json" > "$tmp/sky.json"
for q in draft:4:3 default:8:3 high:13:3; do
  IFS=: read -r rung k others <<< "$q"
  "$veil" render "$tmp/sky.json" --explain --quality "$rung" > "$tmp/env.txt" 2>&1 || fail "explain, sky: $(cat "$tmp/env.txt")"
  grep -q "^light 0    environment (a constant sky): $k directional lights of its median cut into $k" "$tmp/env.txt" ||
    fail "quality $rung: not $k lights: $(cat "$tmp/env.txt")"
  grep -q "^propagate  frame 0: runs, $((k + others)) lights" "$tmp/env.txt" || fail "quality $rung: $((k + others)) lights not propagated"
  [ "$(grep -c '^           cut ' "$tmp/env.txt")" = "$k" ] || fail "quality $rung: the cut's $k lights not listed"
done
grep -q "into 13, the room the other lights leave (the quality's)" "$tmp/env.txt" || fail "room not said: $(cat "$tmp/env.txt")"
sed 's/"remainder": "lights"}/"remainder": "lights", "lights": 2}/' "$tmp/sky.json" > "$tmp/sky2.json"
"$veil" render "$tmp/sky2.json" --explain --quality high > "$tmp/env.txt" 2>&1 || fail "explain, sky 2: $(cat "$tmp/env.txt")"
grep -q "median cut into 2 (its \"lights\")" "$tmp/env.txt" || fail "the scene's lights 2 not kept: $(cat "$tmp/env.txt")"
ok

# needs no GPU: a broken driver does not matter to it
GALLIUM_DRIVER=nope VEIL_DEVICE=software "$veil" render "$scenes/demo.json" --explain > /dev/null 2>&1 \
  || fail "explain needed a GL context"
ok

# what it plans is what the renderer then does and reports
"$veil" render "$scenes/demo.json" -o "$tmp/a.exr" --width 32 --height 24 --turntable 2 --stats > "$tmp/stats.txt"
rc=$?
if [ $rc = 3 ] && [ "${CI:-}" != true ]; then echo "skipped: no GL 4.5 context"; exit 77; fi
[ $rc = 0 ] || fail "render failed (exit $rc)"
grep -c '^inject .*(ran: ' "$tmp/stats.txt" | grep -qx 1 || fail "inject did not run exactly once: $(cat "$tmp/stats.txt")"
grep -c '^inject .*(cached: ' "$tmp/stats.txt" | grep -qx 1 || fail "frame 1 re-injected: $(cat "$tmp/stats.txt")"
grep -c '^propagate .*(cached: ' "$tmp/stats.txt" | grep -qx 1 || fail "frame 1 re-propagated"
grep -c '^render .*(ran: ' "$tmp/stats.txt" | grep -qx 2 || fail "render did not run on both frames"
# the multiple-scattering field is view-independent: made once, kept for frame 1
grep -c '^volumetric .*(ran: ' "$tmp/stats.txt" | grep -qx 1 || fail "the volumetric field did not run once: $(cat "$tmp/stats.txt")"
grep -c '^volumetric .*(cached: ' "$tmp/stats.txt" | grep -qx 1 || fail "frame 1 rebuilt the volumetric field"
grep -q 'the light cache, [0-9]* photons from 3 sources' "$tmp/plan.txt" \
    || fail "the plan does not name the light cache: $(cat "$tmp/plan.txt")"
grep -q 'orders >= 2 from the light cache' "$tmp/plan.txt" || fail "the march's plan does not say it reads the cache"
grep -c '^spread .*(skipped: nothing to spread' "$tmp/stats.txt" | grep -qx 2 || fail "the spread was not skipped (and said why)"
ok

# fog only: inject and propagate skipped, and said why
cat > "$tmp/fog.json" <<'JSON'
{"camera": {"position": [0, 1, -5], "look_at": [0, 1, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [0.1, 0.1, 0.1],
            "sources": [{"type": "exponential", "density": 1, "falloff": 0.5, "direction": [0, 1, 0], "origin": [0, 0, 0]}]},
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]}]}
JSON
"$veil" render "$tmp/fog.json" --explain > "$tmp/fog.txt" || fail "fog explain"
grep -q '^inject     skipped on every frame: no voxelised source (analytic fog' "$tmp/fog.txt" || fail "fog inject: $(cat "$tmp/fog.txt")"
grep -q '^propagate  skipped on every frame: no volume' "$tmp/fog.txt" || fail "fog propagate: $(cat "$tmp/fog.txt")"
ok

# a missing VDB: exit 1 naming the scene and the source, as render would
cat > "$tmp/vdb.json" <<'JSON'
{"camera": {"position": [0, 0, -5], "look_at": [0, 0, 0]},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "vdb", "file": "missing.vdb"}]},
 "lights": []}
JSON
"$veil" render "$tmp/vdb.json" --explain > "$tmp/out.txt" 2> "$tmp/err.txt"; rc=$?
[ $rc = 1 ] || fail "missing VDB: exit $rc"
grep -q 'vdb.json' "$tmp/err.txt" && grep -q 'medium.sources\[0\]' "$tmp/err.txt" && grep -q 'missing.vdb' "$tmp/err.txt" \
  || fail "missing VDB message: $(cat "$tmp/err.txt")"
ok

echo "$passed passed, 0 failed"
