#!/bin/bash
# The two COLLAR criteria side by side on the crease inputs: the angle test
# (sigma 60, the default) and the simple size criterion of the thesis' Ch. 6
# (--collar-size-eps 0.3). One run each; prints a Markdown table
# (docs/svrc-collars.md "Session 16"). Needs a release build with the bench
# targets (the families are written by svrc_plc_bench).
#   bench/svrc/collar_criteria.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
BUILD="${1:-$ROOT/build/release}"
SVRC="$BUILD/client/svrc"
C="${SVRC_CORPUS_DIR:-$ROOT/../shared/corpus}"
EPS="${EPS:-0.3}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
FAMILIES="crease_pair_30deg crease_pair_10deg crease_pair_5deg crease_pair_1deg segment_facet_1deg fan_8x5deg"
args=()
for f in $FAMILIES; do args+=(--family "$f"); done
"$BUILD/bench/svrc/svrc_plc_bench" --tools tetgen --radius-edge 2 --timeout 60 --workdir "$WORK/fam" --keep "${args[@]}" >/dev/null 2>&1 || true
IN="$C/c_creases/knife_edge.poly $C/c_creases/schonhardt.off $C/d_small_angles/segment_fan.poly $C/c_creases/wedge-1.smesh"
for f in $FAMILIES; do IN="$IN $(ls "$WORK"/fam/*_"$f"/*.poly)"; done
echo "| input | criterion | result | vertices | tets | CPU s | rounds | COLLAR repairs | stars+books (within the premises) | star sigma max | largest dihedral, stitched | largest dihedral, all tets | peak RSS MB |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for f in $IN; do
  for crit in "" "$EPS"; do
    flag=(); name="angle (sigma 60)"
    if [ -n "$crit" ]; then flag=(--collar-size-eps "$crit"); name="size $crit"; fi
    rc=0
    /usr/bin/time -f "%U %S %M" -o "$WORK/time" "$SVRC" mesh "$f" -o "$WORK/out.node" --stats "${flag[@]}" \
      >"$WORK/out" 2>"$WORK/err" || rc=$?
    read -r u s m < <(tail -1 "$WORK/time")
    g() { awk -v k="$1" '$1==k {print $2}' "$WORK/out"; }
    all=$(grep "^  dihedral (deg)" "$WORK/out" | awk '{print $NF}' || true)
    python3 - "$(basename "$f")" "$name" "$rc" "$u" "$s" "$m" "$(g output_vertices)" "$(g tets)" \
      "$(g svrc.collar_rounds)" "$(g svrc.collar_repairs)" "$(g svrc.stitch_stars)" "$(g svrc.stitch_books)" \
      "$(g svrc.stitch_bounded)" "$(g svrc.star_sigma_max_deg)" "$(g svrc.max_bounded_dihedral_deg)" \
      "$(g svrc.max_unbounded_dihedral_deg)" "$all" <<'PY'
import sys
(name, crit, rc, u, s, m, verts, tets, rounds, reps, stars, books, bounded, sig, mb, mu, allmax) = sys.argv[1:]
f = lambda x: float(x) if x else 0.0
print(f"| {name} | {crit} | {'ok' if rc == '0' else 'exit ' + rc} | {verts} | {tets} | {f(u) + f(s):.2f} | {rounds} | "
      f"{reps} | {int(f(stars) + f(books))} ({bounded}) | {f(sig):.1f} | {max(f(mb), f(mu)):.1f} | {allmax} | {int(f(m)) // 1024} |")
PY
  done
done
