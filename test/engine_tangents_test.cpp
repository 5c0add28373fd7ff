// Tests of engine/tangents.h: the stacked-tangent Jacobian of a 2-16-16-3 ReLU
// MLP against two independent oracles (Dual<double, 2> forward mode, and central
// differences of the value output), then gradients *through* the Jacobian (the
// normals of Eq. 2 and the J^T J isometry term of Eq. 10) against check_gradients.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/dual.h"
#include "engine/tangents.h"
#include "test/engine_gradcheck_cases.h"

namespace jsa::test {
namespace {

constexpr Index kPoints = 6;
constexpr int kWidths[] = {2, 16, 16, 3};

// W1, b1, W2, b2, W3, b3 with a uniform fan-in scale.
std::vector<Block<double>> mlp_weights(uint64_t seed) {
  Rng rng(seed);
  std::vector<Block<double>> p;
  for (int l = 0; l < 3; ++l) {
    const double s = std::sqrt(6.0 / kWidths[l]);
    p.push_back(uniform_block(rng, kWidths[l], kWidths[l + 1], -s, s));
    p.push_back(uniform_block(rng, 1, kWidths[l + 1], -0.5, 0.5));
  }
  return p;
}

// The network on the tape, stacked: [x; e_u; e_v] -> [f; f_u; f_v].
// p = {W1, b1, W2, b2, W3, b3}. beta = 0: ReLU; beta > 0: softplus.
Stacked mlp_stacked(Tape<double>& t, Var x, const std::vector<Var>& p, double beta = 0) {
  const Index n = t.rows(x);
  auto act = [&](Var z) {
    return beta > 0 ? softplus_stacked(t, z, n, beta) : relu_masked(t, z, n);
  };
  Var h = stack_tangents(t, x);
  h = act(linear(t, h, p[0], p[1], n));
  h = act(linear(t, h, p[2], p[3], n));
  return unstack(t, linear(t, h, p[4], p[5], n));
}

// The same network evaluated with dual numbers, one point at a time, written
// without the engine: the independent oracle. Also reports the smallest
// |pre-activation| seen, so tests can assert they are away from ReLU kinks.
// beta = 0: ReLU; beta > 0: softplus (engine/dual.h's softplus rule).
using D = Dual<double, 2>;
std::vector<D> mlp_dual(const std::vector<Block<double>>& p, double u, double v, double* min_preact,
                        double beta = 0) {
  std::vector<D> h = {D::variable(u, 0), D::variable(v, 1)};
  for (int l = 0; l < 3; ++l) {
    const Block<double>& w = p[2 * l];
    const Block<double>& b = p[2 * l + 1];
    std::vector<D> out(w.cols());
    for (Index j = 0; j < w.cols(); ++j) {
      D z(b(0, j));
      for (Index i = 0; i < w.rows(); ++i) z += h[i] * D(w(i, j));
      if (l < 2) {
        *min_preact = std::min(*min_preact, std::abs(z.a));
        z = beta > 0 ? softplus(z, beta) : relu(z);
      }
      out[j] = z;
    }
    h = out;
  }
  return h;
}

// Points in [-1, 1]^2 (a 2D domain, as phi's input).
Block<double> points(uint64_t seed) {
  Rng rng(seed);
  return uniform_block(rng, kPoints, 2, -1.0, 1.0);
}

}  // namespace

std::vector<GradCase> jacobian_cases() {
  const std::vector<Block<double>> w = mlp_weights(11);
  std::vector<Block<double>> inputs = {points(12)};
  inputs.insert(inputs.end(), w.begin(), w.end());
  // Nested compositions of ~50 ops: a looser atol absorbs finite-difference
  // round-off (~1e-10 relative to the loss) on entries whose gradient is ~0.
  GradCheckOptions o;
  o.atol = 1e-7;
  std::vector<GradCase> cases;

  // n = normalize(J_u x J_v) (Eq. 2 with alpha = 1).
  cases.push_back({"MLP normals (weights + points)",
                   [](Tape<double>& t, const std::vector<Var>& v) {
                     const Stacked s = mlp_stacked(t, v[0], {v.begin() + 1, v.end()});
                     return row_normalize(t, cross3(t, s.du, s.dv));
                   },
                   inputs, o});
  // mean((E - 1)^2 + (G - 1)^2 + 2 F^2) with E = J_u.J_u, F = J_u.J_v, G = J_v.J_v.
  cases.push_back(
      {"MLP J^T J isometry (weights + points)",
       [](Tape<double>& t, const std::vector<Var>& v) {
         const Stacked s = mlp_stacked(t, v[0], {v.begin() + 1, v.end()});
         Var e = row_dot(t, s.du, s.du), f = row_dot(t, s.du, s.dv), g = row_dot(t, s.dv, s.dv);
         Var iso = add(t, add(t, square(t, offset(t, e, -1.0)), square(t, offset(t, g, -1.0))),
                       scale(t, square(t, f), 2.0));
         return mean(t, iso);
       },
       inputs, o});
  // The value rows too, so the check also sees d(loss)/d(points) non-zero (a ReLU
  // net's J is piecewise constant in x, so the two losses above have zero
  // gradient w.r.t. the points: checked, but trivially).
  cases.push_back({"MLP value + normals (weights + points)",
                   [](Tape<double>& t, const std::vector<Var>& v) {
                     const Stacked s = mlp_stacked(t, v[0], {v.begin() + 1, v.end()});
                     return concat_cols(t, {s.value, row_normalize(t, cross3(t, s.du, s.dv))});
                   },
                   inputs, o});
  // Softplus (beta = 2, well inside its curved part): J now varies with x, so
  // these exercise the second-derivative path of softplus_stacked's pull-back
  // into the points as well as the weights.
  cases.push_back({"softplus MLP normals (weights + points)",
                   [](Tape<double>& t, const std::vector<Var>& v) {
                     const Stacked s = mlp_stacked(t, v[0], {v.begin() + 1, v.end()}, 2.0);
                     return row_normalize(t, cross3(t, s.du, s.dv));
                   },
                   inputs, o});
  cases.push_back(
      {"softplus MLP J^T J isometry (weights + points)",
       [](Tape<double>& t, const std::vector<Var>& v) {
         const Stacked s = mlp_stacked(t, v[0], {v.begin() + 1, v.end()}, 2.0);
         Var e = row_dot(t, s.du, s.du), f = row_dot(t, s.du, s.dv), g = row_dot(t, s.dv, s.dv);
         return mean(t, add(t, add(t, square(t, offset(t, e, -1.0)), square(t, offset(t, g, -1.0))),
                            scale(t, square(t, f), 2.0)));
       },
       inputs, o});
  return cases;
}

TEST_CASE("test MLP is away from ReLU kinks", "[tangents]") {
  // Every pre-activation must be far from 0 compared with a finite-difference
  // step (1e-6 relative), or the checks below would straddle a kink.
  const auto w = mlp_weights(11);
  const Block<double> x = points(12);
  double min_preact = 1e300;
  for (Index i = 0; i < x.rows(); ++i) mlp_dual(w, x(i, 0), x(i, 1), &min_preact);
  INFO("smallest |pre-activation| " << min_preact);
  CHECK(min_preact > 1e-3);
}

TEST_CASE("stacked-tangent Jacobian equals Dual<double,2> and finite differences", "[tangents]") {
  const auto w = mlp_weights(11);
  const Block<double> x = points(12);
  Tape<double> t;
  std::vector<Var> p;
  for (const auto& b : w) p.push_back(t.constant(b));
  const Stacked s = mlp_stacked(t, t.constant(x), p);
  const Block<double>& f = t.value(s.value);
  const Block<double>& fu = t.value(s.du);
  const Block<double>& fv = t.value(s.dv);
  REQUIRE(f.rows() == kPoints);
  REQUIRE(f.cols() == 3);

  double min_preact = 1e300, worst_dual = 0, worst_fd = 0;
  for (Index i = 0; i < kPoints; ++i) {
    const std::vector<D> d = mlp_dual(w, x(i, 0), x(i, 1), &min_preact);
    // Central differences of the value, step 1e-6: truncation error is zero on a
    // piecewise-linear net (away from kinks), round-off ~1e-10.
    const double h = 1e-6;
    Tape<double> tp;
    std::vector<Var> pp;
    for (const auto& b : w) pp.push_back(tp.constant(b));
    Block<double> xs(4, 2);
    xs << x(i, 0) + h, x(i, 1),  //
        x(i, 0) - h, x(i, 1),    //
        x(i, 0), x(i, 1) + h,    //
        x(i, 0), x(i, 1) - h;
    const Block<double> g = tp.value(mlp_stacked(tp, tp.constant(xs), pp).value);
    for (Index c = 0; c < 3; ++c) {
      worst_dual = std::max({worst_dual, std::abs(f(i, c) - d[c].a), std::abs(fu(i, c) - d[c].v[0]),
                             std::abs(fv(i, c) - d[c].v[1])});
      const double fd_u = (g(0, c) - g(1, c)) / (2 * h), fd_v = (g(2, c) - g(3, c)) / (2 * h);
      worst_fd = std::max({worst_fd, std::abs(fu(i, c) - fd_u), std::abs(fv(i, c) - fd_v)});
    }
  }
  INFO("max |tape - dual| " << worst_dual << ", max |tape - finite difference| " << worst_fd
                            << ", smallest |pre-activation| " << min_preact);
  CHECK(min_preact > 1e-3);
  CHECK(worst_dual < 1e-12);  // same arithmetic up to summation order
  CHECK(worst_fd < 1e-7);
  // And the Jacobian is not trivially zero.
  CHECK(fu.cwiseAbs().maxCoeff() > 0.1);
  CHECK(fv.cwiseAbs().maxCoeff() > 0.1);
}

TEST_CASE("softplus stacked tangents equal finite differences of the value", "[tangents]") {
  const auto w = mlp_weights(11);
  const Block<double> x = points(12);
  for (double beta : {0.5, 2.0, 50.0}) {
    Tape<double> t;
    std::vector<Var> p;
    for (const auto& b : w) p.push_back(t.constant(b));
    const Stacked s = mlp_stacked(t, t.constant(x), p, beta);
    double worst = 0, largest = 0;
    for (Index i = 0; i < kPoints; ++i) {
      // Central differences, step 1e-5: truncation ~h^2 times the third
      // derivative (beta^2 scale), round-off ~1e-11.
      const double h = 1e-5;
      Block<double> xs(4, 2);
      xs << x(i, 0) + h, x(i, 1), x(i, 0) - h, x(i, 1), x(i, 0), x(i, 1) + h, x(i, 0), x(i, 1) - h;
      Tape<double> tp;
      std::vector<Var> pp;
      for (const auto& b : w) pp.push_back(tp.constant(b));
      const Block<double> g = tp.value(mlp_stacked(tp, tp.constant(xs), pp, beta).value);
      for (Index c = 0; c < 3; ++c) {
        const double fd_u = (g(0, c) - g(1, c)) / (2 * h), fd_v = (g(2, c) - g(3, c)) / (2 * h);
        worst = std::max(
            {worst, std::abs(t.value(s.du)(i, c) - fd_u), std::abs(t.value(s.dv)(i, c) - fd_v)});
        largest = std::max({largest, std::abs(fd_u), std::abs(fd_v)});
      }
    }
    INFO("beta " << beta << ": max |tape - finite difference| " << worst << ", largest entry "
                 << largest);
    CHECK(worst < 1e-6);
    CHECK(largest > 0.1);
  }
}

// The default activation's second oracle: the stacked-tangent softplus
// Jacobian against Dual<double, 2> through engine/dual.h's softplus rule (the
// test above is the first: finite differences of the value rows).
TEST_CASE("softplus stacked-tangent Jacobian equals Dual<double,2>", "[tangents][dual]") {
  const auto w = mlp_weights(11);
  const Block<double> x = points(12);
  for (double beta : {0.5, 2.0, 40.0}) {
    Tape<double> t;
    std::vector<Var> p;
    for (const auto& b : w) p.push_back(t.constant(b));
    const Stacked s = mlp_stacked(t, t.constant(x), p, beta);
    double worst = 0, largest = 0, min_preact = 1e9;
    for (Index i = 0; i < kPoints; ++i) {
      const std::vector<D> f = mlp_dual(w, x(i, 0), x(i, 1), &min_preact, beta);
      for (Index c = 0; c < 3; ++c) {
        worst = std::max({worst, std::abs(t.value(s.value)(i, c) - f[c].a),
                          std::abs(t.value(s.du)(i, c) - f[c].v[0]),
                          std::abs(t.value(s.dv)(i, c) - f[c].v[1])});
        largest = std::max({largest, std::abs(f[c].v[0]), std::abs(f[c].v[1])});
      }
    }
    INFO("beta " << beta << ": max |tape - dual| " << worst << ", largest entry " << largest);
    CHECK(worst < 1e-12);  // the same arithmetic in another order: rounding only
    CHECK(largest > 0.1);
  }
}

TEST_CASE("softplus values, and ReLU as beta grows", "[ops]") {
  Tape<double> t;
  Block<double> z(2, 3);
  z << -2, 0, 3,       //
      0.5, -800, 800;  // exp(800) would overflow without the stable form
  Block<double> y = t.value(softplus_stacked(t, t.constant(z), 2, 1.0));
  for (Index i = 0; i < 2; ++i)
    for (Index j = 0; j < 3; ++j) {
      const double expect =
          std::abs(z(i, j)) > 50 ? std::max(z(i, j), 0.0) : std::log1p(std::exp(z(i, j)));
      CHECK(y(i, j) == Approx(expect).margin(1e-300));
    }
  const Block<double> r = t.value(relu_masked(t, t.constant(z), 2));
  const Block<double> sharp = t.value(softplus_stacked(t, t.constant(z), 2, 1e4));
  CHECK((sharp - r).cwiseAbs().maxCoeff() <
        std::log(2.0) / 1e4 + 1e-12);  // the gap is largest at z = 0
  CHECK_THROWS_AS(softplus_stacked(t, t.constant(z), 2, 0.0), InternalError);
}

TEST_CASE("gradients through the Jacobian pass check_gradients", "[tangents][gradcheck]") {
  for (const GradCase& g : jacobian_cases()) {
    DYNAMIC_SECTION(g.op) {
      const GradCheckResult r = check_gradients(g.f, g.inputs, g.options);
      INFO(r.report);
      CHECK(r.ok);
      CHECK(r.worst_relative < 1e-5);
    }
  }
}

TEST_CASE("stack_tangents layout and unstack", "[tangents]") {
  Tape<double> t;
  Block<double> x(2, 3);
  x << 1, 2, 3,  //
      4, 5, 6;
  Var s = stack_tangents(t, t.constant(x));
  Block<double> expect(6, 3);
  expect << 1, 2, 3,  //
      4, 5, 6,        //
      1, 0, 0,        //
      1, 0, 0,        //
      0, 1, 0,        //
      0, 1, 0;
  CHECK(t.value(s) == expect);
  const Stacked u = unstack(t, s);
  CHECK(t.value(u.value) == x);
  CHECK(t.value(u.du) == expect.middleRows(2, 2));
  CHECK(t.value(u.dv) == expect.bottomRows(2));
  CHECK_THROWS_AS(stack_tangents(t, t.constant(Block<double>::Ones(2, 1))), InternalError);
  CHECK_THROWS_AS(unstack(t, t.constant(Block<double>::Ones(4, 1))), InternalError);
}

}  // namespace jsa::test
