// Tests of engine/gemm.{h,cpp} and engine/gemm_timing.{h,cpp}: both backends
// against the exact product (computed in double) within the classical float
// error bound, the linear op's forward and both pull-backs through the BLAS
// against Eigen's, the Eigen backend against the expressions it replaced (the
// same bits), determinism with a fixed backend, in and out of an OpenMP team,
// the recorder, and the timing's decision rule. Without a BLAS in the build
// the BLAS cases check that asking for it is an error.
#include <omp.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <limits>

#include "engine/gemm.h"
#include "engine/gemm_timing.h"
#include "engine/ops.h"
#include "engine/rng.h"

namespace jsa::test {

namespace {

// The backend for one scope, then back to what it was.
struct UseGemm {
  Gemm before;
  explicit UseGemm(Gemm g) : before(gemm_backend()) { set_gemm(g); }
  ~UseGemm() { set_gemm(before); }
};

Block<float> random_block(Rng& rng, Index rows, Index cols) {
  Block<float> b(rows, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = float(rng.uniform(-1, 1));
  return b;
}

struct Product {
  Index m, n, k;
  bool ta, tb;
};

// Shapes of a step's products: tiny (Eigen's coefficient-wise path), thin
// input and output layers, a hidden layer at a collection's and the default's
// sizes, and dW's long sums (k = the stacked rows).
const Product kProducts[] = {
    {1, 1, 1, false, false},      {5, 3, 4, false, false},       {5, 3, 4, true, false},
    {5, 3, 4, false, true},       {5, 3, 4, true, true},         {6000, 64, 64, false, false},
    {6000, 64, 64, false, true},  {64, 64, 6000, true, false},   {7500, 128, 2, false, false},
    {7500, 3, 128, false, false}, {128, 128, 7500, true, false}, {7500, 128, 128, false, true}};

// |C - (C0 + op(A) op(B))| <= gamma_(k+1) (|C0| + |op(A)| |op(B)|) per entry,
// gamma_j = j u / (1 - j u), u = 2^-24: the bound of any order of summation.
void check_within_float_bound(const Block<float>& c, const Block<float>& c0, bool accumulate,
                              const Block<float>& a, bool ta, const Block<float>& b, bool tb) {
  const Eigen::MatrixXd A = ta ? Eigen::MatrixXd(a.cast<double>().transpose()) : a.cast<double>();
  const Eigen::MatrixXd B = tb ? Eigen::MatrixXd(b.cast<double>().transpose()) : b.cast<double>();
  Eigen::MatrixXd exact = A * B, size = A.cwiseAbs() * B.cwiseAbs();
  if (accumulate) {
    exact += c0.cast<double>();
    size += c0.cast<double>().cwiseAbs();
  }
  const double u = std::ldexp(1.0, -24), j = double(A.cols() + 1);
  const double gamma = j * u / (1 - j * u);
  const Eigen::MatrixXd error = (c.cast<double>() - exact).cwiseAbs();
  const Eigen::MatrixXd allowed = gamma * size;
  INFO("worst error / bound " << (error.array() / allowed.array().max(1e-300)).maxCoeff());
  CHECK((error.array() <= allowed.array()).all());
}

}  // namespace

TEST_CASE("both GEMM backends are within float rounding of the exact product", "[gemm]") {
  std::vector<Gemm> backends{Gemm::eigen};
  if (blas_built_in()) backends.push_back(Gemm::blas);
  Rng rng(41);
  for (const Gemm g : backends)
    for (const Product& p : kProducts)
      for (const bool accumulate : {false, true}) {
        DYNAMIC_SECTION(gemm_name(g) << " " << p.m << "x" << p.k << " by " << p.k << "x" << p.n
                                     << (p.ta ? " A^T" : "") << (p.tb ? " B^T" : "")
                                     << (accumulate ? " accumulated" : "")) {
          const UseGemm use(g);
          const Block<float> a = p.ta ? random_block(rng, p.k, p.m) : random_block(rng, p.m, p.k);
          const Block<float> b = p.tb ? random_block(rng, p.n, p.k) : random_block(rng, p.k, p.n);
          // A first writer's block may hold anything: NaN must not leak through beta = 0.
          Block<float> c0 = accumulate ? random_block(rng, p.m, p.n)
                                       : Block<float>::Constant(
                                             p.m, p.n, std::numeric_limits<float>::quiet_NaN());
          Block<float> c = c0;
          gemm(a, p.ta, b, p.tb, c, accumulate);
          check_within_float_bound(c, c0, accumulate, a, p.ta, b, p.tb);
        }
      }
}

// The linear op's three products, X W, dY W^T and X^T dY, through the BLAS
// against Eigen's: forward values and the gradients of X, W and b, with X also
// feeding a second op, so that linear's pull-back accumulates into a gradient
// the other path has already written (a first writer assigns, the second adds).
TEST_CASE("linear through the BLAS gives Eigen's values and gradients to float precision",
          "[gemm][ops]") {
  if (!blas_built_in()) {
    CHECK_THROWS_AS(set_gemm(Gemm::blas), InputError);
    CHECK(gemm_backend() == Gemm::eigen);
    return;
  }
  struct Sizes {
    Index n, cin, cout, value_rows;
  };
  for (const Sizes s : {Sizes{9, 3, 4, 3}, Sizes{3000, 64, 64, 1000}, Sizes{7500, 128, 3, 2500}}) {
    DYNAMIC_SECTION(s.n << " rows, " << s.cin << " -> " << s.cout) {
      Rng rng(uint64_t(s.n + s.cin));
      const Block<float> x0 = random_block(rng, s.n, s.cin), w0 = random_block(rng, s.cin, s.cout),
                         b0 = random_block(rng, 1, s.cout), dy = random_block(rng, s.n, s.cout),
                         other = random_block(rng, s.n, s.cin);
      auto run = [&](Gemm g) {
        const UseGemm use(g);
        Tape<float> t;
        const Var x = t.variable(x0), w = t.variable(w0), b = t.variable(b0);
        const Var y = linear(t, x, w, b, s.value_rows);
        const Var loss =
            add(t, sum(t, mul(t, y, t.constant(dy))), sum(t, mul(t, x, t.constant(other))));
        t.backward(loss);
        return std::make_tuple(Block<float>(t.value(y)), Block<float>(t.grad(x)),
                               Block<float>(t.grad(w)), Block<float>(t.grad(b)));
      };
      const auto [ye, dxe, dwe, dbe] = run(Gemm::eigen);
      const auto [yb, dxb, dwb, dbb] = run(Gemm::blas);
      auto close = [](const Block<float>& p, const Block<float>& q, double k) {
        // Two float sums of k terms of size <= 1: each within k u of the exact one.
        const double bound =
            2 * k * std::ldexp(1.0, -24) * std::max(1.0, double(q.cwiseAbs().maxCoeff()));
        return (p - q).cwiseAbs().maxCoeff() <= bound;
      };
      CHECK(close(yb, ye, double(s.cin + 1)));
      CHECK(close(dxb, dxe, double(s.cout + 1)));
      CHECK(close(dwb, dwe, double(s.n)));
      CHECK(dbb == dbe);  // the bias's sum is a plain loop, the same for both
    }
  }
}

// Eigen as the backend is the same code as before it was one: the products the
// linear op wrote (Y = X W, and dX += dY W^T, dW += X^T dY into a zeroed or a
// written gradient) give the same bits through gemm(), assigning or adding.
TEST_CASE("the Eigen backend gives the bits of the expressions it replaced", "[gemm]") {
  const UseGemm use(Gemm::eigen);
  Rng rng(43);
  for (const Product& p : kProducts) {
    const Block<float> a = p.ta ? random_block(rng, p.k, p.m) : random_block(rng, p.m, p.k);
    const Block<float> b = p.tb ? random_block(rng, p.n, p.k) : random_block(rng, p.k, p.n);
    const Block<float> c0 = random_block(rng, p.m, p.n);
    Block<float> zeroed_then_added = Block<float>::Zero(p.m, p.n), added = c0;
    if (p.ta && p.tb) {
      zeroed_then_added.noalias() += a.transpose() * b.transpose();
      added.noalias() += a.transpose() * b.transpose();
    } else if (p.ta) {
      zeroed_then_added.noalias() += a.transpose() * b;
      added.noalias() += a.transpose() * b;
    } else if (p.tb) {
      zeroed_then_added.noalias() += a * b.transpose();
      added.noalias() += a * b.transpose();
    } else {
      zeroed_then_added.noalias() += a * b;
      added.noalias() += a * b;
    }
    Block<float> assigned(p.m, p.n), accumulated = c0;
    gemm(a, p.ta, b, p.tb, assigned, false);
    gemm(a, p.ta, b, p.tb, accumulated, true);
    CHECK(assigned == zeroed_then_added);
    CHECK(accumulated == added);
  }
}

// A fixed backend and thread count give the same bits every time, on the main
// thread (the backend's own threads) and inside an OpenMP team (one thread per
// product, as the trainer's per-shape workers run).
TEST_CASE("a fixed GEMM backend gives the same bits every time, in and out of a team", "[gemm]") {
  std::vector<Gemm> backends{Gemm::eigen};
  if (blas_built_in()) backends.push_back(Gemm::blas);
  Rng rng(47);
  const Block<float> x = random_block(rng, 7500, 128), w = random_block(rng, 128, 128),
                     dy = random_block(rng, 7500, 128);
  for (const Gemm g : backends) {
    DYNAMIC_SECTION(gemm_name(g)) {
      const UseGemm use(g);
      auto products = [&] {
        Block<float> y(7500, 128), dx(7500, 128), dw(128, 128);
        gemm(x, false, w, false, y, false);
        gemm(dy, false, w, true, dx, false);
        gemm(x, true, dy, false, dw, false);
        return std::make_tuple(y, dx, dw);
      };
      const auto first = products();
      CHECK(products() == first);
      std::vector<std::tuple<Block<float>, Block<float>, Block<float>>> in_team(2);
#pragma omp parallel for num_threads(2) schedule(static, 1)
      for (int i = 0; i < 2; ++i) in_team[size_t(i)] = products();
      CHECK(in_team[0] == in_team[1]);
      CHECK(products() == first);
    }
  }
}

TEST_CASE("the recorder sees every float product, with its team", "[gemm]") {
  Rng rng(53);
  const Block<float> x0 = random_block(rng, 30, 4), w0 = random_block(rng, 4, 5);
  std::vector<GemmCall> calls;
  {
    const GemmRecorder recorder;
    Tape<float> t;
    const Var x = t.variable(x0), w = t.variable(w0);
    t.backward(sum(t, linear(t, x, w, Var{})));
    Tape<double> td;  // double stays on Eigen and is not recorded
    td.backward(
        sum(td, linear(td, td.variable(x0.cast<double>()), td.variable(w0.cast<double>()), Var{})));
#pragma omp parallel num_threads(2)
    {
      Block<float> c(30, 5);
      gemm(x0, false, w0, false, c, false);
    }
    calls = recorder.calls();
  }
  REQUIRE(calls.size() == 5);
  // Y = X W (30x4 by 4x5), then the pull-back: dX = dY W^T, dW = X^T dY.
  CHECK((calls[0].m == 30 && calls[0].n == 5 && calls[0].k == 4 && !calls[0].transpose_a &&
         !calls[0].transpose_b && calls[0].team == 1));
  CHECK((calls[1].m == 30 && calls[1].n == 4 && calls[1].k == 5 && calls[1].transpose_b));
  CHECK((calls[2].m == 4 && calls[2].n == 5 && calls[2].k == 30 && calls[2].transpose_a));
  CHECK(!calls[1].accumulate);  // each gradient's first writer
  const int threads_seen = int(calls[3].team == 2) + int(calls[4].team == 2);
  CHECK((omp_get_max_threads() < 2 || threads_seen == 2));
  CHECK(calls[3].thread != calls[4].thread);
  const GemmRecorder again;  // one at a time, and the last one is gone
  CHECK(again.calls().empty());
}

TEST_CASE("timing a step's products and the margin of the decision rule", "[gemm]") {
  std::vector<GemmCall> calls(3);
  calls[0] = {false, false, false, 2000, 64, 64, 1, 0};
  calls[1] = {false, true, false, 2000, 64, 64, 1, 0};
  calls[2] = {true, false, true, 64, 64, 2000, 2, 1};  // a worker's, in a team of two
  const GemmTiming t = time_gemm_calls(calls, 3);
  CHECK(t.eigen_seconds > 0);
  CHECK((t.blas_seconds > 0) == blas_built_in());
  CHECK(t.wall_seconds >= t.eigen_seconds);
  CHECK(t.repeats == 3);
  GemmTiming close{1.0, 0.95, 3, 0}, far{1.0, 0.85, 3, 0};
  CHECK(faster_gemm(close) == Gemm::eigen);  // 1.05x: within the margin
  CHECK(faster_gemm(far) == (blas_built_in() ? Gemm::blas : Gemm::eigen));
  CHECK(faster_gemm(GemmTiming{}) == Gemm::eigen);
}

TEST_CASE("GEMM backend names", "[gemm]") {
  Gemm g = Gemm::eigen;
  CHECK(parse_gemm("blas", &g));
  CHECK(g == Gemm::blas);
  CHECK(std::string(gemm_name(g)) == "blas");
  CHECK(parse_gemm("eigen", &g));
  CHECK(g == Gemm::eigen);
  CHECK_FALSE(parse_gemm("auto", &g));
  CHECK_FALSE(parse_gemm("BLAS", &g));
  CHECK(blas_description().empty() == !blas_built_in());
}

}  // namespace jsa::test
