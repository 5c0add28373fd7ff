// The sparse symmetric positive definite solves of the UV steps (SLIM's global
// step, the LSCM fills of uv_repair): CHOLMOD's supernodal Cholesky (SuiteSparse,
// libsuitesparse-dev) when jsatlas is built with it, else Eigen's
// SimplicialLDLT. On a 250k-vertex chart (500k unknowns) the supernodal
// factorisation was 6-7x faster here (docs/uv-quality.md, "Time"); the
// simplicial one is what a build without SuiteSparse gets
// (-DJSATLAS_CHOLMOD=OFF). The dense kernels inside CHOLMOD run on one thread:
// the charts are what runs in parallel.
#pragma once
#include <Eigen/SparseCore>
#include <memory>

namespace jsa {

class SpdSolver {
 public:
  // once: one factorisation of the pattern (a cheap ordering, AMD); many: the
  // pattern is factorised again and again (CHOLMOD's choice of ordering, which
  // may try nested dissection: slower to find, less fill).
  enum class Use { once, many };
  explicit SpdSolver(Use use = Use::once);
  ~SpdSolver();
  SpdSolver(const SpdSolver&) = delete;
  SpdSolver& operator=(const SpdSolver&) = delete;
  // The ordering and symbolic factorisation of A's pattern (A symmetric; both
  // triangles stored), once for every A of that pattern.
  void analyze(const Eigen::SparseMatrix<double>& A);
  // The numeric factorisation; false when A is not (numerically) positive definite.
  bool factorize(const Eigen::SparseMatrix<double>& A);
  bool compute(const Eigen::SparseMatrix<double>& A) {
    analyze(A);
    return factorize(A);
  }
  Eigen::MatrixXd solve(const Eigen::MatrixXd& b) const;
  // "cholmod-supernodal" or "eigen-simplicial-ldlt".
  static const char* backend();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace jsa
