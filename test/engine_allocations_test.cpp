// The engine's steady state allocates nothing: a tape that builds the same
// graph as the step before (every op a training step uses, at sizes where
// Eigen's GEMM packs its panels) asks the heap for nothing in its forward and
// backward, on its own and from inside a team of threads (the trainer's shape
// workers). Counted by test/allocation_counter.h (malloc interposed).
#include <omp.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <vector>

#include "engine/ops.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "engine/tangents.h"
#include "test/allocation_counter.h"

namespace jsa {
namespace {

struct Inputs {
  Block<float> x, w1, b1, w2, w3, code;
  std::vector<int> index;
};

Block<float> uniform(Index rows, Index cols, Rng& rng, double scale) {
  Block<float> b(rows, cols);
  for (Index i = 0; i < b.size(); ++i) b.data()[i] = float(rng.uniform(-scale, scale));
  return b;
}

// M = 1000 points, 128 units: products of 3000 x 128 by 128 x 128, whose
// packed panels exceed Eigen's 128 KiB of stack buffers.
Inputs make_inputs() {
  Rng rng(7);
  Inputs in;
  const Index m = 1000, width = 128;
  in.x = uniform(m, 2, rng, 1);
  in.w1 = uniform(2, width, rng, 1);
  in.b1 = uniform(1, width, rng, 0.5);
  in.w2 = uniform(width, width, rng, 0.1);
  in.w3 = uniform(width, 3, rng, 0.1);
  in.code = uniform(4, 8, rng, 1);
  for (Index i = 0; i < m; ++i) in.index.push_back(int((i * 7) % m));
  return in;
}

// One "step": phi with its stacked Jacobian through the ops an MLP and the
// losses use (linear, both softplus forms, ReLU, stack/unstack, cross3,
// row_normalize, concat and slice of rows and columns, gather, the broadcasts
// of add, sub and mul, the elementwise and reduction ops), then backward.
double step(Tape<float>& t, const Inputs& in) {
  t.clear();
  const Index m = in.x.rows();
  const Var x = t.variable(in.x), w1 = t.variable(in.w1), b1 = t.variable(in.b1);
  const Var w2 = t.variable(in.w2), w3 = t.variable(in.w3), code = t.variable(in.code);
  const Var x3 = stack_tangents(t, x);
  Var h = linear_softplus_stacked(t, x3, w1, b1, m, 40.0f);
  h = softplus_stacked(t, linear(t, h, w2, Var{}, m), m, 40.0f);
  h = relu_masked(t, h, m);
  const Stacked y = unstack(t, linear(t, h, w3, Var{}, m));
  const Var n = row_normalize(t, cross3(t, y.du, y.dv));
  const Var six = concat_cols(t, {y.value, n});
  const Var both = concat_rows(t, {slice_rows(t, six, 0, m / 2), gather_rows(t, six, in.index)});
  const Var code_row = slice_rows(t, code, 1, 1);
  // b broadcast as a row (1 x C), a scalar (1 x 1) and a column (N x 1)
  const Var shifted = add(t, slice_cols(t, both, 0, 3), slice_cols(t, code_row, 0, 3));
  const Var centred = sub(t, shifted, mean(t, shifted));
  const Var spread = add(t, centred, row_norm(t, centred));
  const Var weighted = mul(t, spread, spread);
  const Var e = exp(t, scale(t, row_dot(t, weighted, weighted), -1.0f));
  const Var l = log(t, offset(t, sqrt(t, square(t, e)), 1.0f));
  const Var loss = add(t, sum(t, l), mean(t, row_sum(t, y.value)));
  t.backward(loss);
  return double(t.scalar(loss));
}

}  // namespace

TEST_CASE("engine: a step that builds the same graph again allocates nothing", "[tape]") {
  if (!allocation_counter::counting_available()) {
    WARN("no allocation counting under a sanitizer");
    return;
  }
  const Inputs in = make_inputs();
  Tape<float> t;
  const double first = step(t, in);
  step(t, in);  // the pool of gradient blocks settles in the first two sweeps
  allocation_counter::start();
  const double third = step(t, in);
  const long allocations = allocation_counter::stop();
  CHECK(third == first);
  CHECK(allocations == 0);
}

TEST_CASE("engine: ... nor inside a team of threads, each with its own tape", "[tape]") {
  if (!allocation_counter::counting_available()) {
    WARN("no allocation counting under a sanitizer");
    return;
  }
  const int team = std::max(2, max_threads());
  const Inputs in = make_inputs();
  std::vector<Tape<float>> tapes(static_cast<size_t>(team));
  std::vector<double> losses(static_cast<size_t>(team));
  auto run = [&] {
  // As the trainer's shape workers: one tape per thread; the ops' own
  // regions inside would have one thread, and run inline.
#pragma omp parallel for num_threads(team) schedule(static, 1)
    for (int w = 0; w < team; ++w) losses[size_t(w)] = step(tapes[size_t(w)], in);
  };
  run();
  run();
  allocation_counter::start();
  run();
  const long allocations = allocation_counter::stop();
  for (double l : losses) CHECK(l == losses[0]);
  CHECK(allocations == 0);
}

}  // namespace jsa
