#!/usr/bin/env bash
# `veil info` on good and bad OpenVDB files.
#
#   vdb_bad.sh VEIL EXPECTED_EXIT EXPECTED_TEXT ARGS...
#
# Runs `VEIL ARGS...` and checks that the exit code is exactly EXPECTED_EXIT
# and that stdout + stderr contain EXPECTED_TEXT (a fixed string; runs of
# tabs and spaces in the output count as one space). Prints one PASS or FAIL
# line; exits 0 on PASS, 1 on FAIL.
set -u

if [ $# -lt 3 ]; then
    echo "usage: $0 VEIL EXPECTED_EXIT EXPECTED_TEXT ARGS..." >&2
    exit 2
fi
veil=$1
want_rc=$2
expected=$3
shift 3
logs=$(mktemp -d) || { echo "FAIL: mktemp failed"; exit 1; }
trap 'rm -rf -- "$logs"' EXIT

timeout 120 "$veil" "$@" >"$logs/out" 2>&1
rc=$?
out=$(head -c 20000 "$logs/out" | tr -s ' \t' '  ')
if [ "$rc" -ne "$want_rc" ]; then
    echo "FAIL veil $*: exit code $rc, expected $want_rc; output: $(echo "$out" | head -c 2000)"
    exit 1
fi
if ! grep -qF -- "$expected" <<<"$out"; then
    echo "FAIL veil $*: output lacks '$expected'; output: $(echo "$out" | head -c 2000)"
    exit 1
fi
echo "PASS veil $*: exit $rc, output has '$expected'"
echo "$out" | head -40
exit 0
