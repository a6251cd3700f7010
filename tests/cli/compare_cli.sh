#!/usr/bin/env bash
# `veil compare` end to end: the numbers it prints for images with known
# differences (tests/support/make_compare_exrs.c writes them; the expected values
# are worked out here from that file's formulas), --json, --heatmap, and
# bad input (exit 1, the file named, no heatmap left) and usage (exit 2).
#   compare_cli.sh VEIL MAKE_COMPARE_EXRS
set -u
veil=$1
make_exrs=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
d=$tmp/img # the images (and heatmaps); $tmp holds the captured output
mkdir "$d"
"$make_exrs" "$d" || fail "make_compare_exrs failed"

# run ARGS...: veil compare ARGS, stdout in $tmp/out, stderr in $tmp/err, exit code in $rc
run() { "$veil" compare "$@" > "$tmp/out" 2> "$tmp/err"; rc=$?; }
# field KEY: the value after KEY in the text output
field() { awk -v k="$1" '$1 == k { print $2 }' "$tmp/out"; }
expect_field() {
  local got
  got=$(field "$1")
  [ "$got" = "$2" ] || fail "$3: $1 is '$got', expected '$2' in: $(cat "$tmp/out")"
}
# json_check PYTHON_EXPR: the JSON on stdout parses and the expression
# (over j, the object, and the ramp's moments) holds
json_check() {
  python3 - "$tmp/out" "$1" <<'PY' || fail "JSON check '$2' failed: $(cat "$tmp/out")"
import json, math, struct, sys
j = json.load(open(sys.argv[1]))
f32 = lambda v: struct.unpack('f', struct.pack('f', v))[0]
# ref.exr as make_compare_exrs.c writes it (float32 arithmetic)
ref = [[f32(f32(0.5) + f32(f32(0.01) * x)), f32(f32(0.25) + f32(f32(0.02) * y)),
        f32(f32(0.1) + f32(f32(0.01) * (x + y)))] for y in range(6) for x in range(8)]
vals = [v for p in ref for v in p]
mean = sum(vals) / len(vals)
mean_sq = sum(v * v for v in vals) / len(vals)
peak = max(vals)
close = lambda a, b, tol=1e-6: a is not None and abs(a - b) <= tol * max(1.0, abs(b))
ok = eval(sys.argv[2])
if not ok:
    sys.exit(1)
PY
}
# no_heatmap PATH NAME: neither PATH nor any temporary file exists
no_heatmap() {
  [ ! -e "$1" ] || fail "$2: a heatmap was left behind"
  ls "$d" | grep -q '\.tmp' && fail "$2: a temporary file was left: $(ls "$d")"
  return 0
}

# identical images
run "$d/same.exr" "$d/ref.exr"
[ $rc -eq 0 ] || fail "same: exit $rc: $(cat "$tmp/err")"
expect_field rel_rmse 0 same; expect_field rmse 0 same; expect_field max_abs 0 same
expect_field off_5pct 0 same; expect_field psnr_db inf same; expect_field alpha_max_abs 0 same
grep -q '^rel_rmse .*(floor .*, default)' "$tmp/out" || fail "same: the floor is not stated: $(cat "$tmp/out")"
run "$d/same.exr" "$d/ref.exr" --json
[ $rc -eq 0 ] || fail "same --json: exit $rc"
json_check "j['psnr_db'] is None and j['rel_rmse'] == 0 and j['max_abs'] == 0 and j['heatmap'] is None \
            and j['width'] == 8 and j['height'] == 6 and close(j['floor'], 0.01 * mean)" "same --json"
grep -qi nan "$tmp/out" && fail "NaN printed"

# every RGB value times 1.1: every relative error 0.1, every pixel more than 5 % off
run "$d/scaled.exr" "$d/ref.exr"
expect_field rel_rmse 0.1 scaled; expect_field off_5pct 1 scaled; expect_field max_abs 0.057 scaled
run "$d/scaled.exr" "$d/ref.exr" --json
json_check "close(j['rel_rmse'], 0.1) and j['off_5pct'] == 1 and close(j['max_abs'], 0.1 * peak) \
            and close(j['rmse'], 0.1 * math.sqrt(mean_sq)) \
            and close(j['psnr_db'], 10 * math.log10(peak**2 / (0.01 * mean_sq)), 1e-5) \
            and j['alpha_max_abs'] == 0" "scaled --json"
# an all-black reference (issue 22, item 11): the mean bias is undefined and said so (JSON null),
# never 3.4e38; a floor below 1e-12 is refused by name instead of raised without a word
run "$d/scaled.exr" "$d/black.exr" --json
[ $rc -eq 0 ] || fail "black reference: exit $rc: $(cat "$tmp/err")"
json_check "j['mean_bias'] is None" "black reference --json"
run "$d/scaled.exr" "$d/black.exr"
grep -q '^mean_bias .*undefined' "$tmp/out" || fail "black reference: $(cat "$tmp/out")"
run "$d/black.exr" "$d/black.exr" --json
json_check "j['mean_bias'] == 0" "black against black: no bias"
run "$d/scaled.exr" "$d/ref.exr" --floor 1e-45
[ $rc -eq 2 ] && grep -q -- "--floor: expected a number >= 1e-12" "$tmp/err" || fail "--floor 1e-45: exit $rc: $(cat "$tmp/err")"
# a floor of 2 is above every value: the relative error is 0.1 b / 2
run "$d/scaled.exr" "$d/ref.exr" --floor 2 --json
[ $rc -eq 0 ] || fail "--floor 2: exit $rc: $(cat "$tmp/err")"
json_check "j['floor'] == 2 and close(j['rel_rmse'], 0.05 * math.sqrt(mean_sq)) and j['off_5pct'] == 0" "--floor 2"
run "$d/scaled.exr" "$d/ref.exr" --floor 2
grep -q '^rel_rmse .*(floor 2)$' "$tmp/out" || fail "--floor 2 not stated: $(cat "$tmp/out")"

# mean bias: scaled by 1.1 is +10 % energy; identical images 0
run "$d/scaled.exr" "$d/ref.exr" --json
json_check "close(j['mean_bias'], 0.1, 1e-5) and j['noise'] is None and j['rel_rmse_excess'] is None \
            and j['mean_bias_se'] is None and j['bin'] == 1" "mean_bias"
# the reference's standard error is 2 % of each value (all above the floor): noise 0.02, and
# the excess is sqrt(0.1^2 - 0.02^2) = 0.09798
run "$d/scaled.exr" "$d/ref_se.exr" --json
json_check "close(j['noise'], 0.02, 1e-5) and close(j['rel_rmse_excess'], math.sqrt(0.01 - 0.0004), 1e-5)" "noise"
# the bias's standard error: 1.1 x 0.02 sqrt(sum s^2) / sum s over the pixels' RGB sums s (a pixel's
# channels' errors added, as wholly correlated)
json_check "close(j['mean_bias_se'], 1.1 * 0.02 * math.sqrt(sum(sum(p[:3])**2 for p in ref)) / sum(sum(p[:3]) for p in ref), 1e-5)" \
  "mean_bias_se"
# every error a bound: no noise is taken out
run "$d/scaled.exr" "$d/ref_bound.exr" --json
json_check "j['noise'] == 0 and close(j['rel_rmse_excess'], 0.1, 1e-5) and j['mean_bias_se'] == 0" "stderr.bound"
# standard errors that are not ones (issue 22): refused, naming the channel and the pixel
run "$d/scaled.exr" "$d/ref_se_nan.exr" --json
[ $rc -eq 1 ] && grep -q "channel stderr.G at pixel (3, 2) is not a number" "$tmp/err" \
  || fail "a NaN standard error: exit $rc: $(cat "$tmp/err")"
run "$d/scaled.exr" "$d/ref_se_neg.exr"
[ $rc -eq 1 ] && grep -q "channel stderr.B at pixel (0, 1) is -0.01" "$tmp/err" \
  || fail "a negative standard error: exit $rc: $(cat "$tmp/err")"
run "$d/scaled.exr" "$d/ref_se_part.exr"
[ $rc -eq 1 ] && grep -q "has stderr.R but not all of" "$tmp/err" \
  || fail "stderr.R alone: exit $rc: $(cat "$tmp/err")"
# a file name that is not UTF-8 stays JSON (U+FFFD)
cp "$d/scaled.exr" "$tmp/$(printf 'sc\xffaled.exr')"
run "$tmp/$(printf 'sc\xffaled.exr')" "$d/ref.exr" --json
[ $rc -eq 0 ] && /usr/bin/python3 -c 'import json,sys; j=json.loads(open(sys.argv[1],"rb").read().decode("utf-8")); assert j["image"].endswith("sc\ufffdaled.exr")' "$tmp/out" \
  || fail "a file name that is not UTF-8 in --json: exit $rc: $(cat "$tmp/out" "$tmp/err" | head -c 400)"
# --bin 2: 4x3 blocks of means; scaled stays 0.1 off, with the same bias; a block mean's
# standard error is sqrt(sum se^2) / 4 = 0.02 sqrt(sum r^2) / 4, relative to its mean sum r / 4:
# 0.02 sqrt(sum r^2) / sum r, which is 0.01 for equal r and at most 0.01 (1 + (dr/r)^2 / 8) for
# the ramp's neighbours (dr / r <= 0.16 here): within [0.01, 0.0101]
run "$d/scaled.exr" "$d/ref_se.exr" --bin 2 --json
json_check "j['bin'] == 2 and close(j['rel_rmse'], 0.1, 1e-5) and close(j['mean_bias'], 0.1, 1e-5) \
            and 0.00999 <= j['noise'] <= 0.0101" "--bin 2"
run "$d/scaled.exr" "$d/ref.exr" --bin 0
[ $rc -eq 2 ] || fail "--bin 0: exit $rc, expected 2"
run "$d/scaled.exr" "$d/ref.exr" --bin 9
[ $rc -eq 1 ] && grep -q "bin size 9" "$tmp/err" || fail "--bin 9 (over the 6-pixel side): exit $rc: $(cat "$tmp/err")"
run "$d/scaled.exr" "$d/ref.exr" --bin 2 --heatmap "$d/h.png"
[ $rc -eq 1 ] || fail "--bin with --heatmap: exit $rc, expected 1"
no_heatmap "$d/h.png" "--bin with --heatmap"

# R of pixel (3, 2) raised by 0.25: one pixel of 48 off
run "$d/one_off.exr" "$d/ref.exr"
expect_field max_abs 0.25 one_off; expect_field off_5pct 0.0208333 one_off
run "$d/one_off.exr" "$d/ref.exr" --json
json_check "close(j['max_abs'], 0.25) and j['off_5pct'] == 1 / 48 \
            and close(j['rel_rmse'], math.sqrt((0.25 / ref[2 * 8 + 3][0])**2 / 144)) \
            and close(j['rmse'], math.sqrt(0.25**2 / 144))" "one_off --json"

# alpha alone differs
run "$d/alpha.exr" "$d/ref.exr"
expect_field alpha_max_abs 0.25 alpha; expect_field psnr_db inf alpha; expect_field rel_rmse 0 alpha

# --heatmap: an 8x6 RGB PNG, black where nothing differs, bright at (3, 2)
run "$d/one_off.exr" "$d/ref.exr" --heatmap "$d/heat.png"
[ $rc -eq 0 ] || fail "--heatmap: exit $rc: $(cat "$tmp/err")"
grep -q "^heatmap $d/heat.png: relative error, log scale 1e-4 (black) .. 1 (white)" "$tmp/out" \
  || fail "--heatmap: no scale stated: $(cat "$tmp/out")"
python3 - "$d/heat.png" <<'PY' || fail "--heatmap: the PNG is not what was expected"
import struct, sys, zlib
data = open(sys.argv[1], 'rb').read()
assert data[:8] == b'\x89PNG\r\n\x1a\n', 'signature'
pos, chunks = 8, {}
while pos < len(data):
    n, kind = struct.unpack('>I4s', data[pos:pos + 8])
    chunks.setdefault(kind, b'')
    chunks[kind] += data[pos + 8:pos + 8 + n]
    pos += 12 + n
w, h, depth, colour = struct.unpack('>IIBB', chunks[b'IHDR'][:10])
assert (w, h, depth, colour) == (8, 6, 8, 2), (w, h, depth, colour)
raw, rows, prev, i = zlib.decompress(chunks[b'IDAT']), [], bytearray(w * 3), 0
for y in range(h):
    kind, line = raw[i], bytearray(raw[i + 1:i + 1 + w * 3])
    i += 1 + w * 3
    for x in range(len(line)):
        a = line[x - 3] if x >= 3 else 0
        b, c = prev[x], prev[x - 3] if x >= 3 else 0
        p = a + b - c
        paeth = (a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c)
                 else b if abs(p - b) <= abs(p - c) else c)
        pred = [0, a, b, (a + b) // 2, paeth][kind]
        line[x] = (line[x] + pred) & 255
    rows.append(line)
    prev = line
for y in range(h):
    for x in range(w):
        px = tuple(rows[y][x * 3:x * 3 + 3])
        if (x, y) == (3, 2):
            # relative error 0.25 / 0.53: between yellow (1e-1) and white (1)
            assert px[0] == 255 and px[1] == 255 and 0 < px[2] < 255, px
        else:
            assert px == (0, 0, 0), (x, y, px)
PY
run "$d/one_off.exr" "$d/ref.exr" --heatmap "$d/heat2.png" --json
json_check "j['heatmap'] == '$d/heat2.png'" "--heatmap --json"
[ -s "$d/heat2.png" ] || fail "--heatmap --json wrote no PNG"
rm -f "$d/heat.png" "$d/heat2.png"
no_heatmap "$d/heat.png" "after --heatmap"

# bad input: exit 1, the file named, no heatmap
head -c 200 "$d/ref.exr" > "$d/truncated.exr"
echo "not an image" > "$d/garbage.exr"
bad() { # bad NAME EXPECTED_TEXT ARGS...
  local name=$1 text=$2
  shift 2
  run "$@" --heatmap "$d/bad.png"
  [ $rc -eq 1 ] || fail "$name: exit $rc, expected 1: $(cat "$tmp/err")"
  grep -qF -- "$text" "$tmp/err" || fail "$name: '$text' not in: $(cat "$tmp/err")"
  [ -s "$tmp/out" ] && fail "$name: printed results: $(cat "$tmp/out")"
  no_heatmap "$d/bad.png" "$name"
}
bad missing_image "$d/nope.exr: cannot open" "$d/nope.exr" "$d/ref.exr"
bad missing_reference "$d/nope.exr: cannot open" "$d/same.exr" "$d/nope.exr"
bad truncated "$d/truncated.exr" "$d/truncated.exr" "$d/ref.exr"
bad garbage "$d/garbage.exr" "$d/same.exr" "$d/garbage.exr"
bad size "$d/small.exr is 4x3 but the reference $d/ref.exr is 8x6" "$d/small.exr" "$d/ref.exr"
bad nan_image "image has a non-finite value (not a number) at pixel (5, 4) channel B" "$d/nan.exr" "$d/ref.exr"
bad nan_reference "reference has a non-finite value (not a number) at pixel (5, 4) channel B" "$d/ref.exr" "$d/nan.exr"
grep -qF "$d/ref.exr (image) against $d/nan.exr (reference)" "$tmp/err" \
  || fail "nan: files not named: $(cat "$tmp/err")"
run "$d/one_off.exr" "$d/ref.exr" --heatmap "$d/no/such/dir/h.png"
[ $rc -eq 1 ] || fail "heatmap in a missing folder: exit $rc"
grep -qF "$d/no/such/dir/h.png" "$tmp/err" || fail "heatmap folder: not named: $(cat "$tmp/err")"
# a failed run leaves an existing heatmap as it was
echo keep > "$d/old.png"
run "$d/small.exr" "$d/ref.exr" --heatmap "$d/old.png"
[ $rc -eq 1 ] && [ "$(cat "$d/old.png")" = keep ] || fail "a failed run replaced an existing heatmap"
rm -f "$d/old.png"

# usage: exit 2, a message, no heatmap
usage() { # usage NAME EXPECTED_TEXT ARGS...
  local name=$1 text=$2
  shift 2
  run "$@"
  [ $rc -eq 2 ] || fail "usage $name: exit $rc, expected 2: $(cat "$tmp/err")"
  grep -qF -- "$text" "$tmp/err" || fail "usage $name: '$text' not in: $(cat "$tmp/err")"
  no_heatmap "$d/u.png" "usage $name"
}
usage none "compare: missing A.exr and REF.exr"
usage one "compare: missing REF.exr" "$d/same.exr" --heatmap "$d/u.png"
usage three "unexpected argument '$d/one_off.exr'" "$d/same.exr" "$d/ref.exr" "$d/one_off.exr"
usage unknown "unknown option '--bogus'" "$d/same.exr" "$d/ref.exr" --bogus --heatmap "$d/u.png"
for f in 0 -1 nan inf abc 1e999 "" 2x; do
  usage "floor '$f'" "--floor: expected a positive finite number" \
        "$d/same.exr" "$d/ref.exr" --heatmap "$d/u.png" --floor "$f"
done
usage floor_missing "--floor needs a value" "$d/same.exr" "$d/ref.exr" --floor
usage heatmap_missing "--heatmap needs a value" "$d/same.exr" "$d/ref.exr" --heatmap

left=$(ls "$d" | sort | tr '\n' ' ')
[ "$left" = "alpha.exr black.exr garbage.exr nan.exr one_off.exr ref.exr ref_bound.exr ref_se.exr ref_se_nan.exr ref_se_neg.exr ref_se_part.exr same.exr scaled.exr small.exr truncated.exr " ] \
  || fail "files left behind: $(ls "$d")"
echo PASS
