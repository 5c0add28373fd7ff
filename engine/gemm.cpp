#include "engine/gemm.h"

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <climits>
#include <mutex>
#include <type_traits>

#include "engine/check.h"
#include "engine/gemm_kept_buffers.h"

#ifdef JSATLAS_HAVE_BLAS
#include <cblas.h>
#include <dlfcn.h>
#include <stdlib.h>
#endif

namespace jsa {

namespace {

std::atomic<Gemm> g_backend{Gemm::eigen};

// The recorder's calls (one recorder at a time).
std::atomic<bool> g_recording{false};
std::mutex g_record_mutex;
std::vector<GemmCall> g_calls;

void record(GemmCall call) {
  call.team = omp_in_parallel() ? omp_get_num_threads() : 1;
  call.thread = omp_get_thread_num();
  const std::lock_guard<std::mutex> lock(g_record_mutex);
  g_calls.push_back(call);
}

// C (+)= op(A) op(B) by Eigen, on blocks or on maps of raw storage: the
// products the linear op always wrote (c.noalias() (+)= a * b), by Eigen's
// own product routine, with its packing buffers kept between products rather
// than taken from the heap (engine/gemm_kept_buffers.h).
template <class A, class B, class C>
void eigen_product(const A& a, bool transpose_a, const B& b, bool transpose_b, C& c,
                   bool accumulate) {
  kept_gemm::product(a, transpose_a, b, transpose_b, c, accumulate);
}

#ifdef JSATLAS_HAVE_BLAS
// Row-major C (m x n) (+)= op(A) op(B): A is stored k x m when transposed, else
// m x k, so its row length (lda) is m or k; likewise B's is k or n. beta = 0
// makes C write-only (a first writer's C may hold anything, NaN included).
void blas_product(const GemmCall& g, const float* a, const float* b, float* c) {
  JSA_CHECK(
      g.m <= INT_MAX && g.n <= INT_MAX && g.k <= INT_MAX,
      "gemm: " << g.m << "x" << g.k << " by " << g.k << "x" << g.n << " is beyond a CBLAS's int");
  const int m = int(g.m), n = int(g.n), k = int(g.k);
  const int lda = std::max(1, g.transpose_a ? m : k), ldb = std::max(1, g.transpose_b ? k : n);
  cblas_sgemm(CblasRowMajor, g.transpose_a ? CblasTrans : CblasNoTrans,
              g.transpose_b ? CblasTrans : CblasNoTrans, m, n, k, 1.0f, a, lda, b, ldb,
              g.accumulate ? 1.0f : 0.0f, c, std::max(1, n));
}

// OpenBLAS's own entry points, looked up at run time: Debian links programs
// against the reference libblas.so and runs them on whichever libblas.so.3 the
// alternatives system selects, which may or may not be OpenBLAS.
template <class F>
F openblas_function(const char* name) {
  return reinterpret_cast<F>(dlsym(RTLD_DEFAULT, name));
}
#endif

}  // namespace

const char* gemm_name(Gemm g) { return g == Gemm::blas ? "blas" : "eigen"; }

bool parse_gemm(const std::string& name, Gemm* g) {
  if (name == "eigen")
    *g = Gemm::eigen;
  else if (name == "blas")
    *g = Gemm::blas;
  else
    return false;
  return true;
}

bool blas_built_in() {
#ifdef JSATLAS_HAVE_BLAS
  return true;
#else
  return false;
#endif
}

std::string blas_description() {
#ifdef JSATLAS_HAVE_BLAS
  // "OpenBLAS 0.3.21 NO_LAPACKE DYNAMIC_ARCH NO_AFFINITY USE_OPENMP Zen MAX_THREADS=64"
  if (auto config = openblas_function<char* (*)()>("openblas_get_config")) return config();
  Dl_info info;
  void* f = dlsym(RTLD_DEFAULT, "cblas_sgemm");
  if (f && dladdr(f, &info) && info.dli_fname) {
    char* real = realpath(info.dli_fname, nullptr);  // through Debian's alternatives links
    std::string file = real ? real : info.dli_fname;
    free(real);
    return "cblas_sgemm of " + file;
  }
  return "a CBLAS";
#else
  return "";
#endif
}

void set_gemm(Gemm g) {
  if (g == Gemm::blas && !blas_built_in())
    throw InputError(
        "the BLAS backend of the GEMMs is not built into this jsatlas (CMake found no CBLAS: "
        "install libblas-dev and libopenblas0-openmp and rebuild, or use eigen)");
  g_backend.store(g);
}

Gemm gemm_backend() { return g_backend.load(std::memory_order_relaxed); }

void set_blas_threads(int n) {
#ifdef JSATLAS_HAVE_BLAS
  // openblas_get_parallel: 0 sequential, 1 its own threads, 2 OpenMP.
  const auto parallel = openblas_function<int (*)()>("openblas_get_parallel");
  const auto set = openblas_function<void (*)(int)>("openblas_set_num_threads");
  if (n > 0 && parallel && set && parallel() == 1) set(n);
#else
  (void)n;
#endif
}

template <class T>
void gemm(const Block<T>& a, bool transpose_a, const Block<T>& b, bool transpose_b, Block<T>& c,
          bool accumulate) {
  GemmCall call;
  call.transpose_a = transpose_a;
  call.transpose_b = transpose_b;
  call.accumulate = accumulate;
  call.m = transpose_a ? a.cols() : a.rows();
  call.k = transpose_a ? a.rows() : a.cols();
  call.n = transpose_b ? b.rows() : b.cols();
  JSA_CHECK(
      (transpose_b ? b.cols() : b.rows()) == call.k && c.rows() == call.m && c.cols() == call.n,
      "gemm: op(A) is " << call.m << "x" << call.k << ", op(B) "
                        << (transpose_b ? b.cols() : b.rows()) << "x" << call.n << ", C "
                        << c.rows() << "x" << c.cols());
  if constexpr (std::is_same_v<T, float>) {
    if (g_recording.load(std::memory_order_relaxed)) record(call);
#ifdef JSATLAS_HAVE_BLAS
    if (gemm_backend() == Gemm::blas) {
      blas_product(call, a.data(), b.data(), c.data());
      return;
    }
#endif
  }
  eigen_product(a, transpose_a, b, transpose_b, c, accumulate);
}

void sgemm(Gemm backend, const GemmCall& g, const float* a, const float* b, float* c) {
  using ConstMap = Eigen::Map<const Block<float>>;
  if (backend == Gemm::blas) {
#ifdef JSATLAS_HAVE_BLAS
    blas_product(g, a, b, c);
    return;
#else
    JSA_CHECK(false, "sgemm: the BLAS backend is not built in");
#endif
  }
  const ConstMap A(a, g.transpose_a ? g.k : g.m, g.transpose_a ? g.m : g.k);
  const ConstMap B(b, g.transpose_b ? g.n : g.k, g.transpose_b ? g.k : g.n);
  Eigen::Map<Block<float>> C(c, g.m, g.n);
  eigen_product(A, g.transpose_a, B, g.transpose_b, C, g.accumulate);
}

template <class T>
void gemm(const GemmCall& call, const T* a, const T* b, T* c) {
  if constexpr (std::is_same_v<T, float>) {
    if (g_recording.load(std::memory_order_relaxed)) record(call);
    sgemm(gemm_backend(), call, a, b, c);
  } else {
    using ConstMap = Eigen::Map<const Block<T>>;
    const ConstMap A(a, call.transpose_a ? call.k : call.m, call.transpose_a ? call.m : call.k);
    const ConstMap B(b, call.transpose_b ? call.n : call.k, call.transpose_b ? call.k : call.n);
    Eigen::Map<Block<T>> C(c, call.m, call.n);
    eigen_product(A, call.transpose_a, B, call.transpose_b, C, call.accumulate);
  }
}

GemmRecorder::GemmRecorder() {
  const std::lock_guard<std::mutex> lock(g_record_mutex);
  JSA_CHECK(!g_recording.load(), "one GemmRecorder at a time");
  g_calls.clear();
  g_recording.store(true);
}

GemmRecorder::~GemmRecorder() {
  const std::lock_guard<std::mutex> lock(g_record_mutex);
  g_recording.store(false);
  g_calls.clear();
}

std::vector<GemmCall> GemmRecorder::calls() const {
  const std::lock_guard<std::mutex> lock(g_record_mutex);
  return g_calls;
}

#define JSA_INSTANTIATE(T)                                                              \
  template void gemm<T>(const Block<T>&, bool, const Block<T>&, bool, Block<T>&, bool); \
  template void gemm<T>(const GemmCall&, const T*, const T*, T*);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
