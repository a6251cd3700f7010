#!/usr/bin/env bash
# The fuzz corpus as regression inputs in every build (`make fuzz` needs
# clang; this does not): each file of tests/fuzz/corpus/ goes through the
# reader its folder names, through the CLI, which must answer with exit 0,
# 1 or 2 (never a signal, never a hang: 20 s each), within 1.5 GiB of
# address space without running out of it (an input that makes a reader
# allocate gigabytes is a defect even when the allocation fails cleanly),
# and, when it refuses, say why on stderr.
#
#   fuzz_corpus.sh VEIL CORPUS_DIR
set -u
veil=$1
corpus=$2
fails=0
n=0
limit="ulimit -v 1572864"
ldd "$veil" 2>/dev/null | grep -q libasan && limit=":" # ASan's shadow reserves terabytes
run() { # expected-to-finish command...
    (eval "$limit"; exec timeout 20 "$@") >/dev/null 2>"$log"
    local rc=$?
    n=$((n + 1))
    if [ $rc -gt 2 ] || { [ $rc -ne 0 ] && [ ! -s "$log" ]; } || grep -q "out of memory" "$log"; then
        echo "FAIL $*: exit $rc: $(head -c 300 "$log")"
        fails=$((fails + 1))
    fi
}
log=$(mktemp) || exit 1
trap 'rm -f -- "$log"' EXIT
for f in "$corpus"/vdb/*; do [ -f "$f" ] && run "$veil" info "$f"; done
nvdb=$(mktemp --suffix=.nvdb) || exit 1 # NanoVDB is read by its name's suffix
trap 'rm -f -- "$log" "$nvdb"' EXIT
for f in "$corpus"/nanovdb/*; do [ -f "$f" ] && cp "$f" "$nvdb" && run "$veil" info "$nvdb"; done
for f in "$corpus"/exr/*; do [ -f "$f" ] && run "$veil" compare "$f" "$f"; done
for f in "$corpus"/scene/*; do [ -f "$f" ] && run "$veil" render "$f" --explain; done
echo "$n corpus inputs, $fails failed"
[ $fails -eq 0 ]
