#!/usr/bin/env bash
# The programs' help, their man pages, dnbctl's bash completion and
# --version agree: every long option a program's --help lists (dnbctl's
# commands' too) is in its man page, every option a man page defines is in
# --help, every dnbctl command is in its man page and its completion with its
# options, every page renders without a groff warning, and --version says the
# name and version first.
#   docs_test.sh MAN_DIR COMPLETION VERSION NAME=PROGRAM...
set -euo pipefail

man_dir=${1:?usage: docs_test.sh MAN_DIR COMPLETION VERSION NAME=PROGRAM...}
completion=${2:?}
version=${3:?}
shift 3
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v man >/dev/null || fail "man not found (package man-db)"
[ -f "$completion" ] || fail "$completion: no such file"

# Long options in help text: at the start of an option line ("  -c,--config").
help_options() { grep -oE '^ +(-[a-zA-Z],)?--[a-z][a-z0-9-]*' | sed 's/.*--/--/' | sort -u; }
# Long options a page mentions anywhere, and those it defines (the tag line
# after .TP).
page_options() { grep -oE '\\-\\-[a-z]([a-z0-9]|\\-)*' "$1" | sed 's/\\-/-/g' | sort -u; }
page_defined() {
  awk 'tag { print; tag = 0 } /^\.TP/ { tag = 1 }' "$1" | grep -oE '\\-\\-[a-z]([a-z0-9]|\\-)*' |
    sed 's/\\-/-/g' | sort -u
}

checked=0
for arg in "$@"; do
  name=${arg%%=*}
  program=${arg#*=}
  page=$(ls "$man_dir/$name".[1-8])
  [ -f "$page" ] || fail "no man page for $name in $man_dir"

  warnings=$(LC_ALL=C.UTF-8 MANWIDTH=80 man --warnings -l "$page" 2>&1 >/dev/null)
  [ -z "$warnings" ] || fail "man -l $page: $warnings"

  first=$("$program" --version | head -n 1)
  [ "$first" = "$name $version" ] || fail "$name --version begins '$first', not '$name $version'"
  "$program" --version | grep -qE '^revision .+' || fail "$name --version gives no revision"

  help=$("$program" --help)
  if [ "$name" = dnbctl ]; then
    commands=$(sed -n '/^Subcommands:/,/^$/p' <<<"$help" | grep -oE '^  [a-z]+' | tr -d ' ')
    [ "$(wc -w <<<"$commands")" -ge 10 ] || fail "dnbctl --help lists only: $commands"
    "$program" --version | grep -qE '^Cyclone DDS [0-9.]+' || fail "dnbctl --version gives no Cyclone DDS"
    for c in $commands; do
      grep -qE "^\.B $c( |$)" "$page" || fail "dnbctl.1 does not describe the command $c"
      grep -q "[ \"]$c[ \"]" "$completion" || fail "the completion does not know the command $c"
      sub_options=$("$program" "$c" --help | help_options | { grep -v -- '--help' || true; })
      for o in $sub_options; do
        grep -q -- "$o" "$completion" || fail "the completion does not know dnbctl $c $o"
      done
      help+=$'\n'$("$program" "$c" --help)
    done
  fi

  expected=$(help_options <<<"$help")
  [ -n "$expected" ] || fail "$name --help lists no option"
  missing=$(comm -23 <(echo "$expected") <(page_options "$page"))
  [ -z "$missing" ] || fail "$(basename "$page") does not mention $(echo $missing)"
  unknown=$(comm -13 <(echo "$expected") <(page_defined "$page"))
  [ -z "$unknown" ] || fail "$(basename "$page") defines $(echo $unknown), which $name --help does not list"
  checked=$((checked + 1))
  echo "$name: $(wc -l <<<"$expected") options in --help and in $(basename "$page")"
done
[ "$checked" -ge 1 ] || fail "no program given"

# The configuration's page shows the annotated example, line for line.
toml_page="$man_dir/dnbridge.toml.5"
warnings=$(LC_ALL=C.UTF-8 MANWIDTH=80 man --warnings -l "$toml_page" 2>&1 >/dev/null)
[ -z "$warnings" ] || fail "man -l $toml_page: $warnings"
LC_ALL=C.UTF-8 MANWIDTH=200 man -l "$toml_page" 2>/dev/null | grep -q 'allow_allocate_release = false' ||
  fail "dnbridge.toml.5 does not show the annotated example"
echo "docs agree: OK"
