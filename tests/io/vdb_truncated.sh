#!/usr/bin/env bash
# Truncated OpenVDB files fail fast and small (issue 12, defect 2): each
# truncation of a good file (64 bytes, 256 bytes, all but its last byte) is
# refused by `veil info`, `veil info --json` and `veil render` with exit 1
# and "truncated or corrupt OpenVDB file", under a 1 GiB address-space limit
# and a 10 s timeout. (Before: OpenVDB read lengths from the cut stream and
# allocated 7.6 GB for 20 s and more; under the limit, "out of memory".)
#
#   vdb_truncated.sh VEIL GOOD.vdb
set -u
veil=$1
good=$2
work=$(mktemp -d) || { echo "FAIL: mktemp"; exit 1; }
trap 'rm -rf -- "$work"' EXIT
size=$(stat -c %s "$good")
# the address-space limit, unless veil runs under AddressSanitizer (its shadow memory reserves terabytes)
limit="ulimit -v 1048576"
ldd "$veil" 2>/dev/null | grep -q libasan && limit=":"
fails=0
for n in 64 256 $((size - 1)); do
    head -c "$n" "$good" >"$work/cut.vdb"
    printf '{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "width": 8, "height": 6},
 "medium": {"sigma_s": [1, 1, 1], "sources": [{"type": "vdb", "file": "%s"}]}}\n' "$work/cut.vdb" >"$work/scene.json"
    for cmd in "info $work/cut.vdb" "info $work/cut.vdb --json" "render $work/scene.json -o $work/out.exr"; do
        # shellcheck disable=SC2086
        (eval "$limit"; exec timeout 10 "$veil" $cmd) >"$work/log" 2>&1
        rc=$?
        if [ "$rc" -ne 1 ] || ! grep -qF "truncated or corrupt OpenVDB file" "$work/log"; then
            echo "FAIL veil $cmd ($n of $size bytes): exit $rc: $(head -c 400 "$work/log")"
            fails=$((fails + 1))
        else
            echo "PASS veil $cmd ($n of $size bytes): $(head -c 200 "$work/log")"
        fi
        [ -e "$work/out.exr" ] && { echo "FAIL: out.exr written"; fails=$((fails + 1)); }
    done
done
[ $fails -eq 0 ]
