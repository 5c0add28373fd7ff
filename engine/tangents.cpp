#include "engine/tangents.h"

namespace jsa {

// y = [x; e_u; e_v] ;  dx += dy[0:N]   (the tangent rows are constants)
template <class T>
Var stack_tangents(Tape<T>& t, Var x) {
  const Index n = t.rows(x), d = t.cols(x);
  JSA_CHECK(d >= 2, "stack_tangents needs at least two input columns (u, v), got " << d);
  Var y = t.node(3 * n, d, {x});
  Block<T>& Y = t.value(y);
  Y.topRows(n) = t.value(x);
  Y.bottomRows(2 * n).setZero();
  Y.middleRows(n, n).col(0).setOnes();
  Y.bottomRows(n).col(1).setOnes();
  t.on_backward(y, [x, n](Tape<T>& t, Var y) { t.grad(x) += t.grad(y).topRows(n); });
  return y;
}

template <class T>
Stacked unstack(Tape<T>& t, Var y) {
  JSA_CHECK(t.rows(y) % 3 == 0, "unstack: " << t.rows(y) << " rows is not 3N");
  const Index n = t.rows(y) / 3;
  return {slice_rows(t, y, 0, n), slice_rows(t, y, n, n), slice_rows(t, y, 2 * n, n)};
}

template Var stack_tangents<float>(Tape<float>&, Var);
template Var stack_tangents<double>(Tape<double>&, Var);
template Stacked unstack<float>(Tape<float>&, Var);
template Stacked unstack<double>(Tape<double>&, Var);

}  // namespace jsa
