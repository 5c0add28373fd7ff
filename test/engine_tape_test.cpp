// Tests of engine/tape.h: storage kept across clear(), gradients lent for the
// sweep only, scalar-only backward, stale handles, gradients zeroed per
// backward, pull-backs that overwrite a gradient, and the custom-op hook.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/gradcheck.h"
#include "engine/ops.h"
#include "engine/rng.h"

namespace jsa {
namespace {

// A small graph with a fixed shape, as one training step would build.
// x is node 0 and w node 1: made in two statements, since the order in which
// a call's arguments are evaluated is unspecified (GCC goes right to left).
Var build(Tape<double>& t, const Block<double>& x, const Block<double>& w) {
  const Var xv = t.constant(x);
  const Var wv = t.variable(w);
  Var h = relu(t, linear(t, xv, wv, Var{}));
  return mean(t, square(t, h));
}

}  // namespace

TEST_CASE("clear() keeps every node's storage", "[tape]") {
  Rng rng(4);
  Block<double> x(64, 8), w(8, 16);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = rng.uniform(-1, 1);
  for (Index i = 0; i < w.size(); ++i) w.data()[i] = rng.uniform(-1, 1);
  Tape<double> t;
  Var loss = build(t, x, w);
  t.backward(loss);
  const int size = t.size();
  std::vector<const double*> values;
  for (int i = 0; i < size; ++i) values.push_back(t.value(Var{i}).data());
  const Block<double> dw = t.grad(Var{1});  // w, the one leaf that needs a gradient
  const size_t bytes = t.bytes();

  t.clear();
  CHECK(t.size() == 0);
  loss = build(t, x, w);
  t.backward(loss);
  REQUIRE(t.size() == size);
  for (int i = 0; i < size; ++i) {
    INFO("node " << i);
    CHECK(t.value(Var{i}).data() == values[i]);
  }
  CHECK(t.grad(Var{1}) == dw);
  CHECK(t.bytes() == bytes);  // the gradients came from the pool: nothing new
}

// A chain of L layers, as an MLP builds: each op's gradient is needed only
// from its consumer's pull-back to its own, so the sweep holds a few gradient
// blocks at a time, not one per node.
TEST_CASE("the sweep lends gradients: a deep chain holds a few at a time", "[tape]") {
  Rng rng(5);
  const Index rows = 256, width = 32;
  const int layers = 12;
  Block<double> x(rows, width);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = rng.uniform(-1, 1);
  std::vector<Block<double>> ws;
  for (int k = 0; k < layers; ++k) {
    ws.push_back(Block<double>(width, width));
    for (Index i = 0; i < ws.back().size(); ++i) ws.back().data()[i] = rng.uniform(-0.3, 0.3);
  }
  Tape<double> t;
  std::vector<Var> wv;
  Var h = t.constant(x);
  for (int k = 0; k < layers; ++k) {
    wv.push_back(t.variable(ws[size_t(k)]));
    h = softplus_stacked(t, linear(t, h, wv.back(), Var{}), rows, 1.0);
  }
  Var loss = mean(t, square(t, h));
  t.backward(loss);
  const double block = double(sizeof(double) * rows * width);
  size_t values = 0;
  for (int i = 0; i < t.size(); ++i) values += sizeof(double) * size_t(t.value(Var{i}).size());
  const double gradient_bytes = double(t.bytes() - values);
  // One rows x width block per linear, per softplus and per square: 3 L + 1
  // if every node kept its own; lent, at most a handful are ever live.
  CHECK(gradient_bytes < 4 * block);
  // Every weight's gradient is there to read, and matches the chain rule by
  // central differences on one entry of the first layer (the op gradchecks
  // cover the rest).
  const double analytic = t.grad(wv[0])(2, 3);
  auto loss_at = [&](double delta) {
    Tape<double> u;
    Var g = u.constant(x);
    for (int k = 0; k < layers; ++k) {
      Block<double> w = ws[size_t(k)];
      if (k == 0) w(2, 3) += delta;
      g = softplus_stacked(u, linear(u, g, u.constant(w), Var{}), rows, 1.0);
    }
    return u.scalar(mean(u, square(u, g)));
  };
  const double h_fd = 1e-6;
  CHECK(std::abs(analytic - (loss_at(h_fd) - loss_at(-h_fd)) / (2 * h_fd)) <
        1e-8 * std::max(1.0, std::abs(analytic)));
  // An inner node's gradient is not kept after the sweep, and saying so is an error.
  CHECK_THROWS_AS(t.grad(loss), InternalError);
  CHECK_THROWS_AS(t.grad(h), InternalError);
}

TEST_CASE("backward needs a scalar", "[tape][errors]") {
  Tape<double> t;
  Var x = t.variable(Block<double>::Ones(3, 2));
  Var y = scale(t, x, 2.0);
  CHECK_THROWS_AS(t.backward(y), InternalError);
  CHECK_THROWS_AS(t.scalar(y), InternalError);
  CHECK_NOTHROW(t.backward(sum(t, y)));
}

TEST_CASE("a Var from before clear() is stale", "[tape][errors]") {
  Tape<double> t;
  Var x = t.variable(Block<double>::Ones(2, 2));
  Var y = scale(t, x, 3.0);
  t.clear();
  CHECK_THROWS_AS(t.value(y), InternalError);
  CHECK_THROWS_AS(t.value(Var{}), InternalError);
}

TEST_CASE("repeated backward does not accumulate across calls", "[tape]") {
  // Gradients accumulate within one backward (paths add), but each call starts
  // from zero.
  Tape<double> t;
  Var x = t.variable(Block<double>::Constant(2, 2, 1.5));
  Var loss = sum(t, square(t, x));
  t.backward(loss);
  const Block<double> g1 = t.grad(x);
  t.backward(loss);
  CHECK(t.grad(x) == g1);
  CHECK(g1(1, 1) == 3.0);
}

TEST_CASE("nodes not needing a gradient have no pull-back", "[tape]") {
  Tape<double> t;
  Var a = t.constant(Block<double>::Ones(2, 2));
  Var b = exp(t, a);
  CHECK_FALSE(t.needs_grad(b));
  Var loss = sum(t, b);
  CHECK_NOTHROW(t.backward(loss));  // nothing to do, no error
  Var x = t.variable(Block<double>::Ones(2, 2));
  CHECK(t.needs_grad(add(t, a, x)));
}

TEST_CASE("custom-op hook: node + on_backward", "[tape]") {
  // y = x^3 elementwise, written as a custom op ; dx += 3 x^2 dy.
  Tape<double> t;
  Block<double> x0(1, 3);
  x0 << 1, -2, 0.5;
  Var x = t.variable(x0);
  Var y = t.node(1, 3, {x});
  t.value(y) = t.value(x).array().cube();
  t.on_backward(y, [x](Tape<double>& t, Var y) {
    t.grad(x).array() += 3 * t.value(x).array().square() * t.grad(y).array();
  });
  t.backward(sum(t, y));
  CHECK(t.grad(x)(0, 0) == 3.0);
  CHECK(t.grad(x)(0, 1) == 12.0);
  CHECK(t.grad(x)(0, 2) == 0.75);
}

TEST_CASE("a pull-back that overwrites a gradient: first writer or not, on reused blocks",
          "[tape]") {
  // softplus_stacked and relu_masked ask for their input's gradient with
  // grad_to_overwrite(): as its first writer they assign into a block that was
  // not zeroed (and, lent from the pool, holds an earlier sweep's numbers),
  // after another writer they add. z feeds the activation and a square, the
  // two created in either order, so each case happens once; the gradient is
  // checked against central differences, then a second backward() on the same
  // tape, whose blocks all come back from the pool dirty, must agree exactly.
  const Index n = 4;
  Block<double> z0(3 * n, 5);
  for (Index i = 0; i < z0.size(); ++i) z0.data()[i] = 0.8 * std::sin(0.7 + 1.3 * double(i));
  for (const bool softplus : {true, false}) {
    for (const bool activation_first : {true, false}) {
      INFO((softplus ? "softplus_stacked" : "relu_masked")
           << (activation_first ? ", created first (runs last: adds)"
                                : ", created last (runs first: assigns)"));
      const auto build_graph = [=](Tape<double>& t, const std::vector<Var>& x) {
        const auto activation = [&] {
          return softplus ? softplus_stacked(t, x[0], n, 3.0) : relu_masked(t, x[0], n);
        };
        Var a, b;
        if (activation_first) {
          a = activation();
          b = square(t, x[0]);
        } else {
          b = square(t, x[0]);
          a = activation();
        }
        return add(t, a, b);
      };
      const GradCheckResult r = check_gradients(build_graph, {z0});
      INFO(r.report);
      CHECK(r.ok);
      CHECK(r.checked == z0.size());

      Tape<double> t;
      const Var z = t.variable(z0);
      Block<double> weights(3 * n, 5);
      for (Index i = 0; i < weights.size(); ++i) weights.data()[i] = std::cos(0.3 * double(i));
      const Var loss = sum(t, mul(t, build_graph(t, {z}), t.constant(weights)));
      t.backward(loss);
      const Block<double> once = t.grad(z);
      t.backward(loss);
      CHECK((t.grad(z) - once).cwiseAbs().maxCoeff() == 0.0);
      CHECK(once.cwiseAbs().maxCoeff() > 0.1);
    }
  }
}

TEST_CASE("keep() stores index arrays reused across clear()", "[tape]") {
  Tape<double> t;
  const int s = t.keep({3, 1, 4});
  CHECK(t.kept(s) == std::vector<int>{3, 1, 4});
  t.clear();
  const int s2 = t.keep({1, 5});
  CHECK(s2 == s);
  CHECK(t.kept(s2) == std::vector<int>{1, 5});
}

}  // namespace jsa
