#!/usr/bin/env bash
# check-one-rng.sh SOURCE_DIR
#
# SplitMix64 is written once, in core/rng.h (veil_splitmix64 and friends);
# every other file of the library, the CLI, the tests, the benches and the
# examples uses it from there. A second copy would be free to drift (a
# different shift, float instead of double) while looking the same, so its
# constants may appear in core/rng.h only: the counter's increment
# 0x9E3779B97F4A7C15 and the finaliser's first multiplier 0xBF58476D1CE4E5B9
# (case-insensitive, with or without a ull suffix; a shader or script
# counts too). tests/volume/test_rbf.c pins the first output for seed 0 as a
# number, so it needs neither constant.
set -u
src=${1:?usage: check-one-rng.sh SOURCE_DIR}
cd "$src" || exit 1
home=core/rng.h
dirs=()
for d in core gpu scene io volume propagate render frame reference include cli tests bench examples; do
    [ -d "$d" ] && dirs+=("$d")
done

fails=0
for c in 9E3779B97F4A7C15 BF58476D1CE4E5B9; do
    # -I: skip binary files; -i: any case; the hex digits must not continue
    # (a longer number is a different constant)
    files=$(grep -rIliE "0x${c}([^0-9a-f]|$)" "${dirs[@]}" | sort)
    if [ "$files" != "$home" ]; then
        echo "FAIL: 0x$c must appear in $home only; it appears in:"
        printf '%s\n' "${files:-(nowhere)}" | sed 's/^/    /'
        fails=$((fails + 1))
    fi
done
[ $fails -eq 0 ] && echo "PASS: SplitMix64's constants appear in $home only (searched ${dirs[*]})"
[ $fails -eq 0 ]
