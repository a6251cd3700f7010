#!/usr/bin/env bash
# An environment map over the texel limit (issue 41, item 7): a 16384 x 8192
# half map (3 MB on disk, 1.6 GB as float RGB) is refused from its header
# before any texel is decoded: exit 1 naming the light's field, the file, its
# size and the limit, under 200 MB resident (not under ASan, whose shadow
# memory adds ~110 MB), nothing written, in every command that reads a scene
# (render, --explain, reference). Before: 2.1 GB and 20-30 s, then the same
# refusal. No GPU: the scene is refused before one is asked for.
#
#   env_map_cli.sh VEIL MAKE_ENV_MAP
set -u
veil=$1
make_env_map=$2
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
cd "$work" || exit 1
fails=0
fail() { echo "FAIL $*"; fails=$((fails + 1)); }
asan=0
ldd "$veil" 2>/dev/null | grep -q libasan && asan=1
"$make_env_map" big.exr 16384 8192 || { echo "FAIL: make_env_map"; exit 1; }
cat >scene.json <<'JSON'
{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 16, "height": 12},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "exponential", "density": 0.3, "falloff": 1,
   "direction": [0, 1, 0], "origin": [0, 0, 0], "bounds": [[-1, -1, -1], [1, 1, 1]]}]},
 "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": [1, 1, 1]},
            {"type": "environment", "file": "big.exr"}]}
JSON
want="scene.json: lights[1].file: cannot read the environment map: big.exr: OpenEXR image 16384x8192 has 134217728 pixels, more than the 33554432 read here (an environment map has at most 2^25 texels: 8192 x 4096)"
for cmd in "render scene.json -o out.exr" "render scene.json -o out.exr --explain" "reference scene.json -o out.exr --spp 2"; do
    # shellcheck disable=SC2086
    /usr/bin/time -f "%M" -o mem.txt timeout 60 "$veil" $cmd >out.txt 2>&1
    rc=$?
    kb=$(tail -1 mem.txt)
    [ "$rc" -eq 1 ] && grep -qF -- "$want" out.txt || fail "$cmd: exit $rc: $(head -c 600 out.txt)"
    [ "$asan" = 1 ] || [ "${kb:-999999}" -lt 204800 ] || fail "$cmd: $kb KB resident"
    [ ! -e out.exr ] || fail "$cmd: wrote out.exr"
    echo "$cmd: exit $rc, $kb KB"
done
[ $fails -eq 0 ] && echo "PASS: the map refused from its header"
[ $fails -eq 0 ]
