#!/usr/bin/env bash
# Grid names that are not text (issue 22, item 10): `veil info --json` stays
# JSON (bytes that are not UTF-8 become U+FFFD), the table and error messages
# never send a control character to the terminal (each is shown as \xNN).
#
#   info_names.sh VEIL MAKE_TEST_VDBS
set -u
veil=$1
make_vdbs=$2
dir=$(mktemp -d) || exit 1
trap 'rm -rf -- "$dir"' EXIT
fail=0
"$make_vdbs" --odd-names "$dir/odd.vdb" >/dev/null || { echo "FAIL: make_test_vdbs --odd-names"; exit 1; }

# JSON: parsed by Python's json, the names as U+FFFD-replaced UTF-8
"$veil" info --json "$dir/odd.vdb" >"$dir/info.json" 2>"$dir/err" || { echo "FAIL: info --json: $(cat "$dir/err")"; fail=1; }
/usr/bin/python3 - "$dir/info.json" <<'PY' || fail=1
import json, sys
raw = open(sys.argv[1], "rb").read()
try:
    doc = json.loads(raw.decode("utf-8"))  # strict: fails on bytes that are not UTF-8
except Exception as e:
    print("FAIL: info --json is not UTF-8 JSON:", e)
    sys.exit(1)
names = sorted(g["name"] for g in doc["grids"])
want = sorted(["den\x1b[31msity\ufffd", "caf\u00e9 \ufffd\ufffd\ufffd"])
if names != want:
    print("FAIL: names", [ascii(n) for n in names], "expected", [ascii(n) for n in want])
    sys.exit(1)
print("PASS: info --json is JSON; names", [ascii(n) for n in names])
PY

# the table: no control byte, the escape shown as \x1B, valid UTF-8 kept
"$veil" info "$dir/odd.vdb" >"$dir/table" 2>&1 || { echo "FAIL: info exit $?"; fail=1; }
if LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' "$dir/table"; then
    echo "FAIL: the table holds control characters: $(od -c "$dir/table" | head -5)"; fail=1
elif ! grep -qF 'den\x1B[31msity\xFF' "$dir/table" || ! grep -qF 'café \x80\xC0\xAF' "$dir/table"; then
    echo "FAIL: the names are not shown escaped: $(head -8 "$dir/table")"; fail=1
else
    echo "PASS: the table escapes control characters and bytes that are not UTF-8"
fi

# an error message quoting the file's grid names: escaped on stderr
cat >"$dir/scene.json" <<JSON
{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "fov_y_deg": 40, "width": 8, "height": 8},
 "medium": {"sigma_a": [0.1, 0.1, 0.1], "sigma_s": [1, 1, 1],
            "sources": [{"type": "vdb", "file": "$dir/odd.vdb", "grid": "missing"}]}}
JSON
"$veil" render "$dir/scene.json" -o "$dir/out.exr" >"$dir/out" 2>&1
rc=$?
if [ "$rc" -ne 1 ]; then
    echo "FAIL: render with a missing grid: exit $rc: $(head -c 600 "$dir/out")"; fail=1
elif LC_ALL=C grep -q $'[\x01-\x08\x0b-\x1f\x7f]' "$dir/out"; then
    echo "FAIL: the message holds control characters: $(od -c "$dir/out" | head -5)"; fail=1
elif ! grep -qF 'missing' "$dir/out" || ! grep -qF 'den\x1B[31msity' "$dir/out"; then
    echo "FAIL: the message does not name the grids: $(head -c 600 "$dir/out")"; fail=1
else
    echo "PASS: the message names the grids, escaped: $(head -c 300 "$dir/out")"
fi
exit $fail
