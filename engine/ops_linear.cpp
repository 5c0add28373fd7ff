// linear and ReLU: the two ops an MLP is made of, in plain and stacked-tangent form.
#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

// Y = X W + b   (b on the first bias_rows rows only, see ops.h)
template <class T>
Var linear(Tape<T>& t, Var x, Var w, Var b, Index bias_rows) {
  const Index n = t.rows(x), cin = t.cols(x), cout = t.cols(w);
  JSA_CHECK(t.rows(w) == cin, "linear: X is " << n << "x" << cin << ", W is " << t.rows(w) << "x" << cout);
  if (bias_rows < 0) bias_rows = n;
  JSA_CHECK(bias_rows <= n, "linear: bias on " << bias_rows << " rows of " << n);
  Var y = b.valid() ? t.node(n, cout, {x, w, b}) : t.node(n, cout, {x, w});
  Block<T>& Y = t.value(y);
  Y.noalias() = t.value(x) * t.value(w);  // one GEMM, threaded by Eigen
  if (b.valid()) {
    JSA_CHECK(t.rows(b) == 1 && t.cols(b) == cout, "linear: bias must be 1x" << cout);
    const auto bias = t.value(b).row(0);
    parallel_rows(bias_rows, [&](Index r0, Index r1) { Y.middleRows(r0, r1 - r0).rowwise() += bias; });
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
      Y.middleRows(k * m + r0, r1 - r0) =
          (X.middleRows(r0, r1 - r0).array() > T(0))
              .select(X.middleRows(k * m + r0, r1 - r0), T(0));
  });
  // dx_k += [z > 0] * dy_k   (the mask itself is piecewise constant: no gradient)
  t.on_backward(y, [x, m, blocks](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& dY = t.grad(y);
    Block<T>& dX = t.grad(x);
    parallel_rows(m, [&](Index r0, Index r1) {
      for (Index k = 0; k < blocks; ++k)
        dX.middleRows(k * m + r0, r1 - r0) +=
            (X.middleRows(r0, r1 - r0).array() > T(0))
                .select(dY.middleRows(k * m + r0, r1 - r0), T(0));
    });
  });
  return y;
}

#define JSA_INSTANTIATE(T)                                    \
  template Var linear<T>(Tape<T>&, Var, Var, Var, Index);     \
  template Var relu<T>(Tape<T>&, Var);                        \
  template Var relu_masked<T>(Tape<T>&, Var, Index);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
