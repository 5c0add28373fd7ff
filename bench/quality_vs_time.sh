#!/usr/bin/env bash
# Quality of `jsatlas fit` against its time budget: fits MESH with --minutes
# 1, 2, 5, 10 (each with its own learning-rate schedule) and evaluates each run
# (Chamfer and EMD on 2000 fresh samples each side, next to the sampling floor).
#   bench/quality_vs_time.sh MESH OUT_DIR [extra fit flags...]
set -euo pipefail
mesh="$1"; out="$2"; shift 2
bin="$(dirname "$0")/../build/jsatlas"
mkdir -p "$out"
echo "| budget | iterations | Chamfer x1e-2 (floor) | normal x1e-2 (floor) | EMD x1e-2 (floor) | wall s |"
echo "|---|---|---|---|---|---|"
for m in ${MINUTES:-1 2 5 10}; do
  run="$out/min$m"
  start=$(date +%s.%N)
  "$bin" fit "$mesh" -o "$run" --minutes "$m" --checkpoint-every 0 -q "$@"
  end=$(date +%s.%N)
  "$bin" eval "$run" > "$run/eval.txt"
  python3 - "$run" "$m" "$start" "$end" <<'PY'
import json, sys
run, m, s, e = sys.argv[1], sys.argv[2], float(sys.argv[3]), float(sys.argv[4])
j = json.load(open(run + "/eval.json")); c = json.load(open(run + "/config.json"))
f = lambda k: 100 * j[k]
print(f"| {m} min | {c['settings']['iterations']} | {f('chamfer_spatial'):.2f} ({f('floor_chamfer_spatial'):.2f}) | "
      f"{f('chamfer_normal_unit'):.1f} ({f('floor_chamfer_normal_unit'):.1f}) | "
      f"{f('emd_spatial'):.2f} ({f('floor_emd_spatial'):.2f}) | {e - s:.0f} |")
PY
done
