// Exercise 2: a pull-back. The forward is written; derive and write the
// backward (docs/engine.md derives a harder one line by line). Model:
// row_normalize in engine/ops_reduce.cpp (peek only after you tried).
// Solution: solutions/normalize_rows.cpp.
#include <cmath>

#include "examples/exercises/exercises.h"

namespace jsa::exercise {

// y_i = x_i / r_i,  r_i = sqrt(|x_i|^2 + eps)
Var normalize_rows(Tape<double>& t, Var x) {
  const double eps = 1e-12;
  Var y = t.node(t.rows(x), t.cols(x), {x});
  const Block<double>& X = t.value(x);
  Block<double>& Y = t.value(y);
  for (Index i = 0; i < X.rows(); ++i)
    Y.row(i) = X.row(i) / std::sqrt(X.row(i).squaredNorm() + eps);
  t.on_backward(y, [x, eps](Tape<double>& t, Var y) {
    // TODO(exercise 2): add d(loss)/dx_i into t.grad(x).row(i), from
    // t.grad(y).row(i), t.value(y).row(i) and r_i.
    (void)t, (void)y, (void)x, (void)eps;
  });
  return y;
}

}  // namespace jsa::exercise
