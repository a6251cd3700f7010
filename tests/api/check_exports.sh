#!/usr/bin/env bash
# The ABI is the public headers: libveil.so exports exactly the functions
# (and data) include/ declares with VEIL_API.
#
#   check_exports.sh CC NM LIBRARY HEADER...
#   check_exports.sh CC --symbols LIST HEADER...   (LIST in `nm -D --defined-only` form)
#
# Each HEADER is run through the preprocessor (CC -E, which drops comments
# and follows its #includes) with VEIL_API defined as a marker; every
# statement holding the marker declares one exported name (the identifier
# before its first parenthesis, or its last identifier for data). Fails,
# listing them, when
#   - the library exports a defined symbol (any type: text, data, weak,
#     C++ template code) that no header declares;
#   - a declared name is not exported (a VEIL_API the build lost);
#   - a header declares a veil_ function without VEIL_API;
#   - the headers declare nothing or the library exports nothing (a parser
#     or an nm that sees nothing would otherwise pass).
# tests/api/check_exports_selftest.sh shows that each failure is caught.
set -uo pipefail
usage="usage: check_exports.sh CC (NM LIBRARY | --symbols LIST) HEADER..."
[ $# -ge 4 ] || { echo "$usage"; exit 2; }
cc=$1
if [ "$2" = --symbols ]; then
  symbols=$(cat "$3") || { echo "FAIL: cannot read $3"; exit 1; }
  what=$3
else
  symbols=$("$2" -D --defined-only "$3") || { echo "FAIL: $2 -D --defined-only $3"; exit 1; }
  what=$3
fi
shift 3

mark=VEIL_CHECK_EXPORTS_MARK
# One statement a line: declarations end at ';', bodies open at '{'.
statements=$(for h in "$@"; do
  "$cc" -E -P -x c -DVEIL_API=$mark "$h" || echo "FAIL: $cc -E $h" >&2
done | tr '\n' ' ' | tr ';{}' '\n\n\n') || exit 1

# "E name" for a marked declaration, "U name" for a veil_ function declared without the mark.
decls=$(printf '%s\n' "$statements" | awk -v mark="$mark" '
  $0 ~ mark {
    s = $0; sub(".*" mark, "", s)
    if (match(s, /[A-Za-z_][A-Za-z0-9_]*[ \t]*\(/)) {
      name = substr(s, RSTART, RLENGTH); sub(/[ \t]*\($/, "", name)
    } else {
      sub(/[ \t]*(\[[^]]*\])?[ \t]*(=.*)?[ \t]*$/, "", s); n = split(s, w, /[^A-Za-z0-9_]+/); name = w[n]
    }
    print "E " name; next
  }
  /^[ \t]*(typedef|static)[ \t]/ { next }
  match($0, /veil_[A-Za-z0-9_]*[ \t]*\(/) {
    name = substr($0, RSTART, RLENGTH); sub(/[ \t]*\($/, "", name); print "U " name
  }')
declared=$(printf '%s\n' "$decls" | awk '$1 == "E" { print $2 }' | sort -u)
unmarked=$(printf '%s\n' "$decls" | awk '$1 == "U" { print $2 }' | sort -u)
# nm: "ADDRESS TYPE NAME"; a versioned name reads NAME@@VERSION.
exported=$(printf '%s\n' "$symbols" | awk 'NF >= 3 { n = $3; sub(/@.*/, "", n); print n }' | sort -u)

status=0
nd=$(printf '%s\n' "$declared" | grep -c .)
ne=$(printf '%s\n' "$exported" | grep -c .)
if [ "$nd" -eq 0 ]; then echo "FAIL: the headers declare no VEIL_API name: $*"; status=1; fi
if [ "$ne" -eq 0 ]; then echo "FAIL: $what exports no defined symbol"; status=1; fi
extra=$(comm -13 <(printf '%s\n' "$declared") <(printf '%s\n' "$exported") | grep .)
if [ -n "$extra" ]; then
  echo "FAIL: $what exports $(printf '%s\n' "$extra" | wc -l) symbol(s) that the headers do not declare:"
  printf '%s\n' "$symbols" | awk 'NR == FNR { x[$1] = 1; next } NF >= 3 { n = $3; sub(/@.*/, "", n); if (n in x) print "  " $2 " " $3 }' \
    <(printf '%s\n' "$extra") - | head -40
  status=1
fi
missing=$(comm -23 <(printf '%s\n' "$declared") <(printf '%s\n' "$exported") | grep .)
if [ -n "$missing" ]; then
  echo "FAIL: declared with VEIL_API but not exported by $what:"; printf '  %s\n' $missing; status=1
fi
if [ -n "$unmarked" ]; then
  echo "FAIL: declared without VEIL_API (hidden, so not part of the ABI):"; printf '  %s\n' $unmarked; status=1
fi
[ $status -eq 0 ] && echo "ok: $what exports the $nd names the headers declare, and nothing else"
exit $status
