#!/usr/bin/env bash
# The Blender tests of the veil add-on (blender/veil_blender), one case a ctest:
#
#   tests/blender/run.sh CASE VEIL_CLI VEIL_LIBRARY PYTHON_DIR WORKDIR
#
#   CASE     mapping  camera frame vs Blender's view_frame, sequences, lights, transforms (no GPU)
#            lights   the exported lights' units against Cycles' irradiance on a diffuse patch (no GPU)
#            render   F12 with engine VEIL writes an EXR; the exported scene rendered by `veil render`
#                     gives the same pixels (test_render.py, then compare.py)
#            missing  a Volume whose VDB is missing is reported in Blender's report; no crash
#            export   the exporter's files written all or nothing, its refusals reported (no GPU)
#   VEIL_CLI      build/veil; VEIL_LIBRARY build/libveil.so; PYTHON_DIR the repository's python/
#                 (the module `veil` the engine imports); WORKDIR a scratch folder (emptied)
#
# Blender runs headless: blender -b --factory-startup --python tests/blender/test_CASE.py -- WORKDIR;
# the add-on is enabled by tests/blender/common.py (repository's blender/ on sys.path, register()).
# Exit 77 (ctest: skipped, never passed) when blender is not installed (make test-blender installs
# it), or when numpy, pyopenvdb or OpenImageIO is missing for /usr/bin/python3 (whose packages
# Blender's Python imports); render and missing also when no GL 4.5 context can be made, except
# under CI=true, where that is a failure as for veil's other GPU tests.
set -uo pipefail
case_=$1 cli=$2 lib=$3 pydir=$4 work=$5
here=$(cd "$(dirname "$0")" && pwd)
skip() { echo "SKIPPED: $*"; exit 77; }
command -v blender > /dev/null || skip "blender is not installed (make test-blender installs it: apt-get install blender)"
/usr/bin/python3 -c 'import numpy, pyopenvdb, OpenImageIO' 2> /dev/null ||
  skip "numpy, pyopenvdb or OpenImageIO missing for /usr/bin/python3 (apt-get install python3-numpy python3-openvdb python3-openimageio)"
if [ "$case_" != mapping ] && [ "$case_" != lights ] && [ "$case_" != export ] && ! "$cli" gpuinfo > /dev/null 2>&1; then
  [ "${CI:-}" = true ] && { echo "FAIL: no GL 4.5 context (veil gpuinfo failed) under CI=true"; exit 1; }
  skip "no GL 4.5 context (veil gpuinfo failed)"
fi
rm -rf "$work" && mkdir -p "$work" || exit 1
export VEIL_LIBRARY=$lib PYTHONPATH=$pydir${PYTHONPATH:+:$PYTHONPATH} VEIL_CLI=$cli
log=$work/blender.log
blender -b --factory-startup --python-exit-code 1 --python "$here/test_$case_.py" -- "$work" > "$log" 2>&1
rc=$?
cat "$log"
fail() { echo "FAIL: $*"; exit 1; }
# a Python traceback Blender printed (an uncaught error inside the add-on) or a crash report
grep -q "^Traceback\|Error: Python: Traceback" "$log" && fail "Blender printed a Python traceback (above)"
grep -q "Writing: .*blender.crash.txt" "$log" && fail "Blender crashed (above)"
[ $rc -eq 0 ] || fail "blender exited with status $rc"
case $case_ in
  render)
    "$cli" render "$work/scene.json" -o "$work/cli.exr" --aovs || fail "veil render of the exported scene failed"
    /usr/bin/python3 "$here/compare.py" "$work" || fail "the engine's render differs from veil render's" ;;
  missing)
    grep -q "^Error: veil: volume 'MissingSmoke': cannot read '$work/missing_smoke.vdb'" "$log" ||
      fail "no ERROR report naming the volume and its missing file in Blender's log" ;;
esac
echo "PASS: blender $case_"
