// OpenMP over rows, in fixed chunks. Each chunk writes disjoint rows, so the
// result does not depend on the thread count or on scheduling: the only
// parallelism the engine allows itself for elementwise work.
#pragma once
#include <algorithm>

#include "engine/block.h"

namespace jsa {

// Calls f(begin, end) on consecutive row ranges covering [0, n).
// Small blocks run inline: a parallel region costs a few microseconds.
template <class F>
void parallel_rows(Index n, F&& f, Index grain = 2048) {
  if (n <= grain) {
    f(Index(0), n);
    return;
  }
  const Index chunks = (n + grain - 1) / grain;
#pragma omp parallel for schedule(static)
  for (Index c = 0; c < chunks; ++c) {
    const Index b = c * grain;
    f(b, std::min(n, b + grain));
  }
}

// Threads the engine will use (omp_get_max_threads, 1 without OpenMP).
int max_threads();
// Sets the thread count for OpenMP and Eigen's GEMM; 0 keeps the default.
void set_threads(int n);

}  // namespace jsa
