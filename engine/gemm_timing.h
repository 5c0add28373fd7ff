// Which GEMM backend (engine/gemm.h) is faster here, on a given list of
// products: a step's, as a GemmRecorder saw them. Validate, then time: both
// backends first compute each distinct product on the same data and must
// agree to float precision. Then, `repeats` times (after one round to warm
// up), each distinct product runs once through each backend, back to back,
// the order alternating between rounds, and its time counts as often as the
// list holds it: a round estimates the list's time by each backend at a
// fraction of its cost (a default step's 53 products are 12 distinct ones).
// Each backend's time is the fastest of its rounds: another process taking a
// core only ever slows a round down, so the fastest round is the one least
// disturbed. (The median chose OpenBLAS at 1373 against 346 ms on a host
// that was busy for most of a measurement, where the same list measured on
// the quiet host gives Eigen 336 against 340; the fits it was cached for
// then ran 10-20% slower. docs/performance.md, "The GEMMs' backend".)
// Products made inside an
// OpenMP team (the trainer's per-shape workers) are timed inside a team of
// the same size, each thread on its own products, so both backends run
// single-threaded with every core busy, as in the step; the team's time is
// its slowest thread's.
#pragma once
#include <vector>

#include "engine/gemm.h"

namespace jsa {

struct GemmTiming {
  double eigen_seconds = 0;  // fastest round's time of the list through Eigen
  double blas_seconds = 0;   // ... through the BLAS (0 without one)
  int repeats = 0;
  double wall_seconds = 0;  // the whole measurement, warm-up and check included
};

// Throws InternalError when the two backends disagree (beyond 1e-4 of the
// largest entry). Without a BLAS, only Eigen is timed.
GemmTiming time_gemm_calls(const std::vector<GemmCall>& calls, int repeats = 5);

// The decision rule: the BLAS when it is built in and at least `margin` times
// as fast as Eigen (fastest round against fastest round); Eigen otherwise. The margin keeps
// near ties on Eigen, the default, rather than on whichever the noise favoured.
constexpr double kGemmMargin = 1.1;
Gemm faster_gemm(const GemmTiming& t, double margin = kGemmMargin);

}  // namespace jsa
