#include "engine/parallel.h"

#include <omp.h>

#include <Eigen/Core>
#include <cstdlib>
#if defined(__SSE__)
#include <xmmintrin.h>
#endif

#include "engine/gemm.h"

namespace jsa {

int max_threads() { return omp_get_max_threads(); }

bool region_would_be_serial() {
  return omp_get_max_threads() == 1 || omp_get_active_level() >= omp_get_max_active_levels();
}

namespace {
// MXCSR bits: FTZ (bit 15) makes results below 2^-126 zero, DAZ (bit 6) reads
// such inputs as zero.
constexpr unsigned kFlushToZero = 0x8000, kDenormalsAreZero = 0x0040;

void flush_denormals_here() {
#if defined(__SSE__)
  _mm_setcsr(_mm_getcsr() | kFlushToZero | kDenormalsAreZero);
#endif
}
}  // namespace

bool denormals_flushed() {
#if defined(__SSE__)
  const unsigned both = kFlushToZero | kDenormalsAreZero;
  return (_mm_getcsr() & both) == both;
#else
  return false;
#endif
}

void set_threads(int n) {
  if (n > 0) {
    omp_set_num_threads(n);
    Eigen::setNbThreads(n);
    set_blas_threads(n);  // a BLAS with threads of its own (engine/gemm.h)
  }
  if (std::getenv("JSATLAS_KEEP_DENORMALS")) return;
  // Each thread has its own MXCSR; threads started later copy their creator's.
  flush_denormals_here();
#pragma omp parallel
  flush_denormals_here();
}

}  // namespace jsa
