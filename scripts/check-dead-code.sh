#!/usr/bin/env bash
# check-dead-code.sh BUILD_DIR SOURCE_DIR [NM] [CC] [LIBRARY]
#
# Every function the library defines has a caller. For each global function
# (nm type T) in LIBRARY (default BUILD_DIR/libveil.a), one of these must
# hold:
#   1. some object file under BUILD_DIR (the library's own, the CLI's, the
#      tests', the benches', the examples') references it (nm type U): the
#      link-level evidence;
#   2. it is declared in a header under include/ (include/veil.h and
#      include/veil/*.h, when they exist): the public API, whose callers
#      live outside the project;
#   3. it is called inside the file that defines it: a call within one
#      object leaves no U entry (and may be inlined away entirely), so this
#      falls back to the sources: with comments stripped by the compiler's
#      preprocessor (-fpreprocessed), its name occurs at least twice in the
#      project's .c/.cpp files (its definition and a use). These are listed
#      as candidates for `static`, not as failures.
# A function that meets none is dead: it is printed and the check fails.
# Run it after a full build (every target), or callers are missing.
set -u
usage="usage: check-dead-code.sh BUILD_DIR SOURCE_DIR [NM] [CC] [LIBRARY]"
build=${1:?$usage}
src=${2:?$usage}
nm=${3:-nm}
cc=${4:-cc}
lib=${5:-$build/libveil.a}
[ -f "$lib" ] || { echo "FAIL: $lib not found (build first)"; exit 1; }

work=$(mktemp -d) || exit 1
trap 'rm -rf -- "$work"' EXIT

# Functions the library defines (global text symbols; C++ mangled names from
# io/vdb.cpp's templates are not the project's API and are left out).
"$nm" -g --defined-only "$lib" 2>/dev/null | awk '$2 == "T" && $3 !~ /^_Z/ {print $3}' | sort -u > "$work/defined"
ndef=$(wc -l < "$work/defined")
[ "$ndef" -gt 0 ] || { echo "FAIL: no functions found in $lib"; exit 1; }

# Symbols some object references (undefined there, so resolved at link).
find "$build" -name '*.o' -type f -print0 > "$work/objects"
nobj=$(tr -cd '\0' < "$work/objects" | wc -c)
xargs -0 "$nm" -u < "$work/objects" 2>/dev/null | awk '{print $NF}' | sort -u > "$work/referenced"

# The public API: names followed by '(' in the headers under include/.
: > "$work/public"
if [ -d "$src/include" ]; then
    find "$src/include" -name '*.h' -type f -exec cat {} + |
        grep -oE '\bveil_[A-Za-z0-9_]+[[:space:]]*\(' | sed 's/[[:space:]]*($//' | sort -u > "$work/public"
fi

# The project's C/C++ sources without comments, for in-file callers.
find "$src" \( -path "$src/build*" -o -path "$src/.git" \) -prune -o \
     \( -name '*.c' -o -name '*.cpp' \) -type f -print0 |
    while IFS= read -r -d '' f; do
        case $f in *.cpp) lang=c++ ;; *) lang=c ;; esac
        "$cc" -x "$lang" -fpreprocessed -dD -E -P "$f" 2>/dev/null
    done > "$work/code"

comm -23 "$work/defined" "$work/referenced" | comm -23 - "$work/public" > "$work/unreferenced"
dead=0
local_only=()
while IFS= read -r sym; do
    uses=$(grep -ow -- "$sym" "$work/code" | wc -l)
    if [ "$uses" -ge 2 ]; then
        local_only+=("$sym")
    else
        echo "DEAD: $sym is defined in $(basename "$lib") and called nowhere (no object references it," \
             "no header under include/ declares it, no source calls it)"
        dead=$((dead + 1))
    fi
done < "$work/unreferenced"

echo "$ndef functions in $(basename "$lib"), $nobj object files searched, $(wc -l < "$work/public") public declarations"
if [ ${#local_only[@]} -gt 0 ]; then
    echo "note: no object references these, but the sources call them (inside their own file, so they could be static, or from a target not built): ${local_only[*]}"
fi
echo "$dead dead"
[ $dead -eq 0 ]
