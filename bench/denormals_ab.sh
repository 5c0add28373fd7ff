#!/usr/bin/env bash
# Denormal floats kept (JSATLAS_KEEP_DENORMALS=1) against flushed (the default),
# in pairs run back to back: the same binary, seed and thread, a four-shape
# collection; prints the template start's time and the joint steps' rate from
# the fit's own log (docs/performance.md, "Denormal floats").
#   bench/denormals_ab.sh JSATLAS SHREC_DIR [TEMPLATE_STEPS [PAIRS]]
set -euo pipefail
jsatlas="${1:?usage: bench/denormals_ab.sh JSATLAS SHREC_DIR [TEMPLATE_STEPS [PAIRS]]}"
shrec="${2:?usage: bench/denormals_ab.sh JSATLAS SHREC_DIR [TEMPLATE_STEPS [PAIRS]]}"
steps="${3:-1500}"
pairs="${4:-2}"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
for pair in $(seq "$pairs"); do
  for mode in kept flushed; do
    keep=()
    [ "$mode" = kept ] && keep=(JSATLAS_KEEP_DENORMALS=1)
    env "${keep[@]}" "$jsatlas" fit "$shrec"/ant_{1,2,3,4}.obj -o "$out/$mode$pair" --threads 1 \
      --template-steps "$steps" --iters 40 --checkpoint-every 0 --no-align --seed 1 2>&1 |
      grep -E "template start|it +40/40" | cut -c1-100 | sed "s/^/$mode, pair $pair: /"
  done
done
