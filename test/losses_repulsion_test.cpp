// Repulsion (Eq. 11): the grid cut-off against the exact O(K^2) oracle within
// the bounds stated in repulsion.h, a two-point case by hand, and the tape op's
// gradient against finite differences. `test_losses "[.bench]"` times K = 10^4.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "engine/gradcheck.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/repulsion.h"

using namespace jsa;

namespace {

Block<double> unit_square(Index k, uint64_t seed) {
  Rng rng(seed);
  Block<double> mu(k, 2);
  for (Index i = 0; i < mu.size(); ++i) mu.data()[i] = rng.uniform();
  return mu;
}

// Largest Euclidean norm of a row difference.
double worst_row_error(const Block<double>& a, const Block<double>& b) {
  return (a - b).rowwise().norm().maxCoeff();
}

}  // namespace

TEST_CASE("repulsion cut-off stays within its bounds of the exact sum", "[repulsion]") {
  const Index K = 2000;
  const double sigma = 1 / std::sqrt(double(K));
  const Block<double> mu = unit_square(K, 1);
  Block<double> exact_grad, grad;
  const double exact = repulsion_exact(mu, sigma, &exact_grad);
  // 1e-7 is the default; 1e-3 and 1e-2 cut so close that many pairs are dropped,
  // which checks that the bound, not just the answer, is right.
  for (double tolerance : {1e-7, 1e-3, 1e-2}) {
    INFO("tolerance " << tolerance);
    RepulsionOptions o;
    o.tolerance = tolerance;
    const double value = repulsion_cutoff(mu, sigma, &grad, o);
    CHECK(std::abs(value - exact) < tolerance);
    CHECK(worst_row_error(grad, exact_grad) < 2 * tolerance / (double(K) * sigma));
  }
  // Value only gives the same value.
  CHECK(repulsion_cutoff<double>(mu, sigma, nullptr) == repulsion_cutoff(mu, sigma, &grad));
  // Float: same answer to float precision.
  Block<float> grad_f;
  const double value_f = repulsion_cutoff<float>(mu.cast<float>(), float(sigma), &grad_f);
  CHECK(value_f == Approx(exact).epsilon(1e-5));
  CHECK(worst_row_error(grad_f.cast<double>(), exact_grad) <
        1e-4 * exact_grad.cwiseAbs().maxCoeff());
}

TEST_CASE("repulsion of two points by hand", "[repulsion]") {
  // mu_0 = (0, 0), mu_1 = (d, 0), K = 2:
  //   L = 1/4 (1 + 1 + 2 exp(-d/sigma))
  //   dL/dmu_0 = 1/4 * 2 * (-1/sigma) exp(-d/sigma) (mu_0 - mu_1)/d = (exp(-d/sigma) / (2 sigma),
  //   0) dL/dmu_1 = -dL/dmu_0
  const double d = 0.3, sigma = 0.2, e = std::exp(-d / sigma);
  Block<double> mu(2, 2);
  mu << 0, 0, d, 0;
  Block<double> grad;
  for (int exact = 0; exact < 2; ++exact) {
    const double value =
        exact ? repulsion_exact(mu, sigma, &grad) : repulsion_cutoff(mu, sigma, &grad);
    CHECK(value == Approx(0.25 * (2 + 2 * e)).epsilon(1e-14));
    CHECK(grad(0, 0) == Approx(e / (2 * sigma)).epsilon(1e-14));
    CHECK(grad(0, 1) == 0);
    CHECK(grad(1, 0) == Approx(-e / (2 * sigma)).epsilon(1e-14));
    CHECK(grad(1, 1) == 0);
  }
}

TEST_CASE("repulsion of one mean is its own pair", "[repulsion]") {
  Block<double> mu(1, 2), grad;
  mu << 0.3, -2;
  CHECK(repulsion_cutoff(mu, 0.1, &grad) == 1);
  CHECK(grad.rows() == 1);
  CHECK(grad.isZero(0));
  CHECK(repulsion_exact(mu, 0.1, &grad) == 1);
}

TEST_CASE("repulsion: coincident means count exp(0) and pull nowhere", "[repulsion]") {
  Block<double> mu(3, 2);
  mu << 0.5, 0.5, 0.5, 0.5, 0.9, 0.5;  // mu_0 == mu_1
  Block<double> grad, exact_grad;
  const double value = repulsion_cutoff(mu, 0.1, &grad);
  const double exact = repulsion_exact(mu, 0.1, &exact_grad);
  const double e = std::exp(-0.4 / 0.1);
  CHECK(value == Approx((3 + 2 + 4 * e) / 9).epsilon(1e-14));
  CHECK(exact == Approx(value).epsilon(1e-14));
  CHECK(grad.allFinite());
  CHECK(worst_row_error(grad, exact_grad) < 1e-15);
  // mu_0 and mu_1 feel only mu_2, and identically.
  CHECK(grad.row(0) == grad.row(1));
  CHECK(grad(0, 0) == Approx(2.0 / 9 * e / 0.1).epsilon(1e-14));
}

TEST_CASE("repulsion tape op passes the finite-difference check", "[repulsion]") {
  // 12 distinct means in the unit square, sigma = 0.3: r_c = 0.3 ln(1e7) ~ 4.8
  // exceeds the square, so the grid is one cell and every pair is summed (the
  // loss is then smooth: no pair enters or leaves the sum under the step), and
  // no two means are close to coincident (|x| is not differentiable at 0).
  const Block<double> mu = unit_square(12, 2);
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return repulsion(t, v[0], 0.3); }, {mu});
  INFO(r.report);
  CHECK(r.ok);
  // And a spread-out set where the grid has many cells (sigma = 0.02, 40 means).
  const Block<double> wide = unit_square(40, 3);
  const GradCheckResult r2 = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return repulsion(t, v[0], 0.02); }, {wide});
  INFO(r2.report);
  CHECK(r2.ok);
}

TEST_CASE("repulsion tape op agrees with the kernel and reuses the tape", "[repulsion]") {
  const Block<float> mu = unit_square(500, 4).cast<float>();
  Block<float> expected_grad;
  const double expected = repulsion_cutoff(mu, 0.05f, &expected_grad);
  Tape<float> t;
  for (int step = 0; step < 2; ++step) {
    t.clear();
    Var v = t.variable(mu);
    Var loss = repulsion(t, v, 0.05f);
    t.backward(loss);
    CHECK(t.scalar(loss) == float(expected));
    CHECK(t.grad(v) == expected_grad);
  }
  // As a constant it has a value and no pull-back.
  t.clear();
  Var c = t.constant(mu);
  CHECK(t.scalar(repulsion(t, c, 0.05f)) == float(expected));
}

TEST_CASE("repulsion does not depend on the thread count", "[repulsion]") {
  const Block<float> mu = unit_square(5000, 5).cast<float>();
  Block<float> g1, g2;
  const int threads = max_threads();
  set_threads(1);
  const double v1 = repulsion_cutoff(mu, 0.01f, &g1);
  set_threads(std::max(2, threads));
  const double v2 = repulsion_cutoff(mu, 0.01f, &g2);
  set_threads(threads);
  CHECK(v1 == v2);
  CHECK(g1 == g2);
}

TEST_CASE("repulsion timing at K = 10^4", "[.bench][repulsion]") {
  // K = 10^4 means uniform in the unit square, sigma = 0.01, value + gradient,
  // median of 15; validated against the exact sum first.
  const Index K = 10000;
  const Block<double> mu = unit_square(K, 6);
  const Block<float> mu_f = mu.cast<float>();
  Block<double> grad, exact_grad;
  Block<float> grad_f;
  const double exact = repulsion_exact(mu, 0.01, &exact_grad);
  REQUIRE(std::abs(repulsion_cutoff(mu, 0.01, &grad) - exact) < 1e-7);
  REQUIRE(worst_row_error(grad, exact_grad) < 2e-7 / (K * 0.01));
  auto median_ms = [](auto&& f) {
    std::vector<double> ms;
    for (int r = 0; r < 15; ++r) {
      const auto t0 = std::chrono::steady_clock::now();
      f();
      ms.push_back(
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    return ms[ms.size() / 2];
  };
  const double ms_f = median_ms([&] { repulsion_cutoff(mu_f, 0.01f, &grad_f); });
  const double ms_d = median_ms([&] { repulsion_cutoff(mu, 0.01, &grad); });
  const auto t0 = std::chrono::steady_clock::now();
  repulsion_exact(mu, 0.01, &exact_grad);
  const double ms_exact =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "repulsion K = 10^4, sigma = 0.01, %d threads, median of 15: float %.2f ms, double %.2f ms"
      " (exact oracle, 1 thread, %.0f ms)\n",
      max_threads(), ms_f, ms_d, ms_exact);
}
