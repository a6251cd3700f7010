#!/usr/bin/env bash
# The CLI is described once, in the README's command block (the fenced
# block under "## The command"); `veil --help` prints the same usage lines,
# cli/main.c dispatches the same commands and its header names them, and
# each command's file (cli/X.c) parses exactly the options its usage line
# lists. Fails with a diff naming what drifted.
# Usage: cli_docs_test.sh VEIL README SRC   (SRC: the source root, for cli/)
set -u
veil=$1
readme=$2
src=$3
tmp=$(mktemp -d /tmp/veil-cli-docs.XXXXXX)
trap 'rm -rf "$tmp"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# usage lines -> one line a command: a line starting with "veil " opens an
# entry, the indented lines after it continue it; whitespace collapsed
normalise() {
  sed -e 's/^usage://' | awk '
    /^[ \t]*$/ { next }
    { sub(/^[ \t]+/, ""); gsub(/[ \t]+/, " "); sub(/ $/, "") }
    /^veil / { if (line != "") print line; line = $0; next }
    { if (line == "") { print "stray line before any usage: " $0; next } line = line " " $0 }
    END { if (line != "") print line }'
}
# the command of a usage line: the lower-case words after veil ("rbf generate"), or "--help"
command_of() { awk '{ c = $2; for (i = 3; i <= NF && $i ~ /^[a-z]+$/; i++) c = c " " $i; print c }'; }
# the options of a usage line, sorted
options_of() { grep -o -E '(^| |\[|\|)-(-[a-z][a-z-]*|[a-z])\b' | sed -E 's/^[ [|]//' | sort -u; }

awk '/^## The command/ { sect = 1; next }
     sect && /^```/ { if (inblock) exit; inblock = 1; next }
     inblock' "$readme" | normalise > "$tmp/readme"
"$veil" --help > "$tmp/help.raw" 2>&1 || fail "veil --help exited $?"
awk '/^[ \t]*$/ { exit } { print }' "$tmp/help.raw" | normalise > "$tmp/help"
[ -s "$tmp/readme" ] || { echo "FAIL: no command block under '## The command' in $readme"; exit 1; }
[ -s "$tmp/help" ] || { echo "FAIL: no usage lines in veil --help: $(head -5 "$tmp/help.raw")"; exit 1; }

command_of < "$tmp/readme" > "$tmp/readme.cmds"
command_of < "$tmp/help" > "$tmp/help.cmds"
# main.c: the dispatch (strcmp(cmd, "X")), less `veil help` (--help's alias,
# with -h), and the header's "veil X" lines
grep -o -E 'strcmp\(cmd, "[a-z]+"\)' "$src/cli/main.c" | sed -E 's/.*"([a-z]+)".*/\1/' | grep -v -x help |
  sort -u > "$tmp/dispatch.cmds"
awk '/^\/\*/ { head = 1 } head && /^ \*\/|\*\// { exit } head' "$src/cli/main.c" |
  grep -o -E '^ \* +veil [a-z]+' | awk '{ print $3 }' | sort -u > "$tmp/header.cmds"
awk '{ print $1 }' "$tmp/readme.cmds" | grep -v -- '^--' | sort -u > "$tmp/readme.first"

if ! diff -u --label "README ($readme)" --label "veil --help" "$tmp/readme.cmds" "$tmp/help.cmds" > "$tmp/d"; then
  fail "the commands of veil --help and of the README's block differ:"
  cat "$tmp/d"
fi
if ! diff -u --label "README's commands" --label "cli/main.c's dispatch" "$tmp/readme.first" "$tmp/dispatch.cmds" > "$tmp/d"; then
  fail "the README's commands and those cli/main.c dispatches differ:"
  cat "$tmp/d"
fi
if ! diff -u --label "cli/main.c's dispatch" --label "cli/main.c's header comment" "$tmp/dispatch.cmds" "$tmp/header.cmds" > "$tmp/d"; then
  fail "cli/main.c's header comment does not name every command it dispatches:"
  cat "$tmp/d"
fi

# per command: the options in the README, in --help, and parsed by cli/X.c
while IFS= read -r cmd; do
  grep -E "^veil $cmd( |\$)" "$tmp/readme" | head -1 | options_of > "$tmp/o.readme"
  grep -E "^veil $cmd( |\$)" "$tmp/help" | head -1 | options_of > "$tmp/o.help"
  if ! diff -u --label "README: veil $cmd" --label "veil --help: veil $cmd" "$tmp/o.readme" "$tmp/o.help" > "$tmp/d"; then
    fail "veil $cmd: the options differ between the README and veil --help:"
    cat "$tmp/d"
  fi
  file=$src/cli/${cmd%% *}.c
  if [ -f "$file" ]; then
    grep -o -E '"-(-[a-z][a-z-]*|[a-z])"' "$file" | tr -d '"' | sort -u > "$tmp/o.code"
    if ! diff -u --label "README: veil $cmd" --label "parsed by ${file#"$src"/}" "$tmp/o.readme" "$tmp/o.code" > "$tmp/d"; then
      fail "veil $cmd: the README's options and those ${file#"$src"/} parses differ:"
      cat "$tmp/d"
    fi
  fi
done < "$tmp/readme.cmds"

# last, the usage lines word for word (the help prints the README's block)
if ! diff -u --label "README ($readme)" --label "veil --help" "$tmp/readme" "$tmp/help" > "$tmp/d"; then
  fail "the usage lines of veil --help are not the README's command block (whitespace aside):"
  cat "$tmp/d"
fi

[ $fails -eq 0 ] || exit 1
echo "PASS: $(wc -l < "$tmp/readme.cmds") commands: the README's block, veil --help, cli/main.c's dispatch and header, and each command's options agree"
