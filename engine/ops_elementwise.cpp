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

// b expanded to a's shape, as an Eigen expression-free copy (small blocks only
// take this path: 1xC, Nx1, 1x1).
template <class T>
Block<T> expand(const Block<T>& b, Index n, Index c, Shape s) {
  switch (s) {
    case Shape::Same:
      return b;
    case Shape::Row:
      return b.replicate(n, 1);
    case Shape::Col:
      return b.replicate(1, c);
    case Shape::Scalar:
      return Block<T>::Constant(n, c, b(0, 0));
  }
  return b;
}

// The adjoint of expand: sum g back down to b's shape.
template <class T>
void reduce_into(Block<T>& db, const Block<T>& g, Shape s) {
  switch (s) {
    case Shape::Same:
      db += g;
      break;
    case Shape::Row:
      db += g.colwise().sum();
      break;
    case Shape::Col:
      db += g.rowwise().sum();
      break;
    case Shape::Scalar:
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
  if (s == Shape::Same)
    t.value(y) = t.value(a) + t.value(b);
  else
    t.value(y) = t.value(a) + expand(t.value(b), t.rows(a), t.cols(a), s);
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
  if (s == Shape::Same)
    t.value(y) = t.value(a) - t.value(b);
  else
    t.value(y) = t.value(a) - expand(t.value(b), t.rows(a), t.cols(a), s);
  t.on_backward(y, [a, b, s](Tape<T>& t, Var y) {
    if (t.needs_grad(a)) t.grad(a) += t.grad(y);
    if (t.needs_grad(b)) {
      Block<T> neg = -t.grad(y);
      reduce_into(t.grad(b), neg, s);
    }
  });
  return y;
}

// y = a * b (elementwise) ;  da += dy * b ;  db += reduce(dy * a)
template <class T>
Var mul(Tape<T>& t, Var a, Var b) {
  const Shape s = broadcast_shape(t, a, b, "mul");
  Var y = t.node(t.rows(a), t.cols(a), {a, b});
  const Index n = t.rows(a), c = t.cols(a);
  if (s == Shape::Same)
    t.value(y) = t.value(a).cwiseProduct(t.value(b));
  else
    t.value(y) = t.value(a).cwiseProduct(expand(t.value(b), n, c, s));
  t.on_backward(y, [a, b, s, n, c](Tape<T>& t, Var y) {
    const Block<T>& dY = t.grad(y);
    if (t.needs_grad(a)) {
      if (s == Shape::Same)
        t.grad(a) += dY.cwiseProduct(t.value(b));
      else
        t.grad(a) += dY.cwiseProduct(expand(t.value(b), n, c, s));
    }
    if (t.needs_grad(b)) {
      Block<T> g = dY.cwiseProduct(t.value(a));
      reduce_into(t.grad(b), g, s);
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

#define JSA_INSTANTIATE(T)                  \
  template Var add<T>(Tape<T>&, Var, Var);  \
  template Var sub<T>(Tape<T>&, Var, Var);  \
  template Var mul<T>(Tape<T>&, Var, Var);  \
  template Var scale<T>(Tape<T>&, Var, T);  \
  template Var offset<T>(Tape<T>&, Var, T); \
  template Var square<T>(Tape<T>&, Var);    \
  template Var sqrt<T>(Tape<T>&, Var, T);   \
  template Var exp<T>(Tape<T>&, Var);       \
  template Var log<T>(Tape<T>&, Var);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
