// The step's SGEMMs through Eigen and through the BLAS libraries Debian ships
// (issue 21: "measure Eigen against OpenBLAS and BLIS for the step's shapes,
// and use the fastest"). Each BLAS is loaded at run time (dlopen, its Fortran
// sgemm_), so the program builds without any of them and one run compares them
// all in the same process on the same data:
//
//   bench_sgemm_blas --threads 2
//       --blas /usr/lib/x86_64-linux-gnu/openblas-openmp/libblas.so.3
//       --blas /usr/lib/x86_64-linux-gnu/blis-openmp/libblas.so.3
//
// Shapes: the stacked rows of one layer (value and two tangents, 3M rows) at the
// default (M = 2500, 128 wide), the paper (M = 10^4, 256 wide) and a collection
// shape's (2M = 2000 points, 64 wide) sizes, the
// three products of a layer's step: Y = X W (forward), dW = X^T dY and
// dX = dY W^T (backward). Every library's result is checked against Eigen's
// before it is timed. Medians of --runs repetitions, GFLOP/s per product.
#include <dlfcn.h>

#include <CLI/CLI.hpp>
#include <Eigen/Core>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench/timing.h"
#include "engine/parallel.h"

namespace {

using Mat = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Sgemm = void (*)(const char*, const char*, const int*, const int*, const int*, const float*,
                       const float*, const int*, const float*, const int*, const float*, float*,
                       const int*);

// Row-major C = op(A) op(B) as the column-major C^T = op(B)^T op(A)^T.
void gemm_rowmajor(Sgemm f, bool ta, bool tb, const Mat& A, const Mat& B, Mat& C) {
  const int m = int(C.cols()), n = int(C.rows()), k = int(ta ? A.rows() : A.cols());
  const float one = 1, zero = 0;
  const int lda = int(A.cols()), ldb = int(B.cols()), ldc = int(C.cols());
  const char tA = ta ? 'T' : 'N', tB = tb ? 'T' : 'N';
  f(&tB, &tA, &m, &n, &k, &one, B.data(), &ldb, A.data(), &lda, &zero, C.data(), &ldc);
}

struct Shape {
  std::string name;
  int points, width;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The step's SGEMMs: Eigen against run-time-loaded BLAS libraries"};
  int threads = 2, runs = 7;
  std::vector<std::string> libs;
  app.add_option("--threads", threads, "Threads (OpenMP; also BLIS_NUM_THREADS)");
  app.add_option("--runs", runs, "Repetitions (median)");
  app.add_option("--blas", libs, "A BLAS shared library with sgemm_ (repeatable)");
  CLI11_PARSE(app, argc, argv);
  const std::string t = std::to_string(threads);
  setenv("BLIS_NUM_THREADS", t.c_str(), 1);  // read by BLIS at its first call
  jsa::set_threads(threads);
  std::vector<std::pair<std::string, Sgemm>> blas;
  for (const std::string& path : libs) {
    void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    Sgemm f = h ? reinterpret_cast<Sgemm>(dlsym(h, "sgemm_")) : nullptr;
    if (!f) {
      std::fprintf(stderr, "bench_sgemm_blas: cannot load sgemm_ from %s\n", path.c_str());
      return 1;
    }
    blas.push_back({path, f});
  }
  // "collection": one shape's phi pass in a collection step (2M = 2000 points at
  // M = 1000, 5 x 64 networks), the GEMMs a per-shape worker runs on one thread.
  const std::vector<Shape> shapes{
      {"default", 2500, 128}, {"paper", 10000, 256}, {"collection", 2000, 64}};
  std::printf("threads %d, runs %d (median); GFLOP/s\n", threads, runs);
  std::printf("%-10s %-9s %-70s %8s\n", "config", "product", "library", "GFLOP/s");
  for (const Shape& s : shapes) {
    const int r = 3 * s.points, w = s.width;
    const Mat X = Mat::Random(r, w), W = Mat::Random(w, w), dY = Mat::Random(r, w);
    const double flops = 2.0 * r * w * w;
    struct Product {
      const char* name;
      bool ta, tb;
      const Mat &A, &B;
      Eigen::Index rows, cols;
    };
    const Product products[] = {{"X W", false, false, X, W, r, w},
                                {"X^T dY", true, false, X, dY, w, w},
                                {"dY W^T", false, true, dY, W, r, w}};
    for (const Product& p : products) {
      Mat ref(p.rows, p.cols);
      auto eigen = [&](Mat& C) {
        if (p.ta)
          C.noalias() = p.A.transpose() * p.B;
        else if (p.tb)
          C.noalias() = p.A * p.B.transpose();
        else
          C.noalias() = p.A * p.B;
      };
      auto time = [&](auto&& f) {
        Mat C(p.rows, p.cols);
        f(C);  // warm-up
        std::vector<double> sec;
        for (int i = 0; i < runs; ++i) {
          const auto t0 = bench::Clock::now();
          f(C);
          sec.push_back(bench::seconds_since(t0));
        }
        return flops / bench::median(sec) * 1e-9;
      };
      eigen(ref);
      std::printf("%-10s %-9s %-70s %8.1f\n", s.name.c_str(), p.name, "Eigen", time(eigen));
      for (const auto& [path, f] : blas) {
        Mat C(p.rows, p.cols);
        gemm_rowmajor(f, p.ta, p.tb, p.A, p.B, C);
        const double err = (C - ref).cwiseAbs().maxCoeff() / ref.cwiseAbs().maxCoeff();
        if (!(err < 1e-4)) {
          std::fprintf(stderr, "bench_sgemm_blas: %s disagrees with Eigen (%g)\n", path.c_str(),
                       err);
          return 1;
        }
        std::printf("%-10s %-9s %-70s %8.1f\n", s.name.c_str(), p.name, path.c_str(),
                    time([&](Mat& out) { gemm_rowmajor(f, p.ta, p.tb, p.A, p.B, out); }));
      }
    }
  }
  return 0;
}
