#!/usr/bin/env bash
# The MPI tests of `jsatlas fit` (docs/mpi.md), one CTest test per mode:
#   reference    the 1-process fit of 4 builtin shapes (the others compare with it)
#   np2, np3     mpirun -np 2 / -np 3 (3 ranks on 4 shapes: an uneven split);
#                parameters within BOUND of the reference, relative to the largest
#   determinism  mpirun -np 2 a second time: bit-identical to np2's checkpoint
#   resume       -np 2 stopped at iteration 6, resumed with -np 3: within BOUND
#   batch        --batch-shapes 3 on 1 process and on 2 ranks: within BOUND
#   ramp         --schedule ramp (M 16, 32, 48, 64 over the first 9 of 12 steps) on 2
#                ranks, and on 2 ranks stopped at 3 (where M changes) and resumed on
#                1: within BOUND of the 1-process ramp (every rank draws the same M)
#   align        the pose step (--align) on 1 process and on 2 ranks: same rotations,
#                parameters within BOUND, on three boxes of unequal sides and the torus
#                (the other modes skip it: on the symmetric builtins it tries every axis
#                order and refines a pose that never settles, 46 s of a 50-s run; the
#                boxes' axes are defined, the torus keeps a tie of two axes: 2 s)
#   errors       more ranks than shapes, --wrap or --template-steps over 2 ranks: a one-line
#                error, the job ends non-zero
# Usage: run_tests.sh MODE JSATLAS COMPARE MPIEXEC WORKDIR BOUND
set -euo pipefail
mode=$1 jsatlas=$2 compare=$3 mpiexec=$4 work=$5 bound=$6
# No cache for `fit --gemm auto` (model/tool/gemm_choice.h): nothing written to
# the user's home, and every run on Eigen, as the 1-process reference.
export JSATLAS_GEMM_CACHE="${JSATLAS_GEMM_CACHE:-off}"
mkdir -p "$work"
cd "$work"
printf 'builtin:sphere\nbuiltin:torus\nbuiltin:cube\nbuiltin:capsule\n' > shapes.txt
# Small enough for seconds per run; orientation checks every 4 steps exercise its sum over ranks.
# The pose step runs on every rank; mode align compares it over ranks, the
# others skip it (--no-align). No template start (refused on more than one rank; its automatic
# length is 0 there) and shape 0 as L_metric's reference (the automatic medoid is
# shape 0 there): the 1-process reference must train the same way. L_metric held
# over all twelve steps (by default it ends at a quarter of the run). No
# registration (--auto-register: not over MPI yet, so not on the reference either).
fit=(fit --list shapes.txt --iters 12 -M 64 -K 64 --width 16 --depth 2 --code-size 8 --pool 2000
     --threads 1 --orient-every 4 --mesh-resolution 8 --checkpoint-every 0 --seed 5 -q
     --template-steps 0 --template-shape 0 --no-align --w-metric 1e-2 --w-metric-end -1
     --auto-register 0)
launch=("$mpiexec" --oversubscribe --bind-to none)
[ "$(id -u)" -eq 0 ] && launch+=(--allow-run-as-root)
run() {  # run NP ARGS...: one process without mpirun, else NP ranks
  local np=$1; shift
  if [ "$np" -eq 1 ]; then "$jsatlas" "$@"; else "${launch[@]}" -np "$np" "$jsatlas" "$@"; fi
}
case "$mode" in
  reference)
    rm -rf one && run 1 "${fit[@]}" -o one
    rm -rf one_batch && run 1 "${fit[@]}" --batch-shapes 3 -o one_batch ;;
  np2 | np3)
    np=${mode#np}
    rm -rf "$mode" && run "$np" "${fit[@]}" -o "$mode"
    "$compare" one/model.ckpt "$mode/model.ckpt" "$bound"
    # Rank 0 wrote every output of the collection.
    for i in 0 1 2 3; do test -s "$mode/shape_$i/domain_mesh.obj"; done
    test -s "$mode/losses.csv" ;;
  align)
    box() {  # box FILE SX SY SZ: a closed box of those sides, centred, 12 outward triangles
      awk -v sx="$2" -v sy="$3" -v sz="$4" 'BEGIN {
        for (i = 0; i < 8; i++)
          printf "v %g %g %g\n", (int(i / 4) - 0.5) * sx, (int(i / 2) % 2 - 0.5) * sy, (i % 2 - 0.5) * sz
        print "f 1 2 4\nf 1 4 3\nf 5 7 8\nf 5 8 6\nf 1 5 6\nf 1 6 2"
        print "f 3 4 8\nf 3 8 7\nf 1 3 7\nf 1 7 5\nf 2 6 8\nf 2 8 4" }' > "$1"
    }
    box box_a.obj 1 0.6 0.3 && box box_b.obj 0.9 0.7 0.35 && box box_c.obj 1.1 0.5 0.3
    printf '%s\n' "$PWD/box_a.obj" "$PWD/box_b.obj" builtin:torus "$PWD/box_c.obj" > align.txt
    posed=("${fit[@]}")
    posed[2]=align.txt  # --list's file
    rm -rf one_align && run 1 "${posed[@]}" --align -o one_align
    rm -rf np2_align && run 2 "${posed[@]}" --align -o np2_align
    "$compare" one_align/model.ckpt np2_align/model.ckpt "$bound"
    cmp one_align/rotations.json np2_align/rotations.json ;;
  determinism)
    rm -rf np2_again && run 2 "${fit[@]}" -o np2_again
    "$compare" np2/model.ckpt np2_again/model.ckpt
    cmp np2/model.ckpt np2_again/model.ckpt
    cmp np2/losses.csv np2_again/losses.csv ;;
  resume)
    rm -rf resumed && run 2 "${fit[@]}" --stop-at 6 -o resumed
    grep -q '^6,' resumed/losses.csv || { echo "resume: no row 6 in losses.csv"; exit 1; }
    run 3 fit --resume resumed -q
    "$compare" one/model.ckpt resumed/model.ckpt "$bound"
    # and back to one process from a 3-rank checkpoint
    rm -rf resumed1 && run 3 "${fit[@]}" --stop-at 9 -o resumed1
    run 1 fit --resume resumed1 -q
    "$compare" one/model.ckpt resumed1/model.ckpt "$bound" ;;
  ramp)
    rm -rf one_ramp && run 1 "${fit[@]}" --schedule ramp -o one_ramp
    rm -rf np2_ramp && run 2 "${fit[@]}" --schedule ramp -o np2_ramp
    "$compare" one_ramp/model.ckpt np2_ramp/model.ckpt "$bound"
    rm -rf ramp_resumed && run 2 "${fit[@]}" --schedule ramp --stop-at 3 -o ramp_resumed
    run 1 fit --resume ramp_resumed -q
    "$compare" one_ramp/model.ckpt ramp_resumed/model.ckpt "$bound" ;;
  batch)
    rm -rf np2_batch && run 2 "${fit[@]}" --batch-shapes 3 -o np2_batch
    "$compare" one_batch/model.ckpt np2_batch/model.ckpt "$bound" ;;
  errors)
    expect_error() {  # expect_error MESSAGE NP ARGS...: the job fails and names the reason
      local message=$1 np=$2; shift 2
      if run "$np" "$@" > err.txt 2>&1; then echo "errors: '$*' on $np ranks succeeded"; exit 1; fi
      grep -q -- "$message" err.txt || { echo "errors: no '$message' in:"; cat err.txt; exit 1; }
    }
    expect_error "2 MPI ranks for 1 shapes" 2 fit builtin:sphere -o too_many --iters 2 -q
    expect_error "--wrap is not supported with more than one MPI rank" 2 "${fit[@]}" --wrap 5 -o wrapped
    expect_error "--template-steps is not supported with more than one MPI rank" 2 fit --list \
      shapes.txt --iters 2 --template-steps 5 -o templated -q
    expect_error "--template-shape other than 0 is not supported with more than one MPI rank" 2 \
      fit --list shapes.txt --iters 2 --template-steps 0 --template-shape 2 -o other_template -q ;;
  *) echo "run_tests.sh: unknown mode $mode"; exit 2 ;;
esac
