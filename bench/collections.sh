#!/usr/bin/env bash
# Joint atlases of SHREC categories (issue 5's evaluation): for each category,
# fits the collection with the full method (Table 1 row 11) and without the
# chart (row 9), then reports the correspondence error over the .vts keypoints
# (x 1e-2, unit frame of the target), the reconstruction of every shape, and
# the wall time of each fit. Two fits run at a time, one thread each.
#   bench/collections.sh SHREC_DIR OUT_DIR [extra fit flags...]
#   CATEGORIES="ant teddy" SHAPES="1 2 3 4" MINUTES=14 (the defaults)
set -euo pipefail
shrec="$1"; out="$2"; shift 2
bin="$(cd "$(dirname "$0")/.." && pwd)/build/jsatlas"
mkdir -p "$out"
fit_one() {  # category row [extra fit flags...]
  local c="$1" row="$2" run="$out/$1_row$2" inputs=()
  shift 2
  for i in ${SHAPES:-1 2 3 4}; do inputs+=("$shrec/${c}_$i.obj"); done
  local start end
  start=$(date +%s.%N)
  "$bin" fit "${inputs[@]}" -o "$run" --table-row "$row" --minutes "${MINUTES:-14}" --threads 1 \
    --checkpoint-every 0 -q "$@" > "$run.log" 2>&1
  end=$(date +%s.%N)
  echo "$start $end" > "$run.time"
}
for c in ${CATEGORIES:-ant teddy}; do
  fit_one "$c" 11 "$@" &
  fit_one "$c" 9 "$@" &
  wait
done
echo "| category | method | fit wall s | iterations | corr. L2 x1e-2 | within 0.05 | Chamfer x1e-2 per shape (floor) | normal x1e-2 per shape (floor) |"
echo "|---|---|---|---|---|---|---|---|"
for c in ${CATEGORIES:-ant teddy}; do
  for row in 11 9; do
    run="$out/${c}_row$row"
    "$bin" eval-corr "$run" --keypoints "$shrec" --threads 2 > "$run/corr.txt"
    n=$(ls -d "$run"/shape_* | wc -l)
    for ((i = 0; i < n; ++i)); do "$bin" eval "$run" --shape "$i" --threads 2 > /dev/null; done
    python3 - "$run" "$c" "$row" "$n" <<'PY'
import json, sys
run, c, row, n = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
s, e = map(float, open(run + ".time").read().split())
cfg = json.load(open(run + "/config.json"))
corr = json.load(open(run + "/eval_corr.json"))
within = dict(zip(corr["thresholds"], corr["within"]))
ch, nr = [], []
for i in range(n):
    j = json.load(open(f"{run}/eval_{i}.json"))
    ch.append(f"{100*j['chamfer_spatial']:.2f} ({100*j['floor_chamfer_spatial']:.2f})")
    nr.append(f"{100*j['chamfer_normal_unit']:.1f} ({100*j['floor_chamfer_normal_unit']:.1f})")
name = "full (row 11)" if row == "11" else "no chart (row 9)"
print(f"| {c} | {name} | {e - s:.0f} | {cfg['settings']['iterations']} | {corr['mean_l2_x1e-2']:.2f} | "
      f"{100 * within[0.05]:.0f}% | {'; '.join(ch)} | {'; '.join(nr)} |")
PY
  done
done
