#!/bin/bash
# The device runtime's program links nothing of the host library (planner, readers, plots,
# streamers): no function the host library defines (a strong text symbol) is defined in it.
#   check_device_links.sh HOST_LIBRARY DEVICE_PROGRAM
set -euo pipefail
host_lib=$1 program=$2
strong() { nm --defined-only "$1" 2>/dev/null | awk '$2 == "T" { print $3 }' | sort -u; }
host=$(strong "$host_lib")
[ -n "$host" ] || { echo "check_device_links: no functions read from $host_lib" >&2; exit 1; }
shared=$(comm -12 <(echo "$host") <(strong "$program"))
if [ -n "$shared" ]; then
  echo "$program links $(echo "$shared" | wc -l) functions of $host_lib, e.g.:" >&2
  echo "$shared" | head -5 | c++filt >&2
  exit 1
fi
echo "$(basename "$program"): none of the $(echo "$host" | wc -l) functions of $(basename "$host_lib") linked"
