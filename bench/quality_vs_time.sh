#!/usr/bin/env bash
# Quality of `jsatlas fit` against its time budget, for several schedules,
# shapes and seeds: each fit runs with --minutes T (the schedule follows the
# length that fills T) and `jsatlas eval` scores it (Chamfer, unit normals and
# EMD on 2000 fresh samples each side, as ratios to the sampling floor).
#   bench/quality_vs_time.sh OUT_DIR MESH... [-- extra fit flags]
# Environment: MINUTES (default "1 2 5 10"), SCHEDULES (default "ramp step":
# the default and the previous one), SEEDS (default "1"), JOBS (fits at a time,
# default 1; with JOBS > 1 give --threads 1 among the extra flags). Under a
# short budget a single shape's fit takes a smaller M (`--min-steps`): the
# table's M column says which; give `--min-steps 0` to keep M.
# Writes OUT_DIR/quality.csv, OUT_DIR/quality.md (a table per shape) and, when
# bench_quality_plot is built, OUT_DIR/quality_chamfer.png, quality_normals.png and quality_emd.png.
set -euo pipefail
out="$1"; shift
meshes=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do meshes+=("$1"); shift; done
[ "${1:-}" = "--" ] && shift
here="$(cd "$(dirname "$0")" && pwd)"
bin="$here/../build/jsatlas"
mkdir -p "$out"
csv="$out/quality.csv"
[ -f "$csv" ] || echo "schedule,shape,seed,minutes,wall_s,iterations,chamfer_ratio,normal_ratio,emd_ratio,chamfer,normal,emd,load,points" > "$csv"

one() {  # schedule mesh seed minutes extra...
  local sched="$1" mesh="$2" seed="$3" m="$4"; shift 4
  local shape; shape="$(basename "$mesh")"; shape="${shape%.*}"; shape="${shape#builtin:}"
  local run="$out/$sched/$shape/s$seed/min$m"
  mkdir -p "$run"
  local load; load=$(cut -d' ' -f1 /proc/loadavg)
  local start end
  start=$(date +%s.%N)
  "$bin" fit "$mesh" -o "$run" --schedule "$sched" --seed "$seed" --minutes "$m" --checkpoint-every 0 -q "$@"
  end=$(date +%s.%N)
  "$bin" eval "$run" > "$run/eval.txt"
  python3 - "$run" "$sched" "$shape" "$seed" "$m" "$start" "$end" "$load" >> "$csv" <<'PY'
import json, sys
run, sched, shape, seed, m, s, e, load = sys.argv[1:9]
j = json.load(open(run + "/eval.json")); c = json.load(open(run + "/config.json"))
r = lambda k: j[k] / j["floor_" + k]
print(f"{sched},{shape},{seed},{m},{float(e) - float(s):.1f},{c['settings']['iterations']},"
      f"{r('chamfer_spatial'):.4f},{r('chamfer_normal_unit'):.4f},{r('emd_spatial'):.4f},"
      f"{j['chamfer_spatial']:.6g},{j['chamfer_normal_unit']:.6g},{j['emd_spatial']:.6g},{load},"
      f"{c['settings']['points']}")
PY
}

jobs_max="${JOBS:-1}"
for m in ${MINUTES:-1 2 5 10}; do
  for mesh in "${meshes[@]}"; do
    for seed in ${SEEDS:-1}; do
      for sched in ${SCHEDULES:-ramp step}; do
        while [ "$(jobs -rp | wc -l)" -ge "$jobs_max" ]; do wait -n; done
        one "$sched" "$mesh" "$seed" "$m" "$@" &
      done
    done
  done
done
wait

python3 - "$csv" > "$out/quality.md" <<'PY'
import csv, sys, collections
rows = list(csv.DictReader(open(sys.argv[1])))
by = collections.defaultdict(list)
for r in rows: by[r["shape"]].append(r)
for shape, rs in by.items():
    print(f"\n{shape} (ratios to the sampling floor; load = 1-minute load average at the start)\n")
    print("| budget | schedule | seed | steps | M | Chamfer | unit normals | EMD | wall s | load |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in sorted(rs, key=lambda r: (float(r["minutes"]), r["schedule"], r["seed"])):
        print(f"| {r['minutes']} min | {r['schedule']} | {r['seed']} | {r['iterations']} | {r.get('points') or '-'} | {float(r['chamfer_ratio']):.2f} | "
              f"{float(r['normal_ratio']):.2f} | {float(r['emd_ratio']):.2f} | {float(r['wall_s']):.0f} | {r['load']} |")
PY
cat "$out/quality.md"
plot="$here/../build/bench_quality_plot"
[ -x "$plot" ] && "$plot" "$csv" "$out/quality"
exit 0
