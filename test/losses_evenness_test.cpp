// L_even (losses/evenness.h): the mixture's log-density against the all-pairs
// oracle within the stated cut-off bound, a one-Gaussian case by hand, the tape
// ops against central finite differences, and L_even zero exactly when the
// area element follows P's density.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/gradcheck.h"
#include "engine/ops.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/evenness.h"

using namespace jsa;

namespace {

Block<double> uniform(Index rows, Index cols, double lo, double hi, uint64_t seed) {
  Rng rng(seed);
  Block<double> b(rows, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = rng.uniform(lo, hi);
  return b;
}

Block<double> log_density(const Block<double>& x, const Block<double>& mu, double sigma,
                          const MixtureDensityOptions& o = {}) {
  Tape<double> t;
  return t.value(mixture_log_density(t, t.constant(x), t.constant(mu), sigma, o));
}

}  // namespace

TEST_CASE("mixture log-density: the cut-off stays within its bound of the exact sum",
          "[evenness]") {
  // K = 2500 means in the unit square, sigma = 1/sqrt(K) (Eq. 4): many cells.
  // Points inside the square, and a few far outside it (the exact fallback).
  const Index K = 2500;
  const double sigma = 1 / std::sqrt(double(K));
  const Block<double> mu = uniform(K, 2, 0, 1, 1);
  Block<double> x = uniform(400, 2, -0.05, 1.05, 2);
  x.row(0) << 3, 3;
  x.row(1) << -2, 0.5;
  x.row(2) << 0.5, 1.2;  // 0.2 above the square: 10 sigma, beyond the cut-off
  const Block<double> exact = mixture_log_density_exact(x, mu, sigma);
  for (double tolerance : {1e-10, 1e-6}) {
    INFO("tolerance " << tolerance);
    MixtureDensityOptions o;
    o.tolerance = tolerance;
    const Block<double> fast = log_density(x, mu, sigma, o);
    // The header's bound: dropped mass < K tolerance, or the exact sum.
    for (Index n = 0; n < x.rows(); ++n) {
      const double bound = std::min(1e-3, double(K) * tolerance / std::exp(exact(n, 0)));
      CHECK(exact(n, 0) - fast(n, 0) >= -1e-12);  // only ever drops terms
      CHECK(exact(n, 0) - fast(n, 0) <= bound * 1.0001 + 1e-12);
    }
  }
  // The far points took the exact sum: equal to rounding.
  const Block<double> fast = log_density(x, mu, sigma);
  CHECK(fast(0, 0) == Approx(exact(0, 0)).epsilon(1e-12));
  CHECK(fast(1, 0) == Approx(exact(1, 0)).epsilon(1e-12));
}

TEST_CASE("mixture log-density of one Gaussian by hand", "[evenness]") {
  // K = 1: l(x) = -|x - mu|^2 / (2 sigma^2), dl/dx = -(x - mu) / sigma^2 = -dl/dmu.
  Block<double> mu(1, 2), x(2, 2);
  mu << 0.5, -0.25;
  x << 0.7, -0.25, 0.5, 0.15;
  const double sigma = 0.2;
  Tape<double> t;
  const Var vx = t.variable(x), vm = t.variable(mu);
  const Var l = mixture_log_density(t, vx, vm, sigma);
  CHECK(t.value(l)(0, 0) == Approx(-0.04 / 0.08).epsilon(1e-12));
  CHECK(t.value(l)(1, 0) == Approx(-0.16 / 0.08).epsilon(1e-12));
  t.backward(sum(t, l));
  CHECK(t.grad(vx)(0, 0) == Approx(-0.2 / 0.04).epsilon(1e-12));
  CHECK(t.grad(vx)(0, 1) == Approx(0).margin(1e-12));
  CHECK(t.grad(vx)(1, 1) == Approx(-0.4 / 0.04).epsilon(1e-12));
  CHECK(t.grad(vm)(0, 0) == Approx(0.2 / 0.04).epsilon(1e-12));
  CHECK(t.grad(vm)(0, 1) == Approx(0.4 / 0.04).epsilon(1e-12));
}

TEST_CASE("mixture log-density passes the finite-difference check in x and mu", "[evenness]") {
  // sigma = 0.3 over the unit square: r_c = 0.3 sqrt(2 ln 1e10) ~ 2.0 covers it,
  // so every term is kept and the function is smooth under the step. Two points
  // 5 away (S ~ e^-139) take the exact, shifted sum.
  const Block<double> mu = uniform(15, 2, 0, 1, 3);
  Block<double> x = uniform(10, 2, -0.2, 1.2, 4);
  x.row(0) << 5.5, 0.5;
  x.row(1) << 0.3, -4.6;
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) {
        return mixture_log_density(t, v[0], v[1], 0.3);
      },
      {x, mu});
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("mixture log-density: the gradients do not depend on the thread count", "[evenness]") {
  const Block<float> mu = uniform(3000, 2, 0, 1, 5).cast<float>();
  const Block<float> x = uniform(3000, 2, 0, 1, 6).cast<float>();
  const Block<float> weights = uniform(3000, 1, -1, 1, 7).cast<float>();
  Block<float> first_x, first_mu, first_l;
  const int before = max_threads();
  for (int threads : {1, 2}) {
    set_threads(threads);
    Tape<float> t;
    const Var vx = t.variable(x), vm = t.variable(mu);
    const Var l = mixture_log_density(t, vx, vm, 1 / std::sqrt(3000.0f));
    t.backward(sum(t, mul(t, l, t.constant(weights))));
    if (threads == 1) {
      first_l = t.value(l);
      first_x = t.grad(vx);
      first_mu = t.grad(vm);
    } else {
      CHECK(t.value(l) == first_l);
      CHECK(t.grad(vx) == first_x);
      CHECK(t.grad(vm) == first_mu);
    }
  }
  set_threads(before);
}

TEST_CASE("L_even is zero when the area element follows P's density, and by hand otherwise",
          "[evenness]") {
  // One Gaussian at 0, sigma = 0.5: l_m = log p(x_m) + const = -|x_m|^2 / (2 sigma^2).
  // J_u = (a_m, 0, 0), J_v = (0, 1, 0): area element a_m.
  Block<double> mu = Block<double>::Zero(1, 2), x(3, 2);
  x << 0.1, 0.2, -0.4, 0.3, 0.6, -0.5;
  const double sigma = 0.5;
  auto loss = [&](const Block<double>& a) {
    Tape<double> t;
    Block<double> du = Block<double>::Zero(3, 3), dv = Block<double>::Zero(3, 3);
    du.col(0) = a;
    dv.col(1).setOnes();
    return t.scalar(
        evenness_loss(t, t.constant(x), t.constant(mu), sigma, t.constant(du), t.constant(dv)));
  };
  Block<double> p(3, 1), ones = Block<double>::Ones(3, 1);
  for (Index m = 0; m < 3; ++m) p(m, 0) = std::exp(-x.row(m).squaredNorm() / (2 * sigma * sigma));
  CHECK(loss(p) == Approx(0).margin(1e-12));
  CHECK(loss(Block<double>(7.5 * p)) == Approx(0).margin(1e-12));  // any surface area
  // a = 1: L = Var_m(-|x_m|^2 / (2 sigma^2)) = Var(-0.1, -0.5, -1.22).
  const double l0 = -0.1, l1 = -0.5, l2 = -1.22, mean = (l0 + l1 + l2) / 3;
  const double var =
      ((l0 - mean) * (l0 - mean) + (l1 - mean) * (l1 - mean) + (l2 - mean) * (l2 - mean)) / 3;
  CHECK(loss(ones) == Approx(var).epsilon(1e-10));
}

TEST_CASE("L_even passes the finite-difference check in x, mu and the Jacobian", "[evenness]") {
  Rng rng(8);
  const Block<double> mu = uniform(6, 2, 0, 1, 9), x = uniform(8, 2, 0, 1, 10);
  // Jacobian columns well away from parallel: the area element stays far from 0.
  Block<double> du = uniform(8, 3, -0.3, 0.3, 11), dv = uniform(8, 3, -0.3, 0.3, 12);
  du.col(0).array() += 1;
  dv.col(1).array() += 1;
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) {
        return evenness_loss(t, v[0], v[1], 0.4, v[2], v[3]);
      },
      {x, mu, du, dv});
  INFO(r.report);
  CHECK(r.ok);
}
