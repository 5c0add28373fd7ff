#include "io/geometry/sparse_spd.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#ifdef JSATLAS_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#else
#include <Eigen/SparseCholesky>
#endif

namespace jsa {

#ifdef JSATLAS_HAVE_CHOLMOD
struct SpdSolver::Impl {
  Eigen::CholmodSupernodalLLT<Eigen::SparseMatrix<double>> solver;
};
const char* SpdSolver::backend() { return "cholmod-supernodal"; }
#else
struct SpdSolver::Impl {
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
};
const char* SpdSolver::backend() { return "eigen-simplicial-ldlt"; }
#endif

namespace {
// An OpenMP build of OpenBLAS under CHOLMOD takes its thread count from the
// calling thread's OpenMP setting; on two cores two BLAS threads made a
// factorisation 4-5x slower than one (small supernodes), and the caller may run
// charts in parallel already. Held at 1 for the call, then restored.
// CHOLMOD's supernodal factorisation also opens its own parallel regions with a
// fixed num_threads(4) clause (Debian's SuiteSparse 5.12), which no thread
// count of ours reaches: on two cores four threads took turns spinning, and
// the input-chart UVs of a four-ant collection at --threads 1 took 4.7 s
// against 1.3 s. Dynamic adjustment lets the runtime give such a region no
// more threads than the machine has free; the factor does not depend on it
// (those regions split independent supernodes: outputs byte for byte).
template <class F>
void with_one_blas_thread(F&& f) {
#ifdef _OPENMP
  const int saved = omp_get_max_threads();
  const int saved_dynamic = omp_get_dynamic();
  omp_set_num_threads(1);
  omp_set_dynamic(1);
  f();
  omp_set_dynamic(saved_dynamic);
  omp_set_num_threads(saved);
#else
  f();
#endif
}
}  // namespace

SpdSolver::SpdSolver(Use use) : impl_(std::make_unique<Impl>()) {
#ifdef JSATLAS_HAVE_CHOLMOD
  impl_->solver.cholmod().print = 0;  // a refused matrix is the caller's to report, not CHOLMOD's
  if (use == Use::once) {
    // Measured on a 1M-unknown system: analysis 0.85 s with AMD alone against
    // 4.7 s when CHOLMOD also tries nested dissection, factorisation 9.0 s against 7.8 s.
    impl_->solver.cholmod().nmethods = 1;
    impl_->solver.cholmod().method[0].ordering = CHOLMOD_AMD;
  }
#else
  (void)use;
#endif
}
SpdSolver::~SpdSolver() = default;

void SpdSolver::analyze(const Eigen::SparseMatrix<double>& A) {
  with_one_blas_thread([&] { impl_->solver.analyzePattern(A); });
}

bool SpdSolver::factorize(const Eigen::SparseMatrix<double>& A) {
  with_one_blas_thread([&] { impl_->solver.factorize(A); });
  if (impl_->solver.info() != Eigen::Success) return false;
#ifndef JSATLAS_HAVE_CHOLMOD
  // LDL^T also factors indefinite matrices: positive definite means D > 0.
  if (A.rows() > 0 && !(impl_->solver.vectorD().minCoeff() > 0)) return false;
#endif
  return true;
}

Eigen::MatrixXd SpdSolver::solve(const Eigen::MatrixXd& b) const {
  Eigen::MatrixXd x;
  with_one_blas_thread([&] { x = impl_->solver.solve(b); });
  return x;
}

}  // namespace jsa
