#!/usr/bin/env bash
# Runs one libFuzzer target for a bounded time, seeded from the shared corpus
# (never copied into the repo) and the committed reference container.
#   tests/fuzz/run_fuzz.sh <build-dir> <target> [seconds=90] [extra libFuzzer flags...]
# <target>: plc_poly plc_smesh plc_node plc_off plc_stl plc_obj plc_medit
#           plc_validate codec_decode codec_decode_rehash
# Seeds and the growing corpus live in <build-dir>/fuzz-work/<target>/;
# crashers are written to <build-dir>/fuzz-work/<target>/artifacts/.
# See docs/fuzzing.md.
set -euo pipefail
build=${1:?build dir}; target=${2:?target}; secs=${3:-90}; shift $(( $# < 3 ? $# : 3 ))
src=$(cd "$(dirname "$0")/../.." && pwd)
corpus=${SVRC_CORPUS_DIR:-$src/../shared/corpus}
[[ -d $corpus ]] || { echo "no corpus at $corpus" >&2; exit 1; }
bin=$build/tests/fuzz/fuzz_$target
[[ -x $bin ]] || { echo "no $bin: build with -DSVRC_FUZZ=ON" >&2; exit 1; }
work=$build/fuzz-work/$target
mkdir -p "$work/seeds" "$work/corpus" "$work/artifacts"

# Seeds: the corpus files of the target's format (validate: every reader file
# prefixed with its format byte, the InputFormat order), the reference container.
index_of() { case $1 in poly) echo 0;; smesh) echo 1;; node) echo 2;; off) echo 3;;
                        stl) echo 4;; obj) echo 5;; mesh) echo 6;; *) echo -1;; esac; }
rm -f "$work/seeds"/*
while IFS= read -r f; do
  ext=${f##*.}; ext=${ext,,}; i=$(index_of "$ext"); [[ $i -ge 0 ]] || continue
  name=$(basename "$(dirname "$f")")_$(basename "$f")
  case $target in
    plc_validate) { printf "\\x0$i"; cat "$f"; } > "$work/seeds/$name" ;;
    plc_medit) [[ $ext == mesh ]] && cp "$f" "$work/seeds/$name" ;;
    plc_node) [[ $ext == node || $ext == poly ]] && cp "$f" "$work/seeds/$name" ;;  # .poly starts with a node section
    plc_*) [[ $ext == "${target#plc_}" ]] && cp "$f" "$work/seeds/$name" ;;
  esac
done < <(find "$corpus" -type f | sort)
case $target in
  plc_medit)  # the corpus has no .mesh file: a tetrahedron's surface
    printf 'MeshVersionFormatted 1\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n0 0 1 0\nTriangles\n4\n1 3 2 1\n1 2 4 2\n1 4 3 3\n2 3 4 4\nEnd\n' \
      > "$work/seeds/tetra.mesh" ;;
  codec_*) cp "$src/tests/codec/data/reference_v1.svrc" "$work/seeds/" ;;
esac
# The regression inputs are seeds too.
if [[ -d $src/tests/fuzz/regressions/$target ]]; then
  cp "$src/tests/fuzz/regressions/$target"/* "$work/seeds/" 2>/dev/null || true
fi

exec "$bin" -max_total_time="$secs" -rss_limit_mb=2048 -timeout=5 -max_len=65536 \
  -print_final_stats=1 -artifact_prefix="$work/artifacts/" "$@" "$work/corpus" "$work/seeds"
