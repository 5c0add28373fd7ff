// linear and the activations (ReLU, softplus): the ops an MLP is made of, in
// plain and stacked-tangent form.
#include <cmath>

#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

// Y = X W + b   (b on the first bias_rows rows only, see ops.h)
template <class T>
Var linear(Tape<T>& t, Var x, Var w, Var b, Index bias_rows) {
  const Index n = t.rows(x), cin = t.cols(x), cout = t.cols(w);
  JSA_CHECK(t.rows(w) == cin,
            "linear: X is " << n << "x" << cin << ", W is " << t.rows(w) << "x" << cout);
  if (bias_rows < 0) bias_rows = n;
  JSA_CHECK(bias_rows <= n, "linear: bias on " << bias_rows << " rows of " << n);
  Var y = b.valid() ? t.node(n, cout, {x, w, b}) : t.node(n, cout, {x, w});
  Block<T>& Y = t.value(y);
  Y.noalias() = t.value(x) * t.value(w);  // one GEMM, threaded by Eigen
  if (b.valid()) {
    JSA_CHECK(t.rows(b) == 1 && t.cols(b) == cout, "linear: bias must be 1x" << cout);
    const auto bias = t.value(b).row(0);
    parallel_rows(bias_rows,
                  [&](Index r0, Index r1) { Y.middleRows(r0, r1 - r0).rowwise() += bias; });
  }
  // dX += dY W^T ;  dW += X^T dY ;  db += sum over the biased rows of dY
  t.on_backward(y, [x, w, b, bias_rows](Tape<T>& t, Var y) {
    const Block<T>& dY = t.grad(y);
    if (t.needs_grad(x)) t.grad(x).noalias() += dY * t.value(w).transpose();
    if (t.needs_grad(w)) t.grad(w).noalias() += t.value(x).transpose() * dY;
    if (b.valid() && t.needs_grad(b)) {
      // A plain loop over rows: contiguous in row-major dY (Eigen's colwise()
      // sum strides down each column, ~8x slower here), and serial, so the sum
      // order is fixed.
      auto db = t.grad(b).row(0);
      for (Index i = 0; i < bias_rows; ++i) db += dY.row(i);
    }
  });
  return y;
}

// y = max(x, 0)
template <class T>
Var relu(Tape<T>& t, Var x) {
  return relu_masked(t, x, t.rows(x));
}

// y_k = [z > 0] * x_k for every stacked block k, z = the value block (rows 0..m)
template <class T>
Var relu_masked(Tape<T>& t, Var x, Index m) {
  const Index n = t.rows(x);
  JSA_CHECK(m > 0 && n % m == 0, "relu_masked: " << n << " rows is not a multiple of " << m);
  Var y = t.node(n, t.cols(x), {x});
  const Block<T>& X = t.value(x);
  Block<T>& Y = t.value(y);
  const Index blocks = n / m;
  parallel_rows(m, [&](Index r0, Index r1) {
    for (Index k = 0; k < blocks; ++k)
      Y.middleRows(k * m + r0, r1 - r0) = (X.middleRows(r0, r1 - r0).array() > T(0))
                                              .select(X.middleRows(k * m + r0, r1 - r0), T(0));
  });
  // dx_k += [z > 0] * dy_k   (the mask itself is piecewise constant: no gradient)
  t.on_backward(y, [x, m, blocks](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& dY = t.grad(y);
    Block<T>& dX = t.grad(x);
    parallel_rows(m, [&](Index r0, Index r1) {
      for (Index k = 0; k < blocks; ++k)
        dX.middleRows(k * m + r0, r1 - r0) += (X.middleRows(r0, r1 - r0).array() > T(0))
                                                  .select(dY.middleRows(k * m + r0, r1 - r0), T(0));
    });
  });
  return y;
}

// Softplus on stacked rows, value block z (rows 0..m) and tangent blocks x_k:
//   y_0 = s(z) = log(1 + exp(beta z)) / beta,   y_k = s'(z) x_k,   s'(z) = sigmoid(beta z).
// Unlike ReLU, s' is smooth, so the Jacobian (hence the normal of Eq. 2) varies
// continuously over the domain; the price is the second derivative in the
// pull-back:  dz += dy_0 s'(z) + sum_k dy_k x_k s''(z),  s'' = beta s' (1 - s'),
//             dx_k += dy_k s'(z).
template <class T>
Var softplus_stacked(Tape<T>& t, Var x, Index m, T beta) {
  const Index n = t.rows(x), c = t.cols(x);
  JSA_CHECK(m > 0 && n % m == 0, "softplus_stacked: " << n << " rows is not a multiple of " << m);
  JSA_CHECK(beta > T(0), "softplus_stacked: beta must be positive, got " << beta);
  Var y = t.node(n, c, {x});
  const Block<T>& X = t.value(x);
  Block<T>& Y = t.value(y);
  const Index blocks = n / m;
  // Whole-row-range array expressions, so Eigen vectorises exp and log1p.
  // log(1 + e^bz) = max(bz, 0) + log1p(e^-|bz|) and sigmoid(bz) = 1 / (1 + e^-bz)
  // written with e = e^-|bz| <= 1: neither overflows for any bz.
  parallel_rows(m, [&](Index r0, Index r1) {
    const auto bz = beta * X.middleRows(r0, r1 - r0).array();
    const Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> e = (-bz.abs()).exp();
    Y.middleRows(r0, r1 - r0).array() = (bz.max(T(0)) + e.log1p()) / beta;
    if (blocks > 1) {
      const Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> s1 =
          (bz >= T(0)).select(T(1) / (T(1) + e), e / (T(1) + e));
      for (Index k = 1; k < blocks; ++k)
        Y.middleRows(k * m + r0, r1 - r0).array() = s1 * X.middleRows(k * m + r0, r1 - r0).array();
    }
  });
  t.on_backward(y, [x, m, blocks, beta](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& dY = t.grad(y);
    Block<T>& dX = t.grad(x);
    parallel_rows(m, [&](Index r0, Index r1) {
      const Index h = r1 - r0;
      const auto bz = beta * X.middleRows(r0, h).array();
      const Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> e = (-bz.abs()).exp();
      const Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> s1 =
          (bz >= T(0)).select(T(1) / (T(1) + e), e / (T(1) + e));
      Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> dz =
          dY.middleRows(r0, h).array() * s1;
      if (blocks > 1) {
        const Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> s2 =
            beta * s1 * (T(1) - s1);
        for (Index k = 1; k < blocks; ++k) {
          dz += dY.middleRows(k * m + r0, h).array() * X.middleRows(k * m + r0, h).array() * s2;
          dX.middleRows(k * m + r0, h).array() += dY.middleRows(k * m + r0, h).array() * s1;
        }
      }
      dX.middleRows(r0, h).array() += dz;
    });
  });
  return y;
}

#define JSA_INSTANTIATE(T)                                \
  template Var linear<T>(Tape<T>&, Var, Var, Var, Index); \
  template Var relu<T>(Tape<T>&, Var);                    \
  template Var relu_masked<T>(Tape<T>&, Var, Index);      \
  template Var softplus_stacked<T>(Tape<T>&, Var, Index, T);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
