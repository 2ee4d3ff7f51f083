#!/bin/bash
# Output-sensitive cost of the whole job, svrc against tetgen, on one measure
# (issue #5; bench/RESULTS.md "Session 51"):
#
#   bench/svrc/flatness_vs_tetgen.sh BUILD [REPEAT [VOLUMES [RADIUS_EDGE]]]
#
# For each max volume V (default 1e-4,1e-5,1e-6) the volume-constrained unit
# cube (../shared/corpus/a_convex/cube.poly, copied to a temporary directory)
# is meshed by `svrc mesh --max-volume V --radius-edge R` and by
# `tetgen -pq<R>a<V> -Q`, REPEAT times each, interleaved, for the CPU time
# (user + system, bash's `time`), then once more under
# BUILD/bench/svrc/libsvrc_heap_peak.so for the peak heap (the sensitivity
# bench's count of malloc_usable_size, for both processes; deterministic) and
# the output's tets and vertices. Printed: one row per tool and volume (least
# CPU of the repeats, all of them in brackets), then per tool the
# flatness over the series — largest over smallest of CPU and heap per
# output tet and per output vertex.
set -eu
if [ $# -lt 1 ]; then
  sed -n 2,17p "$0"
  exit 2
fi
build=$(cd "$1" && pwd)
repeat=${2:-3}
volumes=${3:-1e-4,1e-5,1e-6}
re=${4:-2}
here=$(cd "$(dirname "$0")" && pwd)
cube=$here/../../../shared/corpus/a_convex/cube.poly
shim=$build/bench/svrc/libsvrc_heap_peak.so
svrc=$build/client/svrc
for f in "$cube" "$shim" "$svrc" /usr/bin/tetgen; do
  [ -e "$f" ] || { echo "missing $f" >&2; exit 2; }
done
work=$(mktemp -d /tmp/svrc_flat.XXXXXX)
trap 'rm -rf "$work"' EXIT
cp "$cube" "$work/cube.poly"
cd "$work"

# cmd TOOL V: the tool's command line for volume V.
cmd() {
  if [ "$1" = svrc ]; then
    echo "$svrc mesh cube.poly --max-volume $2 --radius-edge $re -o out.node --quiet"
  else
    echo "tetgen -pq${re}a$2 -Q cube.poly"
  fi
}
# cpu TOOL V: user + system seconds of one run (bash's `time`, getrusage).
cpu() {
  local TIMEFORMAT='%3U %3S' t
  t=$( { time $(cmd "$1" "$2") >/dev/null 2>&1; } 2>&1)
  echo "$t" | awk '{printf "%.3f\n", $1 + $2}'
}
# heap TOOL V: "heap_bytes tets vertices" of one run under the shim.
heap() {
  rm -f heap.txt
  SVRC_HEAP_PEAK_OUT=$work/heap.txt LD_PRELOAD=$shim $(cmd "$1" "$2") >/dev/null 2>&1
  local ele=cube.1.ele node=cube.1.node tets verts
  [ "$1" = svrc ] && ele=out.ele node=out.node
  set -- $(grep -v '^#' $ele | head -1) && tets=$1
  set -- $(grep -v '^#' $node | head -1) && verts=$1
  echo "$(head -1 heap.txt | cut -d= -f2) $tets $verts"
}

echo "| tool | max volume | tets | vertices | cpu s: least (all $repeat runs) | µs/tet | µs/vertex | peak heap B | B/tet | B/vertex |"
echo "|---|---|---|---|---|---|---|---|---|---|"
rows=$work/rows.txt
for v in ${volumes//,/ }; do
  for tool in svrc tetgen; do : >"$work/$tool.$v"; done
  for _ in $(seq "$repeat"); do
    for tool in svrc tetgen; do cpu "$tool" "$v" >>"$work/$tool.$v"; done
  done
  for tool in svrc tetgen; do
    least=$(sort -n "$work/$tool.$v" | head -1)
    all=$(tr '\n' ' ' <"$work/$tool.$v")
    echo "$least $(heap "$tool" "$v")" | awk -v tool="$tool" -v v="$v" -v all="$all" '{
      printf "| %s | %s | %d | %d | %.3f (%s) | %.3f | %.2f | %d | %.1f | %.0f |\n",
        tool, v, $3, $4, $1, all, 1e6 * $1 / $3, 1e6 * $1 / $4, $2, $2 / $3, $2 / $4
      print tool, 1e6 * $1 / $3, 1e6 * $1 / $4, $2 / $3, $2 / $4 >> "'"$rows"'"
    }'
  done
done
echo
echo "flatness over the series (largest / smallest):"
for tool in svrc tetgen; do
  awk -v tool="$tool" '$1 == tool {
      for (k = 2; k <= 5; ++k) { if (!(k in lo) || $k < lo[k]) lo[k] = $k; if (!(k in hi) || $k > hi[k]) hi[k] = $k }
    } END {
      printf "  %s: cpu per tet x%.2f, per vertex x%.2f; heap per tet x%.2f, per vertex x%.2f\n",
        tool, hi[2] / lo[2], hi[3] / lo[3], hi[4] / lo[4], hi[5] / lo[5]
    }' "$rows"
done
