#!/usr/bin/env bash
# Checks a bare-metal image for heap and C++ runtime symbols and prints its size; optionally
# measures the core's own .text and asserts a ceiling on it.
#
#   check_image.sh --nm NM --forbidden-only IMAGE
#   check_image.sh --nm NM --size SIZE [--ar AR] [--core-lib LIB.a] [--probe AXES=OBJ]... \
#                  [--max-core-text BYTES [--assert-axes 1,2,3]] IMAGE...
#
# Forbidden (defined or referenced): malloc free calloc realloc, operator new/delete
# (_Znw* _Zna* _Zdl* _Zda*), __cxa_*, __gxx_personality*, _Unwind_*, __aeabi_unwind*.
# Core .text = .text* sections (code only) of the library objects + those of the size probe
# for A axes (every template the core instantiates for SetpointStream<A, 16>, emitted out of
# line by explicit instantiation). .rodata is reported next to it, not counted.
set -euo pipefail

nm=arm-none-eabi-nm
size=arm-none-eabi-size
forbidden_only=0
core_lib=
max_core_text=
assert_axes=   # empty: assert the limit at every probe's axis count
probes=()
images=()
while [ $# -gt 0 ]; do
  case "$1" in
    --nm) nm=$2; shift 2 ;;
    --size) size=$2; shift 2 ;;
    --forbidden-only) forbidden_only=1; shift ;;
    --ar) AR=$2; shift 2 ;;
    --core-lib) core_lib=$2; shift 2 ;;
    --probe) probes+=("$2"); shift 2 ;;
    --max-core-text) max_core_text=$2; shift 2 ;;
    --assert-axes) assert_axes=",$2,"; shift 2 ;;
    -*) echo "check_image.sh: unknown option $1" >&2; exit 2 ;;
    *) images+=("$1"); shift ;;
  esac
done
[ ${#images[@]} -gt 0 ] || [ -n "$core_lib" ] || { echo "check_image.sh: no image" >&2; exit 2; }

forbidden_re='^(malloc|free|calloc|realloc|_Znw.*|_Zna.*|_Zdl.*|_Zda.*|__cxa_.*|__gxx_personality.*|_Unwind_.*|__aeabi_unwind.*)$'
status=0

# Reads hex sizes, one per line; prints "count sum" (decimal). Plain bash: mawk has no strtonum.
sum_hex() {
  local n=0 total=0 h
  while read -r h; do n=$((n + 1)); total=$((total + 16#$h)); done
  echo "$n $total"
}

for image in "${images[@]}"; do
  [ -f "$image" ] || { echo "check_image.sh: $image not found" >&2; exit 2; }
  bad=$("$nm" "$image" | awk '{print $NF}' | grep -E "$forbidden_re" | sort -u || true)
  if [ -n "$bad" ]; then
    echo "FAIL $image: forbidden runtime symbols:" >&2
    echo "$bad" | sed 's/^/  /' >&2
    status=1
  elif [ $forbidden_only -eq 1 ]; then
    echo "check_image: $(basename "$image"): no heap/exception/RTTI runtime symbols"
  fi
done
[ $forbidden_only -eq 1 ] && exit $status

if [ ${#images[@]} -gt 0 ]; then
  echo "== image sizes (bytes; text includes rodata and the .data load image) =="
  "$size" -B "${images[@]}" | awk '{printf "  %-8s %-8s %-8s %s\n", $1, $2, $3, $NF}'
  for image in "${images[@]}"; do
    # Out-of-line core functions (library and template instantiations) and the libgcc helpers
    # the image links (not core code; listed for completeness).
    read -r core_n core_bytes < <("$nm" -S -C "$image" |
      awk '$3 ~ /^[tTwW]$/ && /pathstream::/ && !/pathstream::workload::/ {print $2}' | sum_hex)
    read -r help_n help_bytes < <("$nm" -S "$image" |
      awk '$3 ~ /^[tT]$/ && $4 ~ /^(__aeabi_|__udiv|__div|__mul|__ash|__lsh|__clz|__gnu_)/ {print $2}' | sum_hex)
    echo "  $(basename "$image"): out-of-line pathstream:: functions: $core_n, $core_bytes bytes;" \
         "libgcc helpers: $help_n, $help_bytes bytes"
  done
fi

# Section sums of one object file or archive (all members): ".text* .rodata* .data* .bss*"
# sizes in bytes, from `size -A`; .text* is code only (function sections included).
section_sums() {
  "$size" -A "$1" | awk '
    $1 ~ /^\.text/   {t += $2}
    $1 ~ /^\.rodata/ {r += $2}
    $1 ~ /^\.data/   {d += $2}
    $1 ~ /^\.bss/    {b += $2}
    END {printf "%d %d %d %d\n", t, r, d, b}'
}

if [ -n "$core_lib" ]; then
  [ -f "$core_lib" ] || { echo "check_image.sh: $core_lib not found" >&2; exit 2; }
  echo "== core library objects ($(basename "$core_lib"), before --gc-sections) =="
  printf "  %-8s %-8s %-8s %-8s %s\n" .text .rodata .data .bss object
  tmp=$(mktemp -d)
  (cd "$tmp" && "${AR:-${nm%nm}ar}" x "$(cd "$(dirname "$core_lib")" && pwd)/$(basename "$core_lib")")
  for obj in "$tmp"/*; do
    read -r t r d b < <(section_sums "$obj")
    printf "  %-8s %-8s %-8s %-8s %s\n" "$t" "$r" "$d" "$b" "$(basename "$obj")"
  done
  rm -rf "$tmp"
  read -r lib_text lib_rodata lib_data lib_bss < <(section_sums "$core_lib")
  printf "  %-8s %-8s %-8s %-8s %s\n" "$lib_text" "$lib_rodata" "$lib_data" "$lib_bss" "(total)"
  if [ ${#probes[@]} -gt 0 ]; then
    echo "== core .text = library .text + template .text for one SetpointStream<A, 16> =="
    printf "  %-5s %-9s %-14s %-10s %-12s %-9s %s\n" axes "lib .text" "templates .text" \
      "core .text" "core .rodata" "data+bss" "limit"
    for p in "${probes[@]}"; do
      axes=${p%%=*}
      obj=${p#*=}
      [ -f "$obj" ] || { echo "check_image.sh: $obj not found" >&2; exit 2; }
      read -r pt pr pd pb < <(section_sums "$obj")
      core=$((lib_text + pt))
      verdict=""
      if [ -n "$max_core_text" ]; then
        asserted=1
        [ -z "$assert_axes" ] || [[ "$assert_axes" == *",$axes,"* ]] || asserted=0
        if [ $core -le "$max_core_text" ]; then
          verdict="<= $max_core_text ok ($((max_core_text - core)) spare)"
        elif [ $asserted -eq 1 ]; then
          verdict="> $max_core_text FAIL"; status=1
        else
          verdict="> $max_core_text by $((core - max_core_text)) (not asserted)"
        fi
        [ $asserted -eq 1 ] && verdict="$verdict [asserted]"
      fi
      printf "  %-5s %-9s %-14s %-10s %-12s %-9s %s\n" "$axes" "$lib_text" "$pt" "$core" \
        "$((lib_rodata + pr))" "$((lib_data + lib_bss + pd + pb))" "$verdict"
    done
  fi
fi
exit $status
