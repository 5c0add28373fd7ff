#!/usr/bin/env bash
# The benchmark harness (issue 7), one command:   bench/harness.sh OUT_DIR
#
#  1. bench_iteration at the default (M = K = 2500, 5x128) and the paper
#     (M = K = 10^4, 5x256) configurations: the step, its pieces, the SGEMM
#     bound of the same shapes and the peak memory;
#  1b. bench_sgemm_blas: the step's SGEMMs through Eigen and through each BLAS
#     Debian ships that is installed (OpenBLAS, BLIS, reference; loaded at run
#     time), with the machine's OPENBLAS_* environment as it is (what jsatlas
#     would get) and unset (OpenBLAS's own kernel choice);
#  2. bench_kernels: Chamfer 6D/2D, repulsion, exact assignment, each validated,
#     with its inputs dumped for the SciPy peer;
#  3. if /usr/bin/python3 imports torch: bench/peer_torch.py, self-test first,
#     then both forms at both configurations, on OpenBLAS-openmp with
#     OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE unset (for that command only);
#  4. if it imports scipy: bench/peer_scipy.py on the dumped inputs;
#  5. SCALING=1: bench/scaling.sh as well;
# then OUT_DIR/report.md: the machine, every ratio, the kernel comparisons.
#
# Environment: THREADS (2), RUNS (5, medians of C++ runs and SciPy runs),
# ITERS / WARMUP (5 / 2, torch iterations), CONFIGS ("name:M:K:width:depth ...",
# for a quick check with small sizes), KERNEL_FLAGS (extra bench_kernels flags,
# e.g. "--points 2000 --gaussians 2000 --n 300"), BUILD (build directory),
# NO_BUILD=1 (do not bring the bench targets up to date first), JOBS (build jobs),
# ITER_FLAGS (extra bench_iteration flags, e.g. "--softplus 40" for the default
# fit's activation; the peers stay ReLU, so the torch ratios are then not like for like).
set -euo pipefail
[ $# -eq 1 ] || { echo "usage: $0 OUT_DIR" >&2; exit 2; }
out="$1"
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/.." && pwd)"
b="${BUILD:-$root/build}"
threads="${THREADS:-2}"
runs="${RUNS:-5}"
iters="${ITERS:-5}"
warmup="${WARMUP:-2}"
configs="${CONFIGS:-default:2500:2500:128:5 paper:10000:10000:256:5}"
py=/usr/bin/python3
blas_dir=/usr/lib/x86_64-linux-gnu/openblas-openmp
# The peer's process environment: the OpenMP build of OpenBLAS, its own kernel choice.
peer_env=(env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE "LD_LIBRARY_PATH=$blas_dir" "OMP_NUM_THREADS=$threads")

load_start="$(cut -d' ' -f1-3 /proc/loadavg)"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
rm -f "$out/iteration.csv" "$out/peer_torch.json" "$out/peer_scipy.json"
section() { printf '\n==== %s\n' "$*"; }

if [ "${NO_BUILD:-0}" != 1 ]; then
  section "build"
  cmake --build "$b" -j"${JOBS:-$(nproc)}" --target bench_iteration bench_kernels bench_scaling_plot \
    bench_sgemm_blas
fi

# ---- 1. ours, per configuration
for c in $configs; do
  IFS=: read -r name m k w d <<< "$c"
  section "bench_iteration $name: M=$m K=$k ${d}x$w, $threads threads"
  "$b/bench_iteration" --points "$m" --gaussians "$k" --width "$w" --depth "$d" \
    --threads "$threads" --runs "$runs" --csv "$out/iteration.csv" ${ITER_FLAGS:-} | tee "$out/iteration_$name.log"
done

# ---- 1b. the SGEMM choice: Eigen against the BLAS libraries installed
blas_libs=()
for lib in openblas-openmp/libblas.so.3 blis-openmp/libblas.so.3 blas/libblas.so.3; do
  [ -e "/usr/lib/x86_64-linux-gnu/$lib" ] && blas_libs+=(--blas "/usr/lib/x86_64-linux-gnu/$lib")
done
section "bench_sgemm_blas, machine environment (OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset})"
"$b/bench_sgemm_blas" --threads "$threads" --runs "$runs" "${blas_libs[@]}" | tee "$out/sgemm_blas.log"
section "bench_sgemm_blas, OPENBLAS_* unset"
env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE "$b/bench_sgemm_blas" --threads "$threads" \
  --runs "$runs" "${blas_libs[@]}" | tee "$out/sgemm_blas_unset.log"

# ---- 2. kernels, inputs dumped for the SciPy peer
section "bench_kernels"
mkdir -p "$out/kernels"
# shellcheck disable=SC2086  # KERNEL_FLAGS is a list of flags
"$b/bench_kernels" --threads "$threads" --runs "$runs" --dump "$out/kernels" ${KERNEL_FLAGS:-} \
  | tee "$out/kernels.log"

# ---- 3. the PyTorch peer
have_torch=0
if [ -x "$py" ] && "${peer_env[@]}" "$py" -c 'import torch' 2>/dev/null; then
  have_torch=1
  [ -d "$blas_dir" ] || echo "WARNING: $blas_dir missing (apt install libopenblas0-openmp): the peer runs on a slower BLAS" >&2
  section "peer_torch self-test"
  "${peer_env[@]}" "$py" "$here/peer_torch.py" --selftest --threads "$threads" | tee "$out/peer_torch_selftest.log"
  for c in $configs; do
    IFS=: read -r name m k w d <<< "$c"
    section "peer_torch $name: M=$m K=$k ${d}x$w"
    "${peer_env[@]}" "$py" "$here/peer_torch.py" --form both --points "$m" --gaussians "$k" --width "$w" \
      --depth "$d" --threads "$threads" --iters "$iters" --warmup "$warmup" --json "$out/peer_torch.json" \
      | tee "$out/peer_torch_$name.log"
  done
else
  section "peer_torch skipped: $py cannot import torch (apt install python3-torch libopenblas0-openmp)"
fi

# ---- 4. the SciPy peer
have_scipy=0
if [ -x "$py" ] && "$py" -c 'import scipy.spatial, scipy.optimize' 2>/dev/null; then
  have_scipy=1
  section "peer_scipy"
  OMP_NUM_THREADS="$threads" "$py" "$here/peer_scipy.py" "$out/kernels" --workers "$threads" --runs "$runs" \
    --json "$out/peer_scipy.json" | tee "$out/peer_scipy.log"
else
  section "peer_scipy skipped: $py cannot import scipy (apt install python3-scipy)"
fi

# ---- 5. scaling
if [ "${SCALING:-0}" = 1 ]; then
  section "scaling"
  "$here/scaling.sh" "$out/scaling" | tee "$out/scaling.log"
fi

# ---- report
# json_field LINE KEY: the value of a flat "KEY": value in one JSON line.
json_field() { printf '%s\n' "$1" | sed -n "s/.*\"$2\": \"\{0,1\}\([^\",}]*\)\"\{0,1\}[,}].*/\1/p"; }
# peer_seconds FORM M K W D: the torch peer's median seconds for that form and configuration.
peer_seconds() {
  [ -f "$out/peer_torch.json" ] || return 0
  awk -v f="$1" -v m="$2" -v k="$3" -v w="$4" -v d="$5" -v t="$threads" '
    index($0, "\"form\": \"" f "\"") && index($0, "\"points\": " m ",") && index($0, "\"gaussians\": " k ",") &&
    index($0, "\"width\": " w ",") && index($0, "\"depth\": " d ",") && index($0, "\"threads\": " t ",") { line = $0 }
    END { if (match(line, /"median_s": [^,}]*/)) print substr(line, RSTART + 12, RLENGTH - 12) }' "$out/peer_torch.json"
}
seconds() { awk -v s="$1" 'BEGIN { if (s == "") print "n/a"; else printf "%.3f", s }'; }
ratio() { awk -v a="$1" -v b="$2" 'BEGIN { if (a == "" || b == "" || b + 0 == 0) print "n/a"; else printf "%.2f", a / b }'; }

cpu="$(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')"
commit="$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)"
git -C "$root" diff --quiet HEAD 2>/dev/null || commit="$commit (with uncommitted changes)"
build_type="$(sed -n 's/^CMAKE_BUILD_TYPE:STRING=//p' "$b/CMakeCache.txt" 2>/dev/null || true)"
{
  echo "# Benchmark report"
  echo
  echo "Command: \`bench/harness.sh $1\`$( [ "${SCALING:-0}" = 1 ] && echo ' with SCALING=1')"
  echo
  echo "Machine: $cpu, $(nproc) cores, $(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo);" \
       "$(date -u '+%Y-%m-%d %H:%M UTC'); load average before the run $load_start (near 0 on a quiet machine);" \
       "commit $commit; build ${build_type:-?}; $threads threads;" \
       "medians of $runs runs (C++, SciPy), of $iters iterations after $warmup (torch)."
  echo
  echo "## One training iteration (full method, Table 1 row 11)"
  echo
  echo "Ours: \`bench_iteration\` (\`Trainer::step()\`); bound: the same-run Eigen SGEMM of the MLP shapes."
  echo "Peer: \`bench/peer_torch.py\`, PyTorch on the same 2 cores; ratio = peer seconds / ours (above 1: ours faster)."
  echo
  echo "| config | M | K | MLP | ours step ms | SGEMM bound ms | step / bound | repulsion share | peak MB | torch best s | best / ours | torch authors s | authors / ours |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
  for c in $configs; do
    IFS=: read -r name m k w d <<< "$c"
    row="$(awk -F, -v m="$m" -v k="$k" -v w="$w" -v d="$d" -v t="$threads" '
      NR == 1 { for (i = 1; i <= NF; ++i) col[$i] = i; next }
      $col["points"] == m && $col["gaussians"] == k && $col["width"] == w && $col["depth"] == d && $col["threads"] == t {
        line = $0 }
      END { if (line == "") exit; split(line, f, ",");
        printf "%s %s %s %s", f[col["step_ms"]], f[col["gemm_ms"]], f[col["repulsion_ms"]], f[col["peak_mb"]] }' \
      "$out/iteration.csv")"
    read -r step gemm rep peak <<< "${row:-   }"
    best="$(peer_seconds best "$m" "$k" "$w" "$d")"
    authors="$(peer_seconds authors "$m" "$k" "$w" "$d")"
    step_s="$(awk -v s="${step:-}" 'BEGIN { if (s != "") printf "%.6f", s / 1000 }')"
    printf '| %s | %s | %s | %sx%s | %.1f | %.1f | %s | %s%% | %.0f | %s | %s | %s | %s |\n' \
      "$name" "$m" "$k" "$d" "$w" "${step:-0}" "${gemm:-0}" "$(ratio "${step:-}" "${gemm:-}")" \
      "$(awk -v r="${rep:-}" -v s="${step:-}" 'BEGIN { if (s + 0 > 0) printf "%.1f", 100 * r / s; else print "n/a" }')" \
      "${peak:-0}" "$(seconds "$best")" "$(ratio "$best" "$step_s")" "$(seconds "$authors")" "$(ratio "$authors" "$step_s")"
  done
  echo
  echo "Pieces per configuration (ours):"
  echo
  echo '```'
  for c in $configs; do
    IFS=: read -r name _ <<< "$c"
    sed -n '/^full method/,$p' "$out/iteration_$name.log"
  done
  echo '```'
  if [ "$have_torch" = 1 ]; then
    echo
    echo "Peer: \`$(grep -m1 '^torch ' "$out/peer_torch_selftest.log")\`; BLAS as loaded by the peer:"
    echo
    echo '```'
    grep -A2 '^OpenBLAS:' "$out/peer_torch_selftest.log" || grep '^BLAS libraries' "$out/peer_torch_selftest.log"
    grep -h 'CPU capability usage' "$out/peer_torch_selftest.log" | sed 's/^ *- //' | head -n 1
    grep -h '^WARNING' "$out"/peer_torch_*.log | sort -u || true
    grep -h 'selftest' "$out/peer_torch_selftest.log" | tail -n 1
    for c in $configs; do grep -h 'median' "$out/peer_torch_${c%%:*}.log"; done
    echo '```'
  fi
  echo
  echo "## Kernels"
  echo
  echo '```'
  cat "$out/kernels.log"
  echo '```'
  if [ "$have_scipy" = 1 ]; then
    echo
    echo "Against SciPy on the same inputs (ratio = ours / scipy seconds; below 1: ours faster):"
    echo
    echo "| kernel | size | same value | ours s | scipy s | ours / scipy |"
    echo "|---|---|---|---|---|---|"
    while IFS= read -r line; do
      ours_s="$(json_field "$line" ours_s)" peer_s="$(json_field "$line" median_s)"
      printf '| %s | %s | %s | %.4f | %.4f | %s |\n' "$(json_field "$line" kernel)" \
        "$(json_field "$line" size)" "$(json_field "$line" same)" "$ours_s" "$peer_s" "$(ratio "$ours_s" "$peer_s")"
    done < "$out/peer_scipy.json"
    echo
    echo '```'
    cat "$out/peer_scipy.log"
    echo '```'
  fi
  echo
  echo "## The step's SGEMMs: Eigen against the installed BLAS libraries (GFLOP/s)"
  echo
  echo "Machine environment (OPENBLAS_CORETYPE=${OPENBLAS_CORETYPE:-unset}):"
  echo '```'
  cat "$out/sgemm_blas.log"
  echo '```'
  echo "OPENBLAS_CORETYPE and OPENBLAS_L2_SIZE unset:"
  echo '```'
  cat "$out/sgemm_blas_unset.log"
  echo '```'
  if [ "${SCALING:-0}" = 1 ]; then
    echo
    echo "## Scaling (M = K, bench/scaling.sh)"
    echo
    awk -F, 'NR == 1 { printf "|"; for (i = 1; i <= NF; ++i) printf " %s |", $i; printf "\n|";
                        for (i = 1; i <= NF; ++i) printf "---|"; printf "\n"; next }
             { printf "|"; for (i = 1; i <= NF; ++i) printf " %s |", $i; printf "\n" }' "$out/scaling/scaling.csv"
    echo
    echo "![scaling](scaling/scaling.png)"
  fi
} > "$out/report.md"
section "report: $out/report.md"
cat "$out/report.md"
