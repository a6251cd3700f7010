#!/usr/bin/env bash
# scripts/check-layout.sh must catch what it guards against: on small trees
# made here, an upward include (volume/ -> render/), an io/ file reaching
# into volume/, a library file including cli/, an include that resolves to
# nothing, an example using an internal header, volumetric/ reaching into
# render/ and a shader's //@include going up the pipeline each fail it; a
# clean tree passes.
set -uo pipefail
check=$1
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
mk() { mkdir -p "$(dirname "$tmp/$1")"; printf '%s\n' "$2" > "$tmp/$1"; }
fresh() { rm -rf "$tmp"/*; mk core/a.h '/* core */'; mk render/r.h '#include "../core/a.h"'; mk volume/v.h '#include "../core/a.h"'; mk cli/c.h '/* cli */'; }
expect() { # expect pass|fail what
  out=$(bash "$check" "$tmp" 2>&1); rc=$?
  if [ "$1" = pass ]; then [ $rc = 0 ] || fail "$2: rejected: $out"
  else [ $rc = 1 ] || fail "$2: not caught (exit $rc): $out"; fi
  echo "ok: $2 ($1)"
}
fresh; expect pass "a clean tree"
fresh; mk volume/bad.c '#include "../render/r.h"'; expect fail "volume/ including render/"
fresh; mk io/bad.c '#include "volume/v.h"'; expect fail "io/ including volume/ (root-relative)"
fresh; mk render/bad.c '#include "../cli/c.h"'; expect fail "render/ including cli/"
fresh; mk scene/bad.c '#include "nowhere.h"'; expect fail "an include that is no file"
fresh; mk examples/x.c '#include "frame/renderer.h"'; expect fail "an example with an internal header"
fresh; mk examples/x.c '#include <veil.h>'; expect pass "an example with <veil.h>"
fresh; mk volumetric/bad.c '#include "../render/r.h"'; expect fail "volumetric/ including render/"
fresh; mk volume/shaders/bad.comp '//@include render/r.h'; expect fail "a shader of volume/ pulling in render/ (//@include)"
fresh; mk render/shaders/ok.comp '//@include volume/v.h'; expect pass "a shader of render/ pulling in volume/"
echo "10 passed, 0 failed"
