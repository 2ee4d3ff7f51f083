#!/bin/bash
# Robustness sweep over random PLCs (session 36; bench/RESULTS.md "Session 36").
#
#   bench/svrc/random_sweep.sh BUILD KIND FROM TO [svrc_plc_check options]
#
# For each seed FROM..TO: bench/svrc/random_plcs.py writes a PLC of KIND,
# `svrc validate` skips the invalid ones, and svrc_plc_check meshes it and
# checks every output property (600 s limit). One line per seed:
#   KIND SEED creases=<crease segments> sharpest=<degrees> spread=<Δ> t=<seconds> <check's line>
# BUILD is a build directory configured with -DSVRC_BUILD_BENCH=ON. The PLCs
# are left in $SWEEP_DIR (default: a new temporary directory, printed first).
set -u
if [ $# -lt 4 ]; then
  sed -n 2,12p "$0"
  exit 2
fi
build=$1 kind=$2 from=$3 to=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
dir=${SWEEP_DIR:-$(mktemp -d /tmp/svrc_sweep.XXXXXX)}
mkdir -p "$dir"
echo "# PLCs in $dir" >&2
for seed in $(seq "$from" "$to"); do
  f=$dir/${kind}_$seed.poly
  python3 "$here/random_plcs.py" "$kind" "$seed" "$f"
  v=$("$build/client/svrc" validate "$f" 2>&1)
  if ! grep -q '^VALID' <<<"$v"; then
    echo "$kind $seed INVALID"
    continue
  fi
  creases=$(awk '/^creases/ {print $2}' <<<"$v")
  spread=$(awk '/^spread/ {print $2}' <<<"$v")
  sharpest=$(awk '/^sharpest/ {print $2}' <<<"$v")
  t0=$(date +%s.%N)
  r=$(timeout 600 "$build/bench/svrc/svrc_plc_check" "$f" "$@" 2>&1 | tail -1)
  t1=$(date +%s.%N)
  printf '%s %s creases=%s sharpest=%s spread=%s t=%.1f %s\n' "$kind" "$seed" "$creases" "${sharpest:--}" "$spread" \
    "$(echo "$t1 - $t0" | bc)" "${r:-TIMEOUT}"
done
