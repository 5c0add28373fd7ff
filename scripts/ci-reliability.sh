#!/usr/bin/env bash
# Reliability CI (issue 8): (a) the whole test suite under AddressSanitizer +
# UndefinedBehaviorSanitizer, (b) each libFuzzer target for a bounded time on its
# seed corpus (test/fuzz/corpus/<target>), deterministically (fixed seed and
# number of inputs). Prints how long each step took.
# Builds in build-asan/ and build-fuzz/, both with clang-14; installs clang-14,
# its sanitizer runtime (libclang-rt-14-dev) and its OpenMP runtime
# (libomp-14-dev, not a dependency of clang-14) when missing. FUZZ_SECONDS sets the time cap per target (default 60; the input count, 30000, usually ends a run first).
set -euo pipefail
cd "$(dirname "$0")/.."
fuzz_seconds="${FUZZ_SECONDS:-60}"
# A fixed seed and a fixed number of inputs: CI replays exactly the inputs that
# were fuzzed before the commit, so it cannot turn red on a new random find;
# longer exploratory runs: FUZZ_RUNS=-1 FUZZ_SECONDS=600.
fuzz_runs="${FUZZ_RUNS:-30000}"
jobs=2

# "step NAME COMMAND...": runs COMMAND, then prints NAME and its wall time.
step() {
  local name="$1" start=$SECONDS
  shift
  "$@"
  echo "ci-reliability: $name took $((SECONDS - start)) s"
}

install_clang() {
  local missing=()
  for p in clang-14 libclang-rt-14-dev libomp-14-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  echo "ci-reliability: installing ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
}

# Built by clang-14, -O1, no benchmarks: the build is most of this script's
# time, and GCC 12 with -fsanitize=address,undefined took 2169 s on a 2-core
# machine (about 30 s an object) where clang-14 builds 80 of its 142 objects
# in 372 s, the same tests under the same two sanitizers (2026-12-04). No BLAS
# backend (a library of its own, not ours to check; with it off `--gemm blas`
# is the clear error its tests expect). No MPI: OpenMPI's own allocations
# would read as leaks (the mpirun tests run in the main build).
build_asan() {
  cmake -S . -B build-asan -DJSATLAS_SANITIZE=ON -DJSATLAS_MPI=OFF -DJSATLAS_BLAS=OFF -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo -DJSATLAS_BUILD_BENCH=OFF "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" > /dev/null
  cmake --build build-asan -j "$jobs"
}

# Left out of the sanitizer run: long training loops whose code shorter tests
# also run under the sanitizers, and what is not ours to check (2026-12-02,
# ASan seconds on a 2-core machine, all tests 363 s at -j2):
#   texture transfer of a 3-shape collection (79 s; the collection fit, the
#     valid-UV pipeline and the texture outputs run in "fit writes every output"
#     and the geometry room's tests), reseed_flipped_means on a flipped half
#     (75 s; "moving flipped Gaussians is reported" runs the reseed),
#     wrap_initialize (67 s; "the starting wrap is reported" runs the wrap),
#     the examples (40 s; the library calls they make are tested), the
#     find_package consumer (a CMake build) and the browser test (Chromium).
asan_skip='(texture transfer|reseed_flipped_means: a flipped half|wrap_initialize: phi lands|^example_|^find_package_consumer$|^browser:)'

test_asan() {
  # halt_on_error: the first report fails the test; leaks are reported too.
  ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -E "$asan_skip"
}

# No BLAS backend either: OpenBLAS's OpenMP build brings GCC's OpenMP runtime
# (libgomp), which would sit beside clang's (libomp) in one process; the fuzz
# targets read files and never multiply.
build_fuzz() {
  cmake -S . -B build-fuzz -DJSATLAS_FUZZ=ON -DJSATLAS_MPI=OFF -DJSATLAS_BLAS=OFF -DCMAKE_CXX_COMPILER=clang++-14 \
    -DJSATLAS_BUILD_TESTS=OFF -DJSATLAS_BUILD_BENCH=OFF -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" > /dev/null
  cmake --build build-fuzz -j "$jobs" --target fuzz
}

# Fuzzes one target; new inputs go to a scratch corpus, the seeds stay as they are.
# A crash, a timeout (>10 s on one input), 2 GB of memory or a sanitizer report
# fails the step; the input is kept as build-fuzz/artifacts/<target>/crash-*.
run_fuzzer() {
  local target="$1"
  local scratch="build-fuzz/corpus/$target" artifacts="build-fuzz/artifacts/$target"
  mkdir -p "$scratch" "$artifacts"
  "build-fuzz/test/fuzz/$target" "$scratch" "test/fuzz/corpus/$target" \
    -seed=1 -runs="$fuzz_runs" -max_total_time="$fuzz_seconds" -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="$artifacts/" -print_final_stats=1 > "build-fuzz/$target.log" 2>&1 || {
    tail -n 60 "build-fuzz/$target.log"
    echo "ci-reliability: $target found a bug; the input is in $artifacts/"
    return 1
  }
  grep -E "^#[0-9]+[[:space:]]+DONE" "build-fuzz/$target.log" || true
}

total_start=$SECONDS
step "clang install check" install_clang
step "sanitizer build" build_asan
step "sanitizer tests" test_asan
step "fuzz build" build_fuzz
for target in fuzz_read_obj fuzz_read_off fuzz_read_ply fuzz_read_xyz fuzz_read_keypoints \
              fuzz_read_checkpoint fuzz_fit_config; do
  step "$target (${fuzz_runs} inputs, seed 1)" run_fuzzer "$target"
done
echo "ci-reliability: all steps took $((SECONDS - total_start)) s"
