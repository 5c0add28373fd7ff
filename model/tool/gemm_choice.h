// `jsatlas fit --gemm auto`: which backend runs a run's float GEMMs
// (engine/gemm.h), chosen by timing both on the products of one of the run's
// own steps (engine/gemm_timing.h), and remembered per machine.
//
// Why remembered: a seed and a thread count give the same numbers on one
// machine only with the same backend (the two round differently), and a
// timing is noisy: two runs measuring afresh could choose differently when
// the backends are close. So the first run with a configuration measures and
// stores its choice in a cache file, keyed by the CPU model, the thread count,
// the BLAS library and the step's products (their shapes and threads); every
// later run with that key reads it. Concurrent first runs take a lock on the
// file, so one measures and the others read its answer. Where nothing can be
// remembered (no cache: JSATLAS_GEMM_CACHE=off, as in the tests, or no home
// directory) `auto` is Eigen, unmeasured: a choice is made only if it stays
// made. The run's backend is saved in its settings (config.json, checkpoint),
// so a resumed run keeps it, and `--gemm eigen|blas` repeats it anywhere.
// Deleting the cache file measures again (and may choose otherwise).
#pragma once
#include <string>
#include <vector>

#include "engine/gemm_timing.h"
#include "model/tool/trainer.h"

namespace jsa {

struct GemmChoice {
  Gemm gemm = Gemm::eigen;
  GemmTiming timing;   // of the step's products (zeros when not measured)
  std::string source;  // "measured", "cache", or why nothing was measured
  std::string cache;   // the cache file ("" for none)
  std::string key;     // the cache key (empty when not measured)
  bool saved = false;  // this run measured it and stored it in the cache
};

// The cache file: $JSATLAS_GEMM_CACHE (a path; "off" or "" for none), else
// $XDG_CACHE_HOME/jsatlas/gemm.json, else $HOME/.cache/jsatlas/gemm.json;
// "" when there is no home either.
std::string gemm_cache_path();

// The float GEMMs of one step of a run with options o over `shapes` shapes, as
// recorded from one step of a throwaway trainer (the run's networks, M and
// threads; samples of a sphere as every shape, a fixed M, no wrap, template or
// heuristics: the products' shapes do not depend on them).
std::vector<GemmCall> step_gemm_calls(const FitOptions& o, int shapes);

// The backend for such a run (the header comment): Eigen without a BLAS or
// without a usable cache (its folder or lock cannot be made, it cannot be
// written: `source` says which); else the cache's answer for this key, or a
// measurement (kGemmMargin's rule) that is then stored. A cache file that is
// not one (not JSON of this layout) is replaced.
GemmChoice choose_gemm(const FitOptions& o, int shapes, const std::string& cache_path);

// One line for the fit's progress output: the backend, the timings and where they came from.
std::string describe(const GemmChoice& c);

}  // namespace jsa
