#!/usr/bin/env bash
# check-headers.sh SOURCE_DIR BUILD_DIR [CC]
#
# Every library header compiles on its own, in every branch of its compiler
# tests, without a redundant declaration:
#
#   - each *.h under core gpu scene io volume propagate render frame
#     reference include (not tests/, bench/, cli/) is the only #include of a
#     temporary .c, compiled with -fsyntax-only -std=c11 -Wredundant-decls
#     -Werror and the include paths the library uses (SOURCE_DIR, BUILD_DIR
#     and the pkg-config cflags of epoxy, cglm, libcjson and OpenEXR): a
#     header that leans on an include its user happened to make first fails;
#   - then again on a copy of veil's own headers in which every
#     `defined(__GNUC__)` reads `0`, so the branch other compilers take is
#     compiled too (system headers are untouched: undefining __GNUC__ for
#     them would break glibc). Every header is compiled against the copy,
#     not only those that test __GNUC__, since a header sees the branches
#     of those it includes. A declaration written twice in that branch
#     fails here: io/json_read.h up to commit c37557d declared
#     veil__read_file inside `#else` and again below it for all compilers.
#
# Exit 0 when all pass, 1 listing the headers that fail with the compiler's
# message.
set -u
src=${1:?usage: check-headers.sh SOURCE_DIR BUILD_DIR [CC]}
build=${2:?usage: check-headers.sh SOURCE_DIR BUILD_DIR [CC]}
cc=${3:-cc}
src=$(cd "$src" && pwd) || exit 1
build=$(cd "$build" && pwd) || exit 1

dirs=(core gpu scene io volume propagate render frame reference include)
pc=$(pkg-config --cflags epoxy cglm libcjson OpenEXR) || { echo "FAIL: pkg-config"; exit 1; }

work=$(mktemp -d) || exit 1
trap 'rm -rf -- "$work"' EXIT

# The headers, relative to src; a folder that does not exist yet is skipped.
headers=()
for d in "${dirs[@]}"; do
    [ -d "$src/$d" ] || continue
    while IFS= read -r -d '' h; do headers+=("${h#"$src"/}"); done \
        < <(find "$src/$d" -name '*.h' -type f -print0 | sort -z)
done
[ ${#headers[@]} -gt 0 ] || { echo "FAIL: no headers found under $src"; exit 1; }

# The non-GNU copy: the same tree of headers with `defined(__GNUC__)` -> `0`,
# so relative includes ("../core/result.h") resolve inside the copy.
alt=$work/non_gnu
changed=0
for h in "${headers[@]}"; do
    mkdir -p "$alt/$(dirname "$h")"
    sed 's/defined[[:space:]]*([[:space:]]*__GNUC__[[:space:]]*)/0/g; s/defined[[:space:]]\+__GNUC__/0/g' \
        "$src/$h" > "$alt/$h"
    cmp -s "$src/$h" "$alt/$h" || changed=$((changed + 1))
done

fails=0
checked=0
# Fragments: headers that, by design, are parameterised by their includer
# (documented at their top) and so cannot stand alone; each is compiled
# after the definitions its includer provides (here: as GLSL-like empty
# context parameters), which still checks its syntax and declarations.
declare -A prelude=(
    [propagate/opv_schemes.glsl.h]='#include "core/shared.glsl.h"
#define VEIL_CTX_PARAM
#define VEIL_CTX_ARG
#define VEIL_DIMS(a) ((a) + 2)
#define VEIL_RHO(i, j, k) 0.0f
#define VEIL_DIN(i, j, k) 0.0f'
)

# compile ROOT HEADER LABEL
compile() {
    local root=$1 h=$2 label=$3
    local tu=$work/tu.c
    { [ -n "${prelude[$h]:-}" ] && printf '%s\n' "${prelude[$h]}"; printf '#include "%s"\n' "$h"; } > "$tu"
    # shellcheck disable=SC2086
    if ! out=$("$cc" -std=c11 -fsyntax-only -Wredundant-decls -Werror -I"$root" -I"$build" $pc "$tu" 2>&1); then
        echo "FAIL ($label): $h"
        echo "$out" | sed 's/^/    /'
        fails=$((fails + 1))
    fi
    checked=$((checked + 1))
}
for h in "${headers[@]}"; do
    compile "$src" "$h" "as written"
    compile "$alt" "$h" "non-GNU branch"
done
# Anti-vacuity: the non-GNU pass must have had something to compile.
[ $changed -gt 0 ] || { echo "FAIL: no header tests __GNUC__; the non-GNU pass checked nothing (is the sed broken?)"; fails=$((fails + 1)); }

echo "${#headers[@]} headers, $changed with a __GNUC__ branch, $checked compilations, $fails failed"
[ $fails -eq 0 ]
