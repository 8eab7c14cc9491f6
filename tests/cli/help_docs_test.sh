#!/usr/bin/env bash
# docs/cli.md and `pathstream --help` must not drift apart. From the help of the binary:
#  * every command `pathstream --help` lists has a section "## `pathstream COMMAND`", and every
#    such section names a command that exists;
#  * every option of `pathstream COMMAND --help` (long and short names) is named in that
#    section, or in "## Path file options" when the section links to it; -h/--help and
#    --version once anywhere in the file;
#  * an option the help prints with a default (`=VALUE`) is documented on a line that names the
#    option and that value (the options tables: | `--lead S` | 0.25 | ... |);
#  * every option a section's table documents exists in that command's help;
#  * every section states its exit codes and has an example.
#   help_docs_test.sh PATHSTREAM_BINARY DOCS_CLI_MD
set -u
bin=$1 doc=$2
failures=0 checks=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# The lines of one "## " section of the manual (its heading line starts with $1).
section() { awk -v head="$1" 'index($0, head) == 1 { on = 1; print; next } /^## / { on = 0 } on' "$doc"; }
# True when the text on stdin names $1 as a whole option (--lead is not --lead-in, -m not -mx).
names() { grep -Eq -- "(^|[^-A-Za-z0-9_])$1([^-A-Za-z0-9_]|$)"; }
# True when the text on stdin names $1 and $2 (a default) as whole words on one line.
names_with() {
  local opt=$1 value=$2
  value=$(printf '%s' "$value" | sed 's/[][\.*^$+?(){}|/]/\\&/g')
  grep -E -- "(^|[^-A-Za-z0-9_])$opt([^-A-Za-z0-9_]|$)" | grep -Eq -- "(^|[^-A-Za-z0-9_.])$value([^-A-Za-z0-9_.]|$)"
}

# Checks the options `pathstream WORDS... --help` lists against $text (the section); adds their
# names to $help_names and leaves the help in $help.
check_options() {
  help=$("$bin" "$@" --help) || { fail "$bin $* --help exited $?"; return 1; }
  local cmd="$*" line spec flags rest type default name list
  # Option lines: "  -m,--machine TEXT:FILE REQUIRED", "  --lead FLOAT:FLOAT in [0.01 - 60]=0.25"
  # (the type, up to two spaces or the end of the line, carries the default after "=").
  while IFS= read -r line; do
    spec=${line#  }
    flags=${spec%% *}
    rest=${spec#"$flags"}
    type=$(printf '%s' "$rest" | sed -E 's/^ //; s/  .*$//')
    default=""
    case $type in *=*) default=${type##*=} ;; esac
    IFS=, read -ra list <<< "$flags"
    for name in "${list[@]}"; do
      help_names="$help_names $name"
      case $name in -h | --help) continue ;; esac
      checks=$((checks + 1))
      printf '%s\n' "$text" | names "$name" || fail "'$cmd' option $name is not documented in its section of $doc"
      if [ -n "$default" ] && [ "${name#--}" != "$name" ]; then
        checks=$((checks + 1))
        printf '%s\n' "$text" | names_with "$name" "$default" ||
          fail "'$cmd' option $name: no line of its section of $doc names it with its default $default"
      fi
    done
  done < <(printf '%s\n' "$help" | awk '/^Options:/ { on = 1; next } /^[^ ]/ { on = 0 } on && /^  -/')
}

top=$("$bin" --help) || { echo "FAIL: $bin --help exited $?"; exit 1; }
commands=$(printf '%s\n' "$top" | awk '/^Subcommands:/ { on = 1; next } /^[^ ]/ { on = 0 } on && /^  [a-z]/ { print $1 }')
[ -n "$commands" ] || { echo "FAIL: no commands found in $bin --help"; exit 1; }

for opt in --help -h --version; do
  checks=$((checks + 1))
  names "$opt" < "$doc" || fail "$opt is not in $doc"
done

path_section=$(section "## Path file options")
[ -n "$path_section" ] || fail "$doc has no '## Path file options' section"

for cmd in $commands; do
  checks=$((checks + 1))
  own=$(section "## \`pathstream $cmd\`")
  if [ -z "$own" ]; then
    fail "command '$cmd' has no section '## \`pathstream $cmd\`' in $doc"
    continue
  fi
  text=$own
  if printf '%s\n' "$own" | grep -q '(#path-file-options)'; then text=$own$'\n'$path_section; fi
  for word in "Exit codes" "Example"; do
    checks=$((checks + 1))
    printf '%s\n' "$own" | grep -q "$word" || fail "section of '$cmd' does not state '$word'"
  done

  help_names=""
  check_options "$cmd" || continue
  # A command with subcommands of its own (fleet status, fleet submit, ...): theirs too, in
  # the same section.
  for sub in $(printf '%s\n' "$help" | awk '/^Subcommands:/ { on = 1; next } /^[^ ]/ { on = 0 } on && /^  [a-z]/ { print $1 }'); do
    check_options "$cmd" "$sub"
  done

  # The other way round: an option in a table row of the section must exist.
  for name in $(printf '%s\n' "$own" | grep -E '^\| `-' | grep -oE -- '(^|[^-A-Za-z0-9_])--?[A-Za-z][-A-Za-z0-9]*' |
                sed -E 's/^[^-]//' | sort -u); do
    checks=$((checks + 1))
    case " $help_names " in *" $name "*) ;; *) fail "'$cmd' section documents $name, which '$cmd --help' does not list" ;; esac
  done
done

# Messages the manual quotes are the ones the binary prints (exit code included).
flat=$(tr '\n' ' ' < "$doc" | tr -s ' ')
quoted() {  # quoted NAME EXIT_CODE FROM -- command...: the output from FROM on must be in the doc
  local name=$1 code=$2 from=$3 out rc
  shift 4
  checks=$((checks + 1))
  out=$("$@" 2>&1); rc=$?
  out=${out#*"$from"}
  if [ "$rc" -ne "$code" ]; then
    fail "$name: exit $rc (want $code): $out"
  elif [[ "$flat" != *"\`$from$out\`"* ]]; then
    fail "$name: $doc does not quote the message \`$from$out\`"
  fi
}
src=$(cd "$(dirname "$doc")/.." && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
: > "$work/drawing.txt"
quoted unknown-scheme 2 "bad target URL" -- "$bin" stream "$src/examples/wave.json" \
  -m "$src/examples/machines/pen_plotter.json" -t x
quoted unknown-file-type 1 "unknown file type" -- "$bin" check "$work/drawing.txt"
quoted version 0 "pathstream " -- "$bin" --version

# Sections for commands that do not exist.
for cmd in $(grep -oE '^## `pathstream [a-z]+' "$doc" | awk '{ print $3 }'); do
  checks=$((checks + 1))
  printf '%s\n' "$commands" | grep -qx "$cmd" || fail "$doc documents 'pathstream $cmd', which $bin --help does not list"
done

echo "$checks checks, $failures failed"
[ "$failures" -eq 0 ]
