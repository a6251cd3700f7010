#!/usr/bin/env bash
# The installed library: `cmake --install` into a temporary prefix, then the
# example (examples/render_scene.c) built against it twice, through the
# CMake package (find_package(veil)) and through pkg-config; the installed
# tree holds the tool, libveil.so, the two public headers, the package
# files and the licence, and nothing else under include/; both builds render the demo scene
# to the same bytes (same scene, same seed); the Python module imports from the installed
# tree and reports the installed library's version.
# Exit 77 (skipped) when no GL context can be made, except under CI=true.
#   install_example.sh BUILD_DIR SOURCE_DIR
# Environment: CMAKE, CC (the build's), VEIL_EXAMPLE_CFLAGS (sanitizers).
set -u
build=$1
src=$2
cmake=${CMAKE:-cmake}
cc=${CC:-cc}
cflags=${VEIL_EXAMPLE_CFLAGS:-}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
prefix=$tmp/prefix

"$cmake" --install "$build" --prefix "$prefix" > "$tmp/install.log" 2>&1 || { cat "$tmp/install.log"; fail "cmake --install"; }

# (c) the installed tree
for f in bin/veil lib/libveil.so include/veil.h include/veil/result.h lib/cmake/veil/veilConfig.cmake \
         lib/cmake/veil/veilConfigVersion.cmake lib/pkgconfig/veil.pc; do
  [ -e "$prefix/$f" ] || fail "the installed tree has no $f"
done
[ -s "$prefix/share/doc/veil/LICENSE" ] || fail "the installed tree has no share/doc/veil/LICENSE"
extra=$(cd "$prefix/include" && find . -mindepth 1 ! -path ./veil.h ! -path ./veil ! -path ./veil/result.h)
[ -z "$extra" ] || fail "include/ holds more than the public headers: $extra"

# (e) the Python module (docs/python.md): installed beside the library, it imports from the
# installed tree alone (no VEIL_LIBRARY), loads the installed libveil.so and reports its version.
# Not under sanitizers: an ASan libveil.so cannot be loaded into an uninstrumented python3.
pkg=$(cd "$prefix" && find . -path '*/veil/_libpath.py' | head -n 1)
[ -n "$pkg" ] || fail "the installed tree has no Python package (veil/_libpath.py)"
pydir=$prefix/$(dirname "$(dirname "$pkg")")
if [[ "$cflags" != *sanitize* ]]; then
  py=$(cd "$tmp" && env -u VEIL_LIBRARY PYTHONPATH="$pydir" /usr/bin/python3 -c \
       'import veil; print(veil.__version__); print(veil.library_path())' 2>&1) || fail "import veil from $pydir: $py"
  pc_version=$(sed -n 's/^Version: *//p' "$prefix/lib/pkgconfig/veil.pc")
  [ "$(sed -n 1p <<< "$py")" = "$pc_version" ] || fail "the installed module reports veil $(sed -n 1p <<< "$py"), veil.pc $pc_version"
  case "$(sed -n 2p <<< "$py")" in
    "$prefix"/*) ;;
    *) fail "the installed module loaded $(sed -n 2p <<< "$py"), not the installed library" ;;
  esac
fi

# (a) through the CMake package
"$cmake" -S "$src/examples" -B "$tmp/ex-cmake" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
         -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="$cflags" > "$tmp/ex-cmake.log" 2>&1 &&
  "$cmake" --build "$tmp/ex-cmake" >> "$tmp/ex-cmake.log" 2>&1 || { cat "$tmp/ex-cmake.log"; fail "examples/ against the CMake package"; }

# (b) through pkg-config
pc=$(PKG_CONFIG_PATH="$prefix/lib/pkgconfig" pkg-config --cflags --libs veil) || fail "pkg-config veil"
# shellcheck disable=SC2086 # word splitting of the flags is intended
"$cc" -std=c11 -Wall -Wextra -Werror $cflags -o "$tmp/render_scene_pc" "$src/examples/render_scene.c" $pc ||
  fail "render_scene.c with pkg-config flags: $pc"

# (d) both render the demo scene, identically
run() { # NAME BINARY [ENV...]
  local name=$1 bin=$2
  shift 2
  env "$@" "$bin" "$src/data/scenes/demo.json" "$tmp/$name.exr" 64 48 > "$tmp/$name.out" 2>&1
  local rc=$?
  if [ $rc -eq 3 ]; then
    cat "$tmp/$name.out"
    if [ "${CI:-}" = "true" ]; then fail "no GL context under CI"; fi
    echo "SKIPPED: no GL 4.5 context"; exit 77
  fi
  [ $rc -eq 0 ] || { cat "$tmp/$name.out"; fail "$name exited $rc"; }
  [ -s "$tmp/$name.exr" ] || fail "$name wrote no EXR"
  grep -q "^wrote $tmp/$name.exr (64x48" "$tmp/$name.out" || fail "$name output: $(cat "$tmp/$name.out")"
  grep -q '^render ' "$tmp/$name.out" || fail "$name printed no stage reports: $(cat "$tmp/$name.out")"
}
run cmake "$tmp/ex-cmake/render_scene"
run pkgconfig "$tmp/render_scene_pc" LD_LIBRARY_PATH="$prefix/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
cmp -s "$tmp/cmake.exr" "$tmp/pkgconfig.exr" || fail "the two builds rendered different EXRs"
echo "ok: installed veil $(grep '^Version:' "$prefix/lib/pkgconfig/veil.pc"), example built with CMake and pkg-config"
