// Solution of exercise 1 (examples/exercises/tanh_stacked.cpp): tanh with its
// tangent rule and its dual rule.
#include <cmath>

#include "examples/exercises/exercises.h"

namespace jsa::exercise {

// tanh(a + u e) = tanh(a) + (1 - tanh(a)^2) u e
Dual2 tanh(const Dual2& x) {
  Dual2 r(std::tanh(x.a));
  for (int k = 0; k < 2; ++k) r.v[k] = (1 - r.a * r.a) * x.v[k];
  return r;
}

// y_0 = tanh(z),  y_k = tanh'(z) x_k   (z: rows 0..m, x_k: rows k m..(k+1) m)
// Pull-back, with s1 = tanh'(z) = 1 - y_0^2 and s2 = tanh''(z) = -2 y_0 s1:
//   dx_k += dy_k s1                     (y_k is linear in x_k)
//   dz   += dy_0 s1 + sum_k dy_k x_k s2 (z reaches the loss through y_0 and every y_k)
Var tanh_stacked(Tape<double>& t, Var x, Index m) {
  const Index n = t.rows(x);
  JSA_CHECK(m > 0 && n % m == 0, "tanh_stacked: " << n << " rows is not a multiple of " << m);
  Var y = t.node(n, t.cols(x), {x});
  const Block<double>& X = t.value(x);
  Block<double>& Y = t.value(y);
  Y.topRows(m) = X.topRows(m).array().tanh();
  const Eigen::ArrayXXd s1 = 1 - Y.topRows(m).array().square();
  for (Index k = 1; k < n / m; ++k) Y.middleRows(k * m, m) = s1 * X.middleRows(k * m, m).array();
  t.on_backward(y, [x, m](Tape<double>& t, Var y) {
    const Block<double>& X = t.value(x);
    const Block<double>& Y = t.value(y);
    const Block<double>& dY = t.grad(y);
    Block<double>& dX = t.grad(x);
    const Eigen::ArrayXXd s1 = 1 - Y.topRows(m).array().square();
    const Eigen::ArrayXXd s2 = -2 * Y.topRows(m).array() * s1;
    Eigen::ArrayXXd dz = dY.topRows(m).array() * s1;
    for (Index k = 1; k < X.rows() / m; ++k) {
      dz += dY.middleRows(k * m, m).array() * X.middleRows(k * m, m).array() * s2;
      dX.middleRows(k * m, m).array() += dY.middleRows(k * m, m).array() * s1;
    }
    dX.topRows(m).array() += dz;
  });
  return y;
}

}  // namespace jsa::exercise
