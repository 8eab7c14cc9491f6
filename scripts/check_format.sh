#!/bin/bash
# clang-format (.clang-format) over the C++ the project keeps formatted: the folders listed in
# scripts/format_enforced.txt, and with --changed also every C++ file that differs from HEAD
# (what a commit is about to add). Exit 1 naming each file clang-format would change.
#   check_format.sh SOURCE_DIR [--changed]
set -euo pipefail
source_dir=$1
cd "$source_dir"
command -v clang-format >/dev/null || { echo "check_format: clang-format not found (scripts/setup.sh installs it)" >&2; exit 1; }
files=()
while read -r folder; do
  folder=${folder%%#*}
  folder=${folder// /}
  [ -n "$folder" ] || continue
  [ -e "$folder" ] || { echo "check_format: $folder (scripts/format_enforced.txt) does not exist" >&2; exit 1; }
  while IFS= read -r f; do files+=("$f"); done < <(find "$folder" \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \) -not -path '*/node_modules/*' | sort)
done < scripts/format_enforced.txt
if [ "${2:-}" = "--changed" ]; then
  while IFS= read -r f; do [ -f "$f" ] && files+=("$f"); done < <(git diff --name-only HEAD -- '*.cpp' '*.hpp' '*.h')
fi
bad=0
for f in $(printf '%s\n' "${files[@]}" | sort -u); do
  if ! clang-format --dry-run --Werror "$f" >/dev/null 2>&1; then
    echo "not formatted: $f (clang-format -i $f)" >&2
    bad=$((bad + 1))
  fi
done
[ "$bad" -eq 0 ] || { echo "check_format: $bad files need clang-format" >&2; exit 1; }
echo "check_format: ${#files[@]} files formatted"
