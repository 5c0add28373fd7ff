// Solution of exercise 2 (examples/exercises/normalize_rows.cpp).
#include <cmath>

#include "examples/exercises/exercises.h"

namespace jsa::exercise {

// y_i = x_i / r_i,  r_i = sqrt(|x_i|^2 + eps)
// dy = dx / r - x (x . dx) / r^3 = (dx - y (y . dx)) / r, a symmetric map, so
//   dx_i += (dy_i - y_i (y_i . dy_i)) / r_i
// (the part of dy_i along y_i changes only the length, which y does not have).
Var normalize_rows(Tape<double>& t, Var x) {
  const double eps = 1e-12;
  Var y = t.node(t.rows(x), t.cols(x), {x});
  const Block<double>& X = t.value(x);
  Block<double>& Y = t.value(y);
  for (Index i = 0; i < X.rows(); ++i)
    Y.row(i) = X.row(i) / std::sqrt(X.row(i).squaredNorm() + eps);
  t.on_backward(y, [x, eps](Tape<double>& t, Var y) {
    const Block<double>& X = t.value(x);
    const Block<double>& Y = t.value(y);
    const Block<double>& dY = t.grad(y);
    Block<double>& dX = t.grad(x);
    for (Index i = 0; i < X.rows(); ++i) {
      const double r = std::sqrt(X.row(i).squaredNorm() + eps);
      dX.row(i) += (dY.row(i) - Y.row(i) * Y.row(i).dot(dY.row(i))) / r;
    }
  });
  return y;
}

}  // namespace jsa::exercise
