#!/usr/bin/env bash
# Cost of one training step against M (= K), on 1 and 2 threads, with the
# piece-by-piece breakdown and the SGEMM bound of the same shapes, into a CSV
# and a log-log PNG.   bench/scaling.sh OUT_DIR [extra bench_iteration flags]
set -euo pipefail
out="$1"; shift
b="$(dirname "$0")/../build"
mkdir -p "$out"
rm -f "$out/scaling.csv"
for t in 1 2; do
  for m in ${POINTS:-1000 2500 5000 10000 20000}; do
    "$b/bench_iteration" --points "$m" --gaussians "$m" --threads "$t" --runs "${RUNS:-3}" --csv "$out/scaling.csv" "$@"
  done
done
"$b/bench_scaling_plot" "$out/scaling.csv" "$out/scaling.png"
echo "written: $out/scaling.csv $out/scaling.png"
