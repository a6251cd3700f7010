#!/usr/bin/env bash
# tests/cli/cli_docs_test.sh can fail: run on doctored copies of the README (and
# of cli/main.c's header) it must exit 1 and name what was changed in its
# diff; run on unchanged copies it must pass, so the copying itself is not
# what fails. Usage: cli_docs_selftest.sh CHECK VEIL SRC
set -u
check=$1
veil=$2
src=$3
tmp=$(mktemp -d /tmp/veil-cli-docs-self.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
mkdir -p "$tmp/src"
cp -r "$src/cli" "$tmp/src/cli"

# expect NAME RC PATTERN... : the check on $tmp/README.md and $tmp/src exits RC and prints each PATTERN
expect() {
  local name=$1 want=$2
  shift 2
  bash "$check" "$veil" "$tmp/README.md" "$tmp/src" > "$tmp/$name.log" 2>&1
  local rc=$?
  if [ $rc -ne "$want" ]; then
    echo "FAIL: $name: exit $rc, expected $want"
    sed 's/^/    /' "$tmp/$name.log"
    fails=$((fails + 1))
    return
  fi
  local p
  for p in "$@"; do
    if ! grep -q -F -e "$p" "$tmp/$name.log"; then
      echo "FAIL: $name: the output does not show '$p'"
      sed 's/^/    /' "$tmp/$name.log"
      fails=$((fails + 1))
    fi
  done
  echo "ok: $name (exit $rc)"
}
# doctor NAME SED-SCRIPT: a copy of the README edited by sed, which must change it
doctor() {
  sed -e "$2" "$src/README.md" > "$tmp/README.md"
  if cmp -s "$src/README.md" "$tmp/README.md"; then
    echo "FAIL: $1: the edit '$2' changed nothing (the README moved on: update this self-test)"
    fails=$((fails + 1))
  fi
}

cp "$src/README.md" "$tmp/README.md"
expect unchanged 0 "PASS"

doctor option_dropped 's/^veil info FILE.vdb \[--json\]$/veil info FILE.vdb/'
expect option_dropped 1 "veil info: the options differ" "+--json"

doctor option_renamed 's/\[--heatmap OUT.png\]/[--heat-map OUT.png]/'
expect option_renamed 1 "veil compare" "-" "--heat-map" "--heatmap"

doctor command_added 's/^veil gpuinfo$/veil gpuinfo\nveil frobnicate X.exr [--zap]/'
expect command_added 1 "-frobnicate" "cli/main.c's dispatch"

doctor command_dropped '/^veil rbf generate /,/--format json|binary/d'
expect command_dropped 1 "+rbf generate"

doctor metavar_changed 's/\[--fps F\]/[--fps FPS]/'
expect metavar_changed 1 "not the README's command block" "--fps FPS" "--fps F"

doctor no_block 's/^## The command$/## Commands/'
expect no_block 1 "no command block"

cp "$src/README.md" "$tmp/README.md"
sed -i -e '/^ \*   veil fog /d' "$tmp/src/cli/main.c"
cmp -s "$src/cli/main.c" "$tmp/src/cli/main.c" && { echo "FAIL: header_line_dropped: no 'veil fog' line in cli/main.c's header"; fails=$((fails + 1)); }
expect header_line_dropped 1 "header comment" "-fog"

[ $fails -eq 0 ] || exit 1
echo "PASS: the check passes on unchanged copies and fails, naming the change, on 7 doctored ones"
