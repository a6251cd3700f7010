#!/usr/bin/env bash
# Runs each libFuzzer target of tests/fuzz/ for SECONDS (`make fuzz`).
#
#   scripts/fuzz.sh BUILD_DIR SECONDS
#
# Seeds: tests/fuzz/corpus/TARGET/ (committed: scenes, particle files) plus
# files made here (VDBs by make_test_vdbs, EXRs by make_compare_exrs,
# particle files by veil rbf generate); what the fuzzer finds goes to BUILD_DIR/corpus/TARGET.
# A crash, a leak, undefined behaviour, a timeout (10 s an input), memory
# in use over 2 GiB or a single allocation over 2 GiB stops a target and
# fails the run (the readers check every size a file claims before a
# library allocates it: io/vdb_header.cpp, io/nanovdb_check.hpp; an EXR may
# allocate its image, up to 4 GiB for 16384^2 RGBA float, once every chunk
# is found in the file: calloc's untouched pages, resident only as chunks
# decode, so its single-allocation limit is 4.2 GB): the input is kept in
# BUILD_DIR/crashes/, to be added to tests/fuzz/corpus/TARGET/ once fixed (the
# corpus is the regression set: every file in it is run first).
set -u
build=$1
seconds=${2:-60}
root=$(cd "$(dirname "$0")/.." && pwd)
seeds=$build/fuzz-seeds
mkdir -p "$seeds"/{vdb,nanovdb,exr,particles,envmap,velocity} "$build/crashes"
"$build/tests/make_test_vdbs" "$seeds/vdb.tmp" >/dev/null || exit 1
for f in offset_scaled.vdb offset_scaled.nvdb offset_scaled_half.vdb two_grids.vdb emissive_slab.vdb empty.vdb \
    chunk_big.vdb chunk_raw.vdb chunk_header.vdb root_count.vdb no_offsets.vdb half_mismatch.vdb; do
    cp "$seeds/vdb.tmp/$f" "$seeds/vdb/" 2>/dev/null
done
for f in offset_scaled.nvdb nano_size.nvdb nano_child.nvdb; do
    cp "$seeds/vdb.tmp/$f" "$seeds/nanovdb/" 2>/dev/null
done
# velocities: a vec3 grid, a vec3d one and a float triple (blur.vdb), a sequence's file, a file with none
for f in blur.vdb moving.0001.vdb two_grids.vdb; do
    cp "$seeds/vdb.tmp/$f" "$seeds/velocity/" 2>/dev/null
done
rm -rf "$seeds/vdb.tmp"
"$build/tests/make_compare_exrs" "$seeds/exr" >/dev/null || exit 1
# environment maps: 2:1 maps of a few sizes (the corpus has one over the texel limit, by its header)
for size in "8 4" "64 32" "256 128"; do
    # shellcheck disable=SC2086
    "$build/tests/make_env_map" "$seeds/envmap/sky_${size// /x}.exr" $size || exit 1
done
# particle files in both formats, as veil writes them
for format in binary json; do
    "$build/veil" rbf generate -o "$seeds/particles/three.$format" --count 3 --seed 1 --bounds 0,0,0,1,1,1 \
        --radius 0.1,0.2 --amplitude 1,2 --format "$format" >/dev/null || exit 1
done
fails=0
export ASAN_OPTIONS=detect_leaks=1:allocator_may_return_null=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1
export LSAN_OPTIONS=suppressions=$root/tests/support/lsan.supp:print_suppressions=0
for t in scene particles exr vdb nanovdb paths envmap velocity grid arrays; do
    mkdir -p "$build/corpus/$t"
    dirs=("$build/corpus/$t")
    [ -d "$root/tests/fuzz/corpus/$t" ] && dirs+=("$root/tests/fuzz/corpus/$t")
    [ -d "$seeds/$t" ] && dirs+=("$seeds/$t")
    log=$build/fuzz-$t.log
    malloc_mb=2048
    [ "$t" = exr ] && malloc_mb=4200
    "$build/fuzz_$t" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -malloc_limit_mb=$malloc_mb -print_final_stats=1 \
        -artifact_prefix="$build/crashes/$t-" "${dirs[@]}" >"$log" 2>&1
    rc=$?
    runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
    if [ $rc -ne 0 ]; then
        echo "FAIL fuzz_$t: exit $rc after ${runs:-?} inputs; see $log and $build/crashes/"
        grep -m3 -E "ERROR|runtime error|SUMMARY" "$log"
        fails=$((fails + 1))
    else
        echo "PASS fuzz_$t: ${runs:-?} inputs in ${seconds} s, no crash, leak, hang or undefined behaviour"
    fi
done
[ $fails -eq 0 ]
