// Exercise 1: tanh as an op of the engine, with its tangent rule and its dual
// rule. Model: softplus_stacked in engine/ops_linear.cpp and the worked tanh
// example of docs/engine.md. Solution: solutions/tanh_stacked.cpp.
#include <cmath>

#include "examples/exercises/exercises.h"

namespace jsa::exercise {

// tanh(a + u e) = tanh(a) + (1 - tanh(a)^2) u e
Dual2 tanh(const Dual2& x) {
  Dual2 r(std::tanh(x.a));
  // TODO(exercise 1a): the derivative slots r.v[k], k = 0, 1.
  return r;
}

// y_0 = tanh(z),  y_k = tanh'(z) x_k   (z: rows 0..m, x_k: rows k m..(k+1) m)
Var tanh_stacked(Tape<double>& t, Var x, Index m) {
  const Index n = t.rows(x);
  JSA_CHECK(m > 0 && n % m == 0, "tanh_stacked: " << n << " rows is not a multiple of " << m);
  Var y = t.node(n, t.cols(x), {x});
  const Block<double>& X = t.value(x);
  Block<double>& Y = t.value(y);
  Y.setZero();
  // TODO(exercise 1b): the value block Y.topRows(m) = tanh(z), then each
  // tangent block Y.middleRows(k * m, m) = tanh'(z) * x_k.
  (void)X;
  t.on_backward(y, [x, m](Tape<double>& t, Var y) {
    // TODO(exercise 1b): the pull-back. Derive it first (docs/engine.md does
    // it for softplus): dx_k += ... ; dz += ...
    (void)t, (void)y, (void)x, (void)m;
  });
  return y;
}

}  // namespace jsa::exercise
