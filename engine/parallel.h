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
// Also turns denormal floats off on the calling thread and on every OpenMP
// thread (flush-to-zero and denormals-are-zero, x86's MXCSR): a trained
// softplus network is full of them (the tangent rows s'(z) x_k of Eq. 2's
// Jacobian with s'(z) = sigmoid(beta z) ~ e^(beta z) below 1e-38), and an x86
// core takes a slow path on every multiply that meets one. Measured on the
// collection defaults: 2.5x faster joint steps, 1.6x faster template steps,
// the same losses to 6 digits (docs/performance.md). The environment variable
// JSATLAS_KEEP_DENORMALS (any value) keeps them, for that comparison.
void set_threads(int n);
// Whether floats below 2^-126 become 0 on the calling thread.
bool denormals_flushed();

}  // namespace jsa
