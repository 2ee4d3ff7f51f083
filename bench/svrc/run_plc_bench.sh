#!/usr/bin/env bash
# PLC meshing, svrc vs tetgen 1.5 side by side (issues #5 and #6): builds
# svrc_plc_bench and the svrc CLI (Release, -DSVRC_BUILD_BENCH=ON, in
# build/bench) and runs them on the corpus inputs of #5, the generated
# families (core/plc/families.h) and the crease inputs of #6. The markdown
# table goes to stdout; build output and per-run progress go to stderr.
#
#   bash bench/svrc/run_plc_bench.sh                 # everything, both tools
#   bash bench/svrc/run_plc_bench.sh --tools tetgen  # extra flags go to svrc_plc_bench
#
# Environment: BUILD (default build/bench), CORPUS (default ../shared/corpus),
# TIMEOUT per run in seconds (default 120), MEM_MIB per-run address-space
# limit (default 4096), JOBS for the build (default 2).
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
BUILD=${BUILD:-$ROOT/build/bench}
CORPUS=${CORPUS:-$(cd "$ROOT/.." && pwd)/shared/corpus}
TIMEOUT=${TIMEOUT:-120}
MEM_MIB=${MEM_MIB:-4096}
JOBS=${JOBS:-2}

if [[ ! -f "$CORPUS/MANIFEST.csv" ]]; then
  echo "run_plc_bench: corpus not found at $CORPUS (set CORPUS=...)" >&2
  exit 1
fi
if [[ ! -x /usr/bin/tetgen ]]; then
  echo "run_plc_bench: /usr/bin/tetgen missing (scripts/setup.sh installs the tetgen package)" >&2
  exit 1
fi

# Only what the bench needs: no gRPC service, no test suites.
cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSVRC_BUILD_BENCH=ON \
  -DSVRC_BUILD_SERVICE=OFF -DSVRC_BUILD_TESTS=OFF >&2
cmake --build "$BUILD" -j"$JOBS" --target svrc_plc_bench svrc >&2

inputs=(
  # issue #5: no acute creases
  "$CORPUS/a_convex/cube.poly"
  "$CORPUS/b_internal/box_internal_facet.poly"
  "$CORPUS/b_internal/box_in_box.poly"
  "$CORPUS/e_spread/tiny_cube_in_box.poly"
  "$CORPUS/e_spread/far_offset_close_points.poly"
  # generated families, in the order of families::StandardInputs()
  families
  # issue #6: creases (knife_edge.obj is the .poly's twin; tetgen reads no OBJ)
  "$CORPUS/a_convex/tetra.poly"
  "$CORPUS/b_internal/example.poly"
  "$CORPUS/c_creases/wedge-1.smesh"
  "$CORPUS/c_creases/knife_edge.poly"
  "$CORPUS/c_creases/schonhardt.off"
  "$CORPUS/d_small_angles/segment_fan.poly"
  "$CORPUS/c_creases/fandisk.off"
)

echo "# svrc_plc_bench, $(date -u +%Y-%m-%dT%H:%MZ), commit $(git -C "$ROOT" rev-parse --short HEAD 2>/dev/null || echo '?'), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
exec "$BUILD/bench/svrc/svrc_plc_bench" --radius-edge 2,1.414 --timeout "$TIMEOUT" \
  --mem-limit-mib "$MEM_MIB" "$@" "${inputs[@]}"
