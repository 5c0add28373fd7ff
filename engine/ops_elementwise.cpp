// Elementwise ops. Binary ops broadcast b over a (see ops.h); their pull-backs
// sum the gradient over the broadcast dimension, the adjoint of broadcasting.
#include <cmath>

#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {
namespace {

enum class Shape { Same, Row, Col, Scalar };

template <class T>
Shape broadcast_shape(const Tape<T>& t, Var a, Var b, const char* op) {
  const Index n = t.rows(a), c = t.cols(a), bn = t.rows(b), bc = t.cols(b);
  if (bn == n && bc == c) return Shape::Same;
  if (bn == 1 && bc == 1) return Shape::Scalar;
  if (bn == 1 && bc == c) return Shape::Row;
  if (bn == n && bc == 1) return Shape::Col;
  JSA_CHECK(false, op << ": cannot broadcast " << bn << "x" << bc << " onto " << n << "x" << c);
  return Shape::Same;
}

// Calls f with b broadcast to n x c as an Eigen array expression (no
// expanded copy of b: add and sub run in every step and must not allocate).
template <class T, class F>
void with_broadcast(const Block<T>& b, Index n, Index c, Shape s, F&& f) {
  using Array = Eigen::Array<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  switch (s) {
    case Shape::Same:
      f(b.array());
      break;
    case Shape::Row:
      f(b.row(0).array().replicate(n, 1));
      break;
    case Shape::Col:
      f(b.col(0).array().replicate(1, c));
      break;
    case Shape::Scalar:
      f(Array::Constant(n, c, b(0, 0)));
      break;
  }
}

// The adjoint of broadcasting: db += (g summed down to b's shape), or -=
// when `minus`: the same bits as adding the sum of -g (negation is exact),
// without a block holding -g.
template <class T>
void reduce_into(Block<T>& db, const Block<T>& g, Shape s, bool minus = false) {
  switch (s) {
    case Shape::Same:
      if (minus)
        db -= g;
      else
        db += g;
      break;
    case Shape::Row:
      if (minus)
        db -= g.colwise().sum();
      else
        db += g.colwise().sum();
      break;
    case Shape::Col:
      if (minus)
        db -= g.rowwise().sum();
      else
        db += g.rowwise().sum();
      break;
    case Shape::Scalar:
      if (minus)
        db(0, 0) -= g.sum();
      else
        db(0, 0) += g.sum();
      break;
  }
}

}  // namespace

// y = a + b ;  da += dy ;  db += reduce(dy)
template <class T>
Var add(Tape<T>& t, Var a, Var b) {
  const Shape s = broadcast_shape(t, a, b, "add");
  Var y = t.node(t.rows(a), t.cols(a), {a, b});
  Block<T>& Y = t.value(y);
  const Block<T>& A = t.value(a);
  with_broadcast(t.value(b), A.rows(), A.cols(), s,
                 [&](const auto& bb) { Y = (A.array() + bb).matrix(); });
  t.on_backward(y, [a, b, s](Tape<T>& t, Var y) {
    if (t.needs_grad(a)) t.grad(a) += t.grad(y);
    if (t.needs_grad(b)) reduce_into(t.grad(b), t.grad(y), s);
  });
  return y;
}

// y = a - b ;  da += dy ;  db -= reduce(dy)
template <class T>
Var sub(Tape<T>& t, Var a, Var b) {
  const Shape s = broadcast_shape(t, a, b, "sub");
  Var y = t.node(t.rows(a), t.cols(a), {a, b});
  Block<T>& Y = t.value(y);
  const Block<T>& A = t.value(a);
  with_broadcast(t.value(b), A.rows(), A.cols(), s,
                 [&](const auto& bb) { Y = (A.array() - bb).matrix(); });
  t.on_backward(y, [a, b, s](Tape<T>& t, Var y) {
    if (t.needs_grad(a)) t.grad(a) += t.grad(y);
    if (t.needs_grad(b)) reduce_into(t.grad(b), t.grad(y), s, /*minus=*/true);
  });
  return y;
}

// y = a * b (elementwise) ;  da += dy * b ;  db += reduce(dy * a)
template <class T>
Var mul(Tape<T>& t, Var a, Var b) {
  const Shape s = broadcast_shape(t, a, b, "mul");
  Var y = t.node(t.rows(a), t.cols(a), {a, b});
  Block<T>& Y = t.value(y);
  const Block<T>& A = t.value(a);
  with_broadcast(t.value(b), A.rows(), A.cols(), s,
                 [&](const auto& bb) { Y = (A.array() * bb).matrix(); });
  t.on_backward(y, [a, b, s](Tape<T>& t, Var y) {
    const Block<T>& dY = t.grad(y);
    if (t.needs_grad(a)) {
      Block<T>& dA = t.grad(a);
      with_broadcast(t.value(b), dY.rows(), dY.cols(), s,
                     [&](const auto& bb) { dA.array() += dY.array() * bb; });
    }
    if (t.needs_grad(b)) {
      if (s == Shape::Same) {
        t.grad(b) += dY.cwiseProduct(t.value(a));
      } else {
        // Broadcast b (not in a training step): the product is summed down
        // from a block of its own.
        Block<T> g = dY.cwiseProduct(t.value(a));
        reduce_into(t.grad(b), g, s);
      }
    }
  });
  return y;
}

// y = c x ;  dx += c dy
template <class T>
Var scale(Tape<T>& t, Var x, T c) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = c * t.value(x);
  t.on_backward(y, [x, c](Tape<T>& t, Var y) { t.grad(x) += c * t.grad(y); });
  return y;
}

// y = x + c ;  dx += dy
template <class T>
Var offset(Tape<T>& t, Var x, T c) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = t.value(x).array() + c;
  t.on_backward(y, [x](Tape<T>& t, Var y) { t.grad(x) += t.grad(y); });
  return y;
}

// y = x^2 ;  dx += 2 x dy
template <class T>
Var square(Tape<T>& t, Var x) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = t.value(x).array().square();
  t.on_backward(y, [x](Tape<T>& t, Var y) {
    t.grad(x).array() += T(2) * t.value(x).array() * t.grad(y).array();
  });
  return y;
}

// y = sqrt(x + eps) ;  dx += dy / (2 y)
template <class T>
Var sqrt(Tape<T>& t, Var x, T eps) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = (t.value(x).array() + eps).sqrt();
  t.on_backward(y, [x](Tape<T>& t, Var y) {
    t.grad(x).array() += t.grad(y).array() / (T(2) * t.value(y).array());
  });
  return y;
}

// y = e^x ;  dx += y dy
template <class T>
Var exp(Tape<T>& t, Var x) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = t.value(x).array().exp();
  t.on_backward(
      y, [x](Tape<T>& t, Var y) { t.grad(x).array() += t.value(y).array() * t.grad(y).array(); });
  return y;
}

// y = log x (x > 0) ;  dx += dy / x
template <class T>
Var log(Tape<T>& t, Var x) {
  Var y = t.node(t.rows(x), t.cols(x), {x});
  t.value(y) = t.value(x).array().log();
  t.on_backward(
      y, [x](Tape<T>& t, Var y) { t.grad(x).array() += t.grad(y).array() / t.value(x).array(); });
  return y;
}

// y = [sin x, cos x] ;  dx += cos x dy_sin - sin x dy_cos (read off y itself)
template <class T>
Var sin_cos(Tape<T>& t, Var x) {
  const Index c = t.cols(x);
  Var y = t.node(t.rows(x), 2 * c, {x});
  t.value(y).leftCols(c) = t.value(x).array().sin();
  t.value(y).rightCols(c) = t.value(x).array().cos();
  t.on_backward(y, [x, c](Tape<T>& t, Var y) {
    const auto v = t.value(y).array();
    const auto g = t.grad(y).array();
    t.grad(x).array() += v.rightCols(c) * g.leftCols(c) - v.leftCols(c) * g.rightCols(c);
  });
  return y;
}

#define JSA_INSTANTIATE(T)                  \
  template Var add<T>(Tape<T>&, Var, Var);  \
  template Var sub<T>(Tape<T>&, Var, Var);  \
  template Var mul<T>(Tape<T>&, Var, Var);  \
  template Var scale<T>(Tape<T>&, Var, T);  \
  template Var offset<T>(Tape<T>&, Var, T); \
  template Var square<T>(Tape<T>&, Var);    \
  template Var sqrt<T>(Tape<T>&, Var, T);   \
  template Var exp<T>(Tape<T>&, Var);       \
  template Var log<T>(Tape<T>&, Var);       \
  template Var sin_cos<T>(Tape<T>&, Var);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
