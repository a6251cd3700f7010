#!/usr/bin/env bash
# The layout's rules (docs/architecture.md), checked on every #include "..."
# of the library, the CLI and the examples:
#   - arrows point down the pipeline: each folder includes only the folders
#     listed for it below (so io/ only core/ and scene/; volume/,
#     propagate/ and volumetric/ never render/; volume/ and propagate/
#     never volumetric/; reference/ never propagate/, volumetric/, render/,
#     gpu/ or frame/; nothing but cli/ includes cli/);
#   - shaders' `//@include PATH` lines (paths from the root) keep the same
#     arrows as the C that dispatches them;
#   - the folder graph that the includes draw has no cycle;
#   - examples/ include only the public header <veil.h>;
#   - every quoted include resolves to a file of the tree (or a generated
#     one of the build).
# Usage: scripts/check-layout.sh [SOURCE_ROOT]. Prints each violation; exit 1 if any.
set -uo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root" || exit 2

declare -A allowed=(
  [include]="include"
  [core]="core include"
  [scene]="scene core include"
  [io]="io scene core include"
  [gpu]="gpu core include"
  [volume]="volume io gpu scene core include"
  [propagate]="propagate volume gpu scene core include"
  [volumetric]="volumetric propagate volume gpu scene core include"
  [render]="render volumetric propagate volume io gpu scene core include"
  [frame]="frame render volumetric propagate volume io gpu scene core include"
  [reference]="reference volume io scene core include"
  [cli]="cli frame reference render volumetric propagate volume io gpu scene core include"
)
# files made at build time, included by path
generated="shaders/registry.c"

bad=0
edges=""
complain() { echo "check-layout: $*"; bad=1; }

for dir in "${!allowed[@]}"; do
  [ -d "$dir" ] || continue
  while IFS= read -r file; do
    while IFS= read -r inc; do
      [ -n "$inc" ] || continue
      here=$(dirname "$file")
      if [ -f "$here/$inc" ]; then
        target=$(realpath -m --relative-to=. "$here/$inc")
      elif [ -f "$inc" ]; then
        target=$inc
      elif grep -qx "$inc" <<<"$generated"; then
        continue
      else
        complain "$file includes \"$inc\", which is no file of the tree"
        continue
      fi
      to=${target%%/*}
      [ "$to" = "$target" ] && to="(root)"
      [ "$to" = "$dir" ] || edges+="$dir $to"$'\n'
      case " ${allowed[$dir]} " in
        *" $to "*) ;;
        *) complain "$file includes $target: $dir/ may include only ${allowed[$dir]}" ;;
      esac
    done < <(sed -n -e 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"\([^"]*\)".*/\1/p' \
                    -e 's#^[[:space:]]*//@include[[:space:]]*\([^[:space:]]*\).*#\1#p' "$file")
  done < <(find "$dir" -type f \( -name '*.c' -o -name '*.h' -o -name '*.cpp' -o -name '*.comp' -o -name '*.glsl' \))
done

# no folder cycle: tsort reports a loop on stderr
if [ -n "$edges" ]; then
  cyc=$(printf '%s' "$edges" | sort -u | tsort 2>&1 >/dev/null)
  [ -z "$cyc" ] || complain "the folders include each other in a cycle: $cyc"
fi

# examples: the public header only (and the C library's own headers)
if [ -d examples ]; then
  while IFS= read -r file; do
    while IFS= read -r inc; do
      case "$inc" in
        '<veil.h>') ;;
        '"'*|*/*) complain "$file includes $inc: examples use only <veil.h>" ;;
      esac
    done < <(sed -n 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*\([<"][^>"]*[>"]\).*/\1/p' "$file")
  done < <(find examples -type f -name '*.c')
fi

n=$(printf '%s' "$edges" | sort -u | grep -c . || true)
if [ "$bad" = 0 ]; then
  echo "check-layout: the include rules hold ($n folder edges, no cycle)"
  exit 0
fi
exit 1
