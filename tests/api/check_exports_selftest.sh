#!/usr/bin/env bash
# tests/api/check_exports.sh must catch what it guards against. Against the
# built libveil.so and copies of the public headers made here, it fails
#   - with one VEIL_API declaration removed from veil.h (the library then
#     exports a name the header does not declare);
#   - with one declaration's VEIL_API removed (declared but unmarked);
# and against the library's own symbol list with, added, an internal
# function, an internal datum, a weak C++ template instance or a versioned
# stray, or with a declared function taken out; the real library and
# headers pass.
#   check_exports_selftest.sh CC NM LIBRARY INCLUDE_DIR
set -uo pipefail
[ $# -eq 4 ] || { echo "usage: check_exports_selftest.sh CC NM LIBRARY INCLUDE_DIR"; exit 2; }
cc=$1 nm=$2 lib=$3 inc=$4
check=$(dirname "$0")/check_exports.sh
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
fresh() { rm -rf "$tmp/inc"; mkdir -p "$tmp/inc/veil"; cp "$inc/veil.h" "$tmp/inc/"; cp "$inc/veil/result.h" "$tmp/inc/veil/"; }
headers() { echo "$tmp/inc/veil.h" "$tmp/inc/veil/result.h"; }
passed=0
expect() { # expect pass|fail what ARGS...
  local want=$1 what=$2
  shift 2
  out=$(bash "$check" "$cc" "$@" 2>&1); rc=$?
  if [ "$want" = pass ]; then [ $rc = 0 ] || fail "$what: rejected: $out"
  else [ $rc = 1 ] || fail "$what: not caught (exit $rc): $out"; fi
  passed=$((passed + 1))
  echo "ok: $what ($want)"
}
"$nm" -D --defined-only "$lib" > "$tmp/real.syms" || fail "$nm -D --defined-only $lib"
grep -q ' T veil_image_rgba$' "$tmp/real.syms" || fail "the library does not export veil_image_rgba: the cases below assume it"

# shellcheck disable=SC2046 # the header list splits on purpose
fresh; expect pass "the real library and headers" "$nm" "$lib" $(headers)
fresh; grep -q '^VEIL_API const float\* veil_image_rgba(' "$tmp/inc/veil.h" || fail "veil.h's veil_image_rgba line moved"
sed -i '/^VEIL_API const float\* veil_image_rgba(/d' "$tmp/inc/veil.h"
expect fail "veil.h without veil_image_rgba's declaration" "$nm" "$lib" $(headers)
fresh; sed -i 's/^VEIL_API \(const float\* veil_image_rgba(\)/\1/' "$tmp/inc/veil.h"
expect fail "veil_image_rgba declared without VEIL_API" "$nm" "$lib" $(headers)
fresh; sed -i 's/^VEIL_API \(const char\* veil_result_name(\)/\1/' "$tmp/inc/veil/result.h"
expect fail "veil/result.h's veil_result_name without VEIL_API" "$nm" "$lib" $(headers)

stray() { # stray NAME LINE: the real list plus LINE
  { cat "$tmp/real.syms"; echo "$2"; } > "$tmp/$1.syms"
  expect fail "$1 exported" --symbols "$tmp/$1.syms" $(headers)
}
fresh
stray "an internal function" "0000000000001000 T veil__renderer_create"
stray "an internal datum" "0000000000002000 D VEIL__R_ANY"
stray "a read-only table" "0000000000002000 R veil_image_set_channel_names"
stray "a weak C++ template instance" "0000000000003000 W _ZN7openvdb5v10_04tree8TreeBase12readTopologyERSib"
stray "a versioned stray" "0000000000003000 T helper@@VEIL_0.2"
grep -v ' veil_version_numbers$' "$tmp/real.syms" > "$tmp/missing.syms"
expect fail "a declared function the library lacks" --symbols "$tmp/missing.syms" $(headers)
: > "$tmp/empty.syms"
expect fail "an empty symbol list" --symbols "$tmp/empty.syms" $(headers)
echo "$passed passed, 0 failed"
