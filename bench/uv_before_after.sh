#!/usr/bin/env bash
# The UV report of psi alone and of the valid map, for fitted runs, with two
# builds side by side (docs/uv-quality.md, "Before and after on trained fits"):
#   FITS=DIR OUT=DIR SHAPES="teddy_1 ant_1 ..." NEW=build/jsatlas OLD=old/jsatlas bench/uv_before_after.sh
#   python3 bench/uv_table.py OUT teddy_1 ant_1 ...      # the markdown table
set -e
: "${FITS:?runs directory (FITS/SHAPE holds a fit)}" "${OUT:?output directory}" "${SHAPES:?run names}"
NEW=${NEW:-build/jsatlas}
mkdir -p "$OUT"
for s in $SHAPES; do
  "$NEW" chart "$FITS/$s" -o "$OUT/${s}_psi.obj" --psi-only --threads 2 -q
  [ -n "$OLD" ] && "$OLD" chart "$FITS/$s" -o "$OUT/${s}_landed.obj" --threads 2 -q
  "$NEW" chart "$FITS/$s" -o "$OUT/${s}_now.obj" --threads 2 -q
done
