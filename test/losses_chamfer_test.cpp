// The Chamfer op (Eq. 6): value against a brute-force double loop, gradients
// against finite differences, and accumulation when many points share a match.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <limits>

#include "engine/gradcheck.h"
#include "engine/ops.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/chamfer.h"
#include "test/uniform_block.h"

using namespace jsa;
using test_support::uniform_block;

namespace {

// 1/N sum_i min_j |x_i - y_j|^2, the obvious way.
double one_way(const Block<double>& x, const Block<double>& y) {
  double s = 0;
  for (Index i = 0; i < x.rows(); ++i) {
    double best = std::numeric_limits<double>::infinity();
    for (Index j = 0; j < y.rows(); ++j) best = std::min(best, (x.row(i) - y.row(j)).squaredNorm());
    s += best;
  }
  return s / double(x.rows());
}

// The gap between the nearest and the second-nearest squared distance of each
// query, minimised over queries: if it is far above the finite-difference step,
// no match can flip while the gradient checker perturbs one coordinate.
double smallest_match_gap(const Block<double>& x, const Block<double>& y) {
  double gap = std::numeric_limits<double>::infinity();
  for (Index i = 0; i < x.rows(); ++i) {
    double d1 = std::numeric_limits<double>::infinity(), d2 = d1;
    for (Index j = 0; j < y.rows(); ++j) {
      const double d = (x.row(i) - y.row(j)).squaredNorm();
      if (d < d1) {
        d2 = d1;
        d1 = d;
      } else {
        d2 = std::min(d2, d);
      }
    }
    gap = std::min(gap, d2 - d1);
  }
  return gap;
}

}  // namespace

TEST_CASE("chamfer value equals the brute-force double loop", "[chamfer]") {
  for (Index c : {2, 3, 6}) {
    const Block<double> x = uniform_block(300, c, 100 + c), y = uniform_block(250, c, 200 + c);
    const double expected = one_way(x, y) + one_way(y, x);
    Tape<double> t;
    ChamferMatches<double> m;
    Var loss = chamfer(t, t.constant(x), t.constant(y), &m);
    CHECK(t.scalar(loss) == Approx(expected).epsilon(1e-12));
    CHECK(chamfer_distance(x, y) == Approx(expected).epsilon(1e-12));
    REQUIRE(m.x_to_y.size() == 300);
    REQUIRE(m.y_to_x.size() == 250);
    REQUIRE(m.x_squared_distance.size() == 300);
    for (Index i = 0; i < x.rows(); ++i)
      CHECK(m.x_squared_distance[i] == Approx((x.row(i) - y.row(m.x_to_y[i])).squaredNorm()));
    // float agrees with double to float precision
    const Block<float> xf = x.cast<float>(), yf = y.cast<float>();
    CHECK(chamfer_distance(xf, yf) == Approx(expected).epsilon(1e-5));
  }
}

TEST_CASE("chamfer of a set with itself is zero", "[chamfer]") {
  const Block<double> x = uniform_block(100, 3, 7);
  CHECK(chamfer_distance(x, x) == 0);
}

TEST_CASE("chamfer gradient passes the finite-difference check", "[chamfer]") {
  // Random points are in general position: the nearest and second-nearest
  // squared distances of every query differ by far more than the step (1e-6
  // relative), so no match flips during the check and the loss is smooth there.
  const Block<double> x = uniform_block(40, 3, 300), y = uniform_block(30, 3, 301);
  REQUIRE(smallest_match_gap(x, y) > 1e-4);
  REQUIRE(smallest_match_gap(y, x) > 1e-4);
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return chamfer(t, v[0], v[1]); }, {x, y});
  INFO(r.report);
  CHECK(r.ok);

  // 2D, the L_2D shape, and chamfer feeding further ops (gradient scaled on the way).
  const Block<double> u = uniform_block(25, 2, 310), w = uniform_block(35, 2, 311);
  REQUIRE(smallest_match_gap(u, w) > 1e-4);
  REQUIRE(smallest_match_gap(w, u) > 1e-4);
  const GradCheckResult r2 = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) {
        return scale(t, chamfer(t, v[0], v[1]), 3.0);
      },
      {u, w});
  INFO(r2.report);
  CHECK(r2.ok);
}

TEST_CASE("chamfer accumulates gradients on shared matches", "[chamfer]") {
  // y_0 is near the eight x, y_1 and y_2 far away: every a_i = 0, so
  // y_0 collects eight pull-backs, and y_1, y_2 both match the x of largest
  // first coordinate, which collects two.
  Block<double> y(3, 2);
  y << 0, 0, 10, 0, 10, 1;
  Rng rng(400);
  Block<double> x(8, 2);
  for (Index i = 0; i < x.rows(); ++i) x.row(i) << rng.uniform(-0.5, 0.5), rng.uniform(-0.5, 0.5);

  Tape<double> t;
  ChamferMatches<double> m;
  Var vx = t.variable(x), vy = t.variable(y);
  Var loss = chamfer(t, vx, vy, &m);
  t.backward(loss);
  for (int a : m.x_to_y) CHECK(a == 0);
  CHECK(m.y_to_x[1] == m.y_to_x[2]);

  // The gradient of y, written out from the formula in chamfer.h.
  const double N = 8, M = 3;
  Block<double> dy = Block<double>::Zero(3, 2), dx = Block<double>::Zero(8, 2);
  for (Index i = 0; i < 8; ++i) {
    dx.row(i) += 2 / N * (x.row(i) - y.row(0));
    dy.row(0) -= 2 / N * (x.row(i) - y.row(0));
  }
  for (Index j = 0; j < 3; ++j) {
    const Index b = m.y_to_x[j];
    dy.row(j) += 2 / M * (y.row(j) - x.row(b));
    dx.row(b) -= 2 / M * (y.row(j) - x.row(b));
  }
  CHECK((t.grad(vy) - dy).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((t.grad(vx) - dx).cwiseAbs().maxCoeff() < 1e-12);

  // And the finite-difference check agrees (the matches are stable, see above).
  REQUIRE(smallest_match_gap(x, y) > 1e-4);
  REQUIRE(smallest_match_gap(y, x) > 1e-4);
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) { return chamfer(t, v[0], v[1]); }, {x, y});
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("chamfer with a constant side only differentiates the other", "[chamfer]") {
  const Block<float> x = uniform_block(50, 6, 500).cast<float>(),
                     y = uniform_block(60, 6, 501).cast<float>();
  Tape<float> t;
  Var vx = t.variable(x), vy = t.constant(y);
  Var loss = chamfer(t, vx, vy);
  t.backward(loss);
  CHECK(t.grad(vx).rows() == 50);
  CHECK(t.grad(vx).allFinite());
  CHECK(!t.needs_grad(vy));
  // Reusing the tape gives the same numbers (storage kept between steps).
  const Block<float> first = t.grad(vx);
  t.clear();
  vx = t.variable(x);
  vy = t.constant(y);
  loss = chamfer(t, vx, vy);
  t.backward(loss);
  CHECK(t.grad(vx) == first);
}

TEST_CASE("chamfer gradients do not depend on the thread count", "[chamfer]") {
  // Enough rows that the own-row pull-back runs in several parallel chunks.
  const Block<float> x = uniform_block(9000, 3, 700).cast<float>();
  const Block<float> y = uniform_block(7000, 3, 701).cast<float>();
  auto gradients = [&](int threads) {
    set_threads(threads);
    Tape<float> t;
    Var vx = t.variable(x), vy = t.variable(y);
    t.backward(chamfer(t, vx, vy));
    return std::make_pair(Block<float>(t.grad(vx)), Block<float>(t.grad(vy)));
  };
  const int threads = max_threads();
  const auto one = gradients(1), two = gradients(std::max(2, threads));
  set_threads(threads);
  CHECK(one.first == two.first);
  CHECK(one.second == two.second);
}

TEST_CASE("dense chamfer: x searches the pool, y searches x", "[chamfer]") {
  // Value: 1/N sum_i min over the pool + 1/M sum_j min over x, by double loops.
  for (Index c : {3, 6}) {
    const Block<double> x = uniform_block(120, c, 800 + c), y = uniform_block(90, c, 810 + c);
    const Block<double> pool = uniform_block(2000, c, 820 + c);
    const NearestIndex<double> surface(pool);
    const double expected = one_way(x, pool) + one_way(y, x);
    Tape<double> t;
    ChamferMatches<double> m;
    Var loss = chamfer(t, t.constant(x), t.constant(y), surface, &m);
    CHECK(t.scalar(loss) == Approx(expected).epsilon(1e-12));
    // The pool is far denser than y, so the dense first term is smaller.
    CHECK(one_way(x, pool) < one_way(x, y));
    for (Index i = 0; i < x.rows(); ++i)
      CHECK(m.x_squared_distance[size_t(i)] ==
            Approx((x.row(i) - pool.row(m.x_to_y[size_t(i)])).squaredNorm()));
  }
  // When the pool is y itself, the dense op is Eq. (6) exactly, gradients too.
  const Block<double> x = uniform_block(60, 6, 830), y = uniform_block(50, 6, 831);
  const NearestIndex<double> same(y);
  Tape<double> t1, t2;
  Var x1 = t1.variable(x), x2 = t2.variable(x);
  t1.backward(chamfer(t1, x1, t1.constant(y)));
  t2.backward(chamfer(t2, x2, t2.constant(y), same));
  CHECK((t1.grad(x1) - t2.grad(x2)).cwiseAbs().maxCoeff() < 1e-14);
}

TEST_CASE("dense chamfer gradient passes the finite-difference check", "[chamfer]") {
  // x and y are variables, the pool a constant: dL/dy has only the own-row
  // term (y's matches in x), dL/dx both. Matches are stable (general position).
  const Block<double> x = uniform_block(40, 6, 840), y = uniform_block(30, 6, 841);
  const Block<double> pool = uniform_block(500, 6, 842);
  REQUIRE(smallest_match_gap(x, pool) > 1e-4);
  REQUIRE(smallest_match_gap(y, x) > 1e-4);
  const NearestIndex<double> surface(pool);
  const GradCheckResult r = check_gradients(
      [&](Tape<double>& t, const std::vector<Var>& v) { return chamfer(t, v[0], v[1], surface); },
      {x, y});
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("chamfer's coverage weight scales the second direction, value and gradient",
          "[chamfer]") {
  // L_w = 1/N sum_i min_j |x_i - y_j|^2 + w/M sum_j min_i |y_j - x_i|^2, plain and dense.
  const Block<double> x = uniform_block(40, 6, 850), y = uniform_block(30, 6, 851);
  const Block<double> pool = uniform_block(500, 6, 852);
  REQUIRE(smallest_match_gap(x, y) > 1e-4);
  REQUIRE(smallest_match_gap(y, x) > 1e-4);
  REQUIRE(smallest_match_gap(x, pool) > 1e-4);
  const NearestIndex<double> surface(pool);
  ChamferMatches<double>* const none = nullptr;
  for (double w : {0.0, 2.5}) {
    Tape<double> t;
    CHECK(t.scalar(chamfer(t, t.constant(x), t.constant(y), none, w)) ==
          Approx(one_way(x, y) + w * one_way(y, x)).epsilon(1e-12));
    CHECK(t.scalar(chamfer(t, t.constant(x), t.constant(y), surface, none, w)) ==
          Approx(one_way(x, pool) + w * one_way(y, x)).epsilon(1e-12));
    const GradCheckResult plain = check_gradients(
        [w, none](Tape<double>& t, const std::vector<Var>& v) {
          return chamfer(t, v[0], v[1], none, w);
        },
        {x, y});
    INFO("w = " << w << ": " << plain.report);
    CHECK(plain.ok);
    const GradCheckResult dense = check_gradients(
        [&](Tape<double>& t, const std::vector<Var>& v) {
          return chamfer(t, v[0], v[1], surface, none, w);
        },
        {x, y});
    INFO("dense, w = " << w << ": " << dense.report);
    CHECK(dense.ok);
  }
  Tape<double> t;
  CHECK_THROWS(chamfer(t, t.constant(x), t.constant(y), none, -1.0));
}

TEST_CASE("chamfer timing at training-loop sizes", "[.bench][chamfer]") {
  // L_6D shape: 10^4 x 10^4 points in 6 columns, float, forward + backward:
  // xyz in a cube, the last three columns scaled to ~0.01 like the normals.
  Block<float> x = uniform_block(10000, 6, 600).cast<float>();
  Block<float> y = uniform_block(10000, 6, 601).cast<float>();
  x.rightCols(3) *= 0.01f;
  y.rightCols(3) *= 0.01f;
  Tape<float> t;
  std::vector<double> ms;
  for (int r = 0; r < 15; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    t.clear();
    Var vx = t.variable(x), vy = t.constant(y);
    t.backward(chamfer(t, vx, vy));
    ms.push_back(
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  std::printf(
      "chamfer 10^4 x 10^4 x 6 (xyz + 0.01 normals), forward + backward, median of 15: %.2f ms\n",
      ms[ms.size() / 2]);
}
