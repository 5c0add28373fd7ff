// Moving blocks around: concatenation and slicing of columns and rows, and
// gathering rows by index. Each pull-back is the adjoint of the forward copy.
#include "engine/ops.h"

namespace jsa {

// y = [x_1 | x_2 | ...] ;  dx_k += dy[:, columns of x_k]
template <class T>
Var concat_cols(Tape<T>& t, VarList xs) {
  JSA_CHECK(!xs.empty(), "concat_cols of nothing");
  const Index n = t.rows(xs[0]);
  Index c = 0;
  for (Var x : xs) {
    JSA_CHECK(t.rows(x) == n, "concat_cols: " << t.rows(x) << " rows vs " << n);
    c += t.cols(x);
  }
  Var y = t.node(n, c, xs);
  for (Index k = 0, at = 0; k < Index(xs.size()); at += t.cols(xs[k]), ++k)
    t.value(y).middleCols(at, t.cols(xs[k])) = t.value(xs[k]);
  // The inputs' ids are kept on the tape (a captured vector would be a heap copy).
  t.on_backward(y, [inputs = t.keep(xs)](Tape<T>& t, Var y) {
    const std::vector<int>& xs = t.kept(inputs);
    for (Index k = 0, at = 0; k < Index(xs.size()); at += t.cols(Var{xs[k]}), ++k)
      if (t.needs_grad(Var{xs[k]}))
        t.grad(Var{xs[k]}) += t.grad(y).middleCols(at, t.cols(Var{xs[k]}));
  });
  return y;
}

// y = x[:, begin : begin + count] ;  dx[:, begin : begin + count] += dy
template <class T>
Var slice_cols(Tape<T>& t, Var x, Index begin, Index count) {
  JSA_CHECK(begin >= 0 && count >= 0 && begin + count <= t.cols(x),
            "slice_cols [" << begin << ", " << begin + count << ") of " << t.cols(x));
  Var y = t.node(t.rows(x), count, {x});
  t.value(y) = t.value(x).middleCols(begin, count);
  t.on_backward(
      y, [x, begin, count](Tape<T>& t, Var y) { t.grad(x).middleCols(begin, count) += t.grad(y); });
  return y;
}

// y = [x_1; x_2; ...] (stacked vertically) ;  dx_k += dy[rows of x_k]
template <class T>
Var concat_rows(Tape<T>& t, VarList xs) {
  JSA_CHECK(!xs.empty(), "concat_rows of nothing");
  const Index c = t.cols(xs[0]);
  Index n = 0;
  for (Var x : xs) {
    JSA_CHECK(t.cols(x) == c, "concat_rows: " << t.cols(x) << " columns vs " << c);
    n += t.rows(x);
  }
  Var y = t.node(n, c, xs);
  for (Index k = 0, at = 0; k < Index(xs.size()); at += t.rows(xs[k]), ++k)
    t.value(y).middleRows(at, t.rows(xs[k])) = t.value(xs[k]);
  t.on_backward(y, [inputs = t.keep(xs)](Tape<T>& t, Var y) {
    const std::vector<int>& xs = t.kept(inputs);
    for (Index k = 0, at = 0; k < Index(xs.size()); at += t.rows(Var{xs[k]}), ++k)
      if (t.needs_grad(Var{xs[k]}))
        t.grad(Var{xs[k]}) += t.grad(y).middleRows(at, t.rows(Var{xs[k]}));
  });
  return y;
}

// y = x[begin : begin + count, :] ;  dx[begin : begin + count, :] += dy
template <class T>
Var slice_rows(Tape<T>& t, Var x, Index begin, Index count) {
  JSA_CHECK(begin >= 0 && count >= 0 && begin + count <= t.rows(x),
            "slice_rows [" << begin << ", " << begin + count << ") of " << t.rows(x));
  Var y = t.node(count, t.cols(x), {x});
  t.value(y) = t.value(x).middleRows(begin, count);
  t.on_backward(
      y, [x, begin, count](Tape<T>& t, Var y) { t.grad(x).middleRows(begin, count) += t.grad(y); });
  return y;
}

// y_i = x_{index_i} ;  dx_{index_i} += dy_i  (scatter-add, in index order)
template <class T>
Var gather_rows(Tape<T>& t, Var x, const std::vector<int>& index) {
  const Index n = Index(index.size()), rows = t.rows(x);
  Var y = t.node(n, t.cols(x), {x});
  const Block<T>& X = t.value(x);
  Block<T>& Y = t.value(y);
  for (Index i = 0; i < n; ++i) {
    JSA_CHECK(index[i] >= 0 && index[i] < rows,
              "gather_rows: index " << index[i] << " of " << rows);
    Y.row(i) = X.row(index[i]);
  }
  if (!t.needs_grad(y)) return y;
  const int slot = t.keep(index);
  t.on_backward(y, [x, slot](Tape<T>& t, Var y) {
    const std::vector<int>& ix = t.kept(slot);
    Block<T>& dX = t.grad(x);
    const Block<T>& dY = t.grad(y);
    for (size_t i = 0; i < ix.size(); ++i) dX.row(ix[i]) += dY.row(i);
  });
  return y;
}

#define JSA_INSTANTIATE(T)                                 \
  template Var concat_cols<T>(Tape<T>&, VarList);          \
  template Var slice_cols<T>(Tape<T>&, Var, Index, Index); \
  template Var concat_rows<T>(Tape<T>&, VarList);          \
  template Var slice_rows<T>(Tape<T>&, Var, Index, Index); \
  template Var gather_rows<T>(Tape<T>&, Var, const std::vector<int>&);
JSA_INSTANTIATE(float)
JSA_INSTANTIATE(double)

}  // namespace jsa
