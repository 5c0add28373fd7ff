// The GEMMs of the linear op (engine/ops_linear.cpp), C = op(A) op(B) or
// C += op(A) op(B) on row-major blocks, through one of two backends:
//   eigen  Eigen's own product (the default; the only one without a CBLAS);
//   blas   cblas_sgemm of the BLAS the binary links (CMake option JSATLAS_BLAS;
//          on Debian libblas.so.3, which scripts/install-deps.sh points at
//          OpenBLAS's OpenMP build). Floats only: double stays on Eigen.
// Which one is fastest depends on the machine (docs/performance.md: OpenBLAS
// 1.1-1.5x Eigen on an AVX2 core, 0.6-0.9x on an AVX-512 one), so it is a
// process-wide choice made at run time, like the thread count (set_threads):
// `jsatlas fit --gemm` sets it, by measurement with `auto` (model/tool/gemm_choice.h).
//
// Determinism: each backend, at a fixed thread count, gives the same bits run
// to run (OpenBLAS's threads split C's rows and columns, not the sums, and the
// split depends on the shape and thread count only; test/engine_gemm_test.cpp
// checks the bits twice, in and out of an OpenMP team). The two
// backends differ from each other in the last bits, so a run's backend is one
// of its settings. Threads: OpenBLAS's OpenMP build reads the OpenMP thread
// count at every call (omp_get_max_threads, which set_threads and so --threads
// set) and runs on one thread inside a parallel region (omp_in_parallel), as
// Eigen does: the trainer's per-shape workers do not oversubscribe the cores.
// A BLAS with threads of its own (OpenBLAS's pthreads build) knows nothing of
// our OpenMP regions; set_threads tells it the count, but inside the workers it
// would still start its own: use the OpenMP build (or a single-threaded BLAS).
#pragma once
#include <string>
#include <vector>

#include "engine/block.h"

namespace jsa {

enum class Gemm { eigen, blas };

// "eigen" / "blas"; parse_gemm returns false for any other name.
const char* gemm_name(Gemm g);
bool parse_gemm(const std::string& name, Gemm* g);

// Whether the binary was built with a CBLAS (CMake: JSATLAS_BLAS).
bool blas_built_in();
// The BLAS behind the backend as it reports itself at run time (OpenBLAS:
// openblas_get_config, its core and threading), or the library file that
// defines cblas_sgemm; "" when not built in.
std::string blas_description();

// The process-wide backend of the float GEMMs; Eigen until set. Throws
// InputError for blas in a binary without it. Set it before any thread
// computes: a step must not change backend midway.
void set_gemm(Gemm g);
Gemm gemm_backend();

// The BLAS's own thread count, for a BLAS with threads of its own (OpenBLAS's
// pthreads build; nothing for its OpenMP build, which follows OpenMP).
// set_threads calls it.
void set_blas_threads(int n);

// C = op(A) op(B), or C += op(A) op(B) when accumulate; op(X) = X^T when
// transpose_x. C must already have op(A)'s rows and op(B)'s columns (not
// resized here: a first writer's block may hold anything, it is overwritten).
// Through gemm_backend() for float, Eigen for double.
template <class T>
void gemm(const Block<T>& a, bool transpose_a, const Block<T>& b, bool transpose_b, Block<T>& c,
          bool accumulate);

// One product's shape: op(A) is m x k, op(B) k x n, C m x n. team and thread:
// the OpenMP team it ran in (1 and 0 outside a parallel region).
struct GemmCall {
  bool transpose_a = false, transpose_b = false, accumulate = false;
  Index m = 0, n = 0, k = 0;
  int team = 1, thread = 0;
};

// The same product on raw row-major storage, through gemm_backend() for float
// (and recorded like the above), Eigen for double: a and b hold op(A) and op(B)
// before their transposes (k x m when transpose_a, else m x k; likewise b),
// c is m x n, all contiguous. A run of rows of a block is contiguous, so this is
// how an op hands over row tiles (engine/ops_linear_softplus.cpp).
template <class T>
void gemm(const GemmCall& call, const T* a, const T* b, T* c);

// The same product on raw row-major storage through a given backend (the
// timing replays recorded calls with it: engine/gemm_timing.h). a holds op(A)
// before the transpose (k x m when transposed), likewise b; all contiguous.
void sgemm(Gemm backend, const GemmCall& call, const float* a, const float* b, float* c);

// While one lives, every float gemm() call, from any thread, is appended to
// calls() in the order the calls start (a step's products, to time them).
// One recorder at a time (its calls are kept in gemm.cpp).
class GemmRecorder {
 public:
  GemmRecorder();
  ~GemmRecorder();
  GemmRecorder(const GemmRecorder&) = delete;
  GemmRecorder& operator=(const GemmRecorder&) = delete;
  std::vector<GemmCall> calls() const;
};

}  // namespace jsa
