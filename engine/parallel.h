// OpenMP over rows, in chunks of at most `grain` rows. Each chunk writes
// disjoint rows and each row's result depends on that row alone, so the result
// does not depend on the thread count or on scheduling: the only parallelism
// the engine allows itself for elementwise work.
//
// The chunks are of equal size (to a row) and their count is a multiple of
// the thread count, so a static schedule gives every thread the same work.
// Cutting at multiples of the grain instead left 5000 rows (phi's value rows
// at the default M) as 2048 + 2048 + 904: one thread did 4096 rows while the
// other did 904, and every softplus and bias pass ran at 0.61 of two cores.
#pragma once
#include <algorithm>

#include "engine/block.h"

namespace jsa {

// Threads the engine will use (omp_get_max_threads, 1 without OpenMP).
int max_threads();

// Whether a parallel region opened here would run on one thread: one thread
// in all (--threads 1), or inside an active region with no nesting level left
// (OpenMP's default allows one), which is where the trainer's shape workers
// run the ops. libgomp allocates a team on the heap for every region of one
// thread (it keeps only an outermost team of several for the next region), so
// the engine runs that work inline instead: the same single thread, the same
// results, no allocation in the step. A region whose `if` or thread count
// would give it one thread is skipped the same way by its caller.
bool region_would_be_serial();

// Calls f(begin, end) on consecutive row ranges covering [0, n).
// Small blocks run inline: a parallel region costs a few microseconds.
template <class F>
void parallel_rows(Index n, F&& f, Index grain = 2048) {
  if (n <= grain || region_would_be_serial()) {
    f(Index(0), n);
    return;
  }
  const Index threads = max_threads();
  Index chunks = (n + grain - 1) / grain;
  chunks = (chunks + threads - 1) / threads * threads;
  const Index base = n / chunks, extra = n % chunks;  // the first `extra` chunks get a row more
#pragma omp parallel for schedule(static)
  for (Index c = 0; c < chunks; ++c) {
    const Index b = c * base + std::min(c, extra);
    f(b, b + base + (c < extra ? 1 : 0));
  }
}

// Sets the thread count for OpenMP, Eigen's GEMM and the BLAS's (engine/gemm.h);
// 0 keeps the default.
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
