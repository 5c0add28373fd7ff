// Reductions and per-row geometry: what turns blocks into losses, Jacobians
// into normals (Eq. 2) and metrics (Eq. 10).
#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

// y = sum_ij x_ij ;  dx_ij += dy
template <class T>
Var sum(Tape<T>& t, Var x) {
  Var y = t.node(1, 1, {x});
  t.value(y)(0, 0) = t.value(x).sum();
  t.on_backward(y, [x](Tape<T>& t, Var y) { t.grad(x).array() += t.grad(y)(0, 0); });
  return y;
}

// y = (1 / NC) sum_ij x_ij ;  dx_ij += dy / NC
template <class T>
Var mean(Tape<T>& t, Var x) {
  const T inv = T(1) / T(std::max<Index>(1, t.value(x).size()));
  Var y = t.node(1, 1, {x});
  t.value(y)(0, 0) = t.value(x).sum() * inv;
  t.on_backward(y, [x, inv](Tape<T>& t, Var y) { t.grad(x).array() += t.grad(y)(0, 0) * inv; });
  return y;
}

// y_i = sum_c x_ic ;  dx_ic += dy_i
template <class T>
Var row_sum(Tape<T>& t, Var x) {
  Var y = t.node(t.rows(x), 1, {x});
  t.value(y) = t.value(x).rowwise().sum();
  t.on_backward(y, [x](Tape<T>& t, Var y) { t.grad(x).colwise() += t.grad(y).col(0); });
  return y;
}

// y_i = <a_i, b_i> ;  da_i += dy_i b_i ;  db_i += dy_i a_i
template <class T>
Var row_dot(Tape<T>& t, Var a, Var b) {
  JSA_CHECK(t.rows(a) == t.rows(b) && t.cols(a) == t.cols(b), "row_dot: shapes differ");
  Var y = t.node(t.rows(a), 1, {a, b});
  t.value(y) = t.value(a).cwiseProduct(t.value(b)).rowwise().sum();
  t.on_backward(y, [a, b](Tape<T>& t, Var y) {
    const auto dy = t.grad(y).col(0);
    if (t.needs_grad(a)) t.grad(a) += (t.value(b).array().colwise() * dy.array()).matrix();
    if (t.needs_grad(b)) t.grad(b) += (t.value(a).array().colwise() * dy.array()).matrix();
  });
  return y;
}

// y_i = sqrt(|x_i|^2 + eps) ;  dx_i += dy_i x_i / y_i
template <class T>
Var row_norm(Tape<T>& t, Var x, T eps) {
  Var y = t.node(t.rows(x), 1, {x});
  t.value(y) = (t.value(x).rowwise().squaredNorm().array() + eps).sqrt();
  // Row by row: Eigen evaluates a broadcast expression column (dy / y) into a
  // temporary block, a heap allocation in every step.
  t.on_backward(y, [x](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& Y = t.value(y);
    const Block<T>& dY = t.grad(y);
    Block<T>& dX = t.grad(x);
    for (Index i = 0; i < X.rows(); ++i) dX.row(i) += X.row(i) * (dY(i, 0) / Y(i, 0));
  });
  return y;
}

// y_i = x_i / r_i, r_i = sqrt(|x_i|^2 + eps)
// dx_i += (dy_i - y_i <y_i, dy_i>) / r_i   (the projection that removes the
// radial part, since scaling x_i does not change y_i when eps = 0)
template <class T>
Var row_normalize(Tape<T>& t, Var x, T eps) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  const Block<T>& X = t.value(x);
  Block<T>& Y = t.value(y);
  for (Index i = 0; i < X.rows(); ++i)
    Y.row(i) = X.row(i) / std::sqrt(X.row(i).squaredNorm() + eps);
  t.on_backward(y, [x, eps](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& Y = t.value(y);
    const Block<T>& dY = t.grad(y);
    Block<T>& dX = t.grad(x);
    for (Index i = 0; i < X.rows(); ++i) {
      const T r = std::sqrt(X.row(i).squaredNorm() + eps);
      dX.row(i) += (dY.row(i) - Y.row(i) * Y.row(i).dot(dY.row(i))) / r;
    }
  });
  return y;
}

// y_i = a_i x b_i ;  da_i += b_i x dy_i ;  db_i += dy_i x a_i
// (from <dy, a x b> = <b x dy, a> = <dy x a, b>)
template <class T>
Var cross3(Tape<T>& t, Var a, Var b) {
  JSA_CHECK(t.cols(a) == 3 && t.cols(b) == 3 && t.rows(a) == t.rows(b), "cross3 needs two N x 3");
  const Index n = t.rows(a);
  Var y = t.node(n, 3, {a, b});
  const Block<T>& A = t.value(a);
  const Block<T>& B = t.value(b);
  Block<T>& Y = t.value(y);
  for (Index i = 0; i < n; ++i) {
    Y(i, 0) = A(i, 1) * B(i, 2) - A(i, 2) * B(i, 1);
    Y(i, 1) = A(i, 2) * B(i, 0) - A(i, 0) * B(i, 2);
    Y(i, 2) = A(i, 0) * B(i, 1) - A(i, 1) * B(i, 0);
  }
  t.on_backward(y, [a, b](Tape<T>& t, Var y) {
    const Block<T>& A = t.value(a);
    const Block<T>& B = t.value(b);
    const Block<T>& G = t.grad(y);
    const bool ga = t.needs_grad(a), gb = t.needs_grad(b);
    for (Index i = 0; i < A.rows(); ++i) {
      if (ga) {
        t.grad(a)(i, 0) += B(i, 1) * G(i, 2) - B(i, 2) * G(i, 1);
        t.grad(a)(i, 1) += B(i, 2) * G(i, 0) - B(i, 0) * G(i, 2);
        t.grad(a)(i, 2) += B(i, 0) * G(i, 1) - B(i, 1) * G(i, 0);
      }
      if (gb) {
        t.grad(b)(i, 0) += G(i, 1) * A(i, 2) - G(i, 2) * A(i, 1);
        t.grad(b)(i, 1) += G(i, 2) * A(i, 0) - G(i, 0) * A(i, 2);
        t.grad(b)(i, 2) += G(i, 0) * A(i, 1) - G(i, 1) * A(i, 0);
      }
    }
  });
  return y;
}

#define JSA_INSTANTIATE(T)                         \
  template Var sum<T>(Tape<T>&, Var);              \
  template Var mean<T>(Tape<T>&, Var);             \
  template Var row_sum<T>(Tape<T>&, Var);          \
  template Var row_dot<T>(Tape<T>&, Var, Var);     \
  template Var row_norm<T>(Tape<T>&, Var, T);      \
  template Var row_normalize<T>(Tape<T>&, Var, T); \
  template Var cross3<T>(Tape<T>&, Var, Var);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
