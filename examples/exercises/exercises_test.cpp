// Tests of the three exercises (exercises.h), tagged [exercise]. Each fails on
// the blank version and passes once the piece is right; the oracles are the
// engine's own gradient checker (central differences) and Dual<double, 2>.
#include "examples/exercises/exercises.h"

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "engine/gradcheck.h"
#include "engine/ops.h"
#include "engine/rng.h"
#include "engine/tangents.h"

namespace jsa::exercise {
namespace {

Block<double> random_block(Rng& rng, Index rows, Index cols) {
  Block<double> b(rows, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = rng.uniform(-1.5, 1.5);
  return b;
}

}  // namespace

TEST_CASE("exercise 1a: the dual rule of tanh", "[exercise]") {
  // f = tanh(u v) at (u, v) = (0.7, -0.4): f_u = tanh'(uv) v, f_v = tanh'(uv) u.
  const Dual2 f = tanh(Dual2::variable(0.7, 0) * Dual2::variable(-0.4, 1));
  const double s1 = 1 - std::pow(std::tanh(-0.28), 2);
  CHECK(f.a == Approx(std::tanh(-0.28)));
  CHECK(f.v[0] == Approx(s1 * -0.4));
  CHECK(f.v[1] == Approx(s1 * 0.7));
}

TEST_CASE("exercise 1b: tanh_stacked's value and tangent rows equal Dual<double, 2>",
          "[exercise]") {
  // A 2-5-3 network tanh(x W1 + b1) W2 on stacked rows against the same with
  // duals (using your rule from 1a and the engine's linear).
  Rng rng(2);
  const Block<double> x = random_block(rng, 4, 2), w1 = random_block(rng, 2, 5),
                      b1 = random_block(rng, 1, 5), w2 = random_block(rng, 5, 3);
  Tape<double> t;
  const Var h = tanh_stacked(
      t, linear(t, stack_tangents(t, t.constant(x)), t.constant(w1), t.constant(b1), 4), 4);
  const Block<double> y = t.value(linear(t, h, t.constant(w2), Var{}));
  double worst = 0;
  for (Index i = 0; i < 4; ++i) {
    std::vector<Dual2> z(5);
    for (Index j = 0; j < 5; ++j) {
      Dual2 s(b1(0, j));
      s += Dual2::variable(x(i, 0), 0) * Dual2(w1(0, j));
      s += Dual2::variable(x(i, 1), 1) * Dual2(w1(1, j));
      z[size_t(j)] = tanh(s);
    }
    for (Index c = 0; c < 3; ++c) {
      Dual2 o;
      for (Index j = 0; j < 5; ++j) o += z[size_t(j)] * Dual2(w2(j, c));
      worst = std::max({worst, std::abs(y(i, c) - o.a), std::abs(y(4 + i, c) - o.v[0]),
                        std::abs(y(8 + i, c) - o.v[1])});
    }
  }
  CHECK(y.cwiseAbs().maxCoeff() > 0.1);  // not all zero
  CHECK(worst < 1e-12);
}

TEST_CASE("exercise 1b: tanh_stacked's pull-back passes the gradient check", "[exercise]") {
  Rng rng(3);
  const GraphBuilder f = [](Tape<double>& t, const std::vector<Var>& in) {
    return tanh_stacked(t, in[0], 4);
  };
  const Block<double> x = random_block(rng, 12, 3);  // 3 blocks of 4 rows
  Tape<double> t;
  const Block<double> y = t.value(tanh_stacked(t, t.constant(x), 4));
  CHECK((y.topRows(4).array() - x.topRows(4).array().tanh()).abs().maxCoeff() <
        1e-15);  // the value rows
  const GradCheckResult r = check_gradients(f, {x});
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("exercise 2: normalize_rows's pull-back passes the gradient check", "[exercise]") {
  Rng rng(4);
  const GraphBuilder f = [](Tape<double>& t, const std::vector<Var>& in) {
    return normalize_rows(t, in[0]);
  };
  const GradCheckResult r =
      check_gradients(f, {random_block(rng, 6, 3)});  // |x_i| well away from 0
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("exercise 3: the hand-written gradient of L_iso equals the tape's", "[exercise]") {
  Rng rng(5);
  const Block<double> du = random_block(rng, 7, 3), dv = random_block(rng, 7, 3);
  Block<double> d_du, d_dv;
  const double mine = isometry_grad(du, dv, d_du, d_dv);
  Tape<double> t;  // the same loss from the engine's ops (as losses/isometry.cpp)
  const Var u = t.variable(du), v = t.variable(dv);
  const Var e = offset(t, row_dot(t, u, u), -1.0), g = offset(t, row_dot(t, v, v), -1.0),
            f = row_dot(t, u, v);
  const Var l = mean(t, add(t, add(t, square(t, e), square(t, g)), scale(t, square(t, f), 2.0)));
  t.backward(l);
  CHECK(mine == Approx(t.scalar(l)));
  CHECK((d_du - t.grad(u)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((d_dv - t.grad(v)).cwiseAbs().maxCoeff() < 1e-12);
}

}  // namespace jsa::exercise
