// linear and the activations (ReLU, softplus): the ops an MLP is made of, in
// plain and stacked-tangent form.
#include <cmath>

#include "engine/gemm.h"
#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

namespace {
// Elementwise choices as plain loops over n contiguous entries: GCC turns the
// ternary into a vector blend, where Eigen's `select` on these array
// expressions ran one coefficient at a time (5.2 against 0.29 ns an entry on an
// AVX2 core: docs/performance.md, "Eigen's select"; the same bits).

// out = [z > 0] * x
template <class T>
void masked_copy(const T* z, const T* x, T* out, Index n, bool accumulate) {
  if (accumulate)
    for (Index j = 0; j < n; ++j) out[j] += z[j] > T(0) ? x[j] : T(0);
  else
    for (Index j = 0; j < n; ++j) out[j] = z[j] > T(0) ? x[j] : T(0);
}

// s' = sigmoid(bz) from e = e^-|bz|:  1 / (1 + e) for bz >= 0, e / (1 + e) below.
template <class T>
void sigmoid_from(const T* bz, const T* e, T* s1, Index n) {
  for (Index j = 0; j < n; ++j) s1[j] = (bz[j] >= T(0) ? T(1) : e[j]) / (T(1) + e[j]);
}
}  // namespace

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
  gemm(t.value(x), false, t.value(w), false, Y, false);  // one GEMM (engine/gemm.h), threaded
  if (b.valid()) {
    JSA_CHECK(t.rows(b) == 1 && t.cols(b) == cout, "linear: bias must be 1x" << cout);
    const auto bias = t.value(b).row(0);
    parallel_rows(bias_rows,
                  [&](Index r0, Index r1) { Y.middleRows(r0, r1 - r0).rowwise() += bias; });
  }
  // dX += dY W^T ;  dW += X^T dY ;  db += sum over the biased rows of dY
  // Each GEMM writes every entry of its gradient, so a first writer assigns
  // (beta = 0 in BLAS terms) and its block is never zeroed (Tape::grad_to_overwrite).
  t.on_backward(y, [x, w, b, bias_rows](Tape<T>& t, Var y) {
    const Block<T>& dY = t.grad(y);
    bool first = false;
    if (t.needs_grad(x)) {
      Block<T>& dX = t.grad_to_overwrite(x, &first);
      gemm(dY, false, t.value(w), true, dX, !first);
    }
    if (t.needs_grad(w)) {
      Block<T>& dW = t.grad_to_overwrite(w, &first);
      gemm(t.value(x), true, dY, false, dW, !first);
    }
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
  const Index c = t.cols(x);
  parallel_rows(m, [&](Index r0, Index r1) {
    if (r1 <= r0) return;
    const Index len = (r1 - r0) * c;  // rows r0..r1 of a block are contiguous
    for (Index k = 0; k < blocks; ++k)
      masked_copy(X.row(r0).data(), X.row(k * m + r0).data(), Y.row(k * m + r0).data(), len, false);
  });
  // dx_k += [z > 0] * dy_k   (the mask itself is piecewise constant: no gradient;
  // every entry is written, so a first writer assigns: Tape::grad_to_overwrite)
  t.on_backward(y, [x, m, blocks](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& dY = t.grad(y);
    bool first = false;
    Block<T>& dX = t.grad_to_overwrite(x, &first);
    const Index c = t.cols(x);
    parallel_rows(m, [&](Index r0, Index r1) {
      if (r1 <= r0) return;
      const Index len = (r1 - r0) * c;
      for (Index k = 0; k < blocks; ++k)
        masked_copy(X.row(r0).data(), dY.row(k * m + r0).data(), dX.row(k * m + r0).data(), len,
                    !first);
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
// The same identities as the scalar rule of engine/dual.h (softplus), here over
// whole rows so that Eigen vectorises exp and log1p.
// Fused: one pass per point i over its value row and its tangent rows, in the
// forward and in the pull-back, with the row's e^-|bz| and s' in stack arrays
// (no heap allocation in the step; kMaxWidth is the command line's width bound).
// The pull-back recomputes e^-|bz| rather than keeping s' from the forward: an
// exp per element is cheaper than a stored block per layer (memory, issue 21).
namespace {
constexpr int kMaxWidth = 4096;
template <class T>
using RowArray = Eigen::Array<T, 1, Eigen::Dynamic, Eigen::RowMajor, 1, kMaxWidth>;
}  // namespace

template <class T>
Var softplus_stacked(Tape<T>& t, Var x, Index m, T beta) {
  const Index n = t.rows(x), c = t.cols(x);
  JSA_CHECK(m > 0 && n % m == 0, "softplus_stacked: " << n << " rows is not a multiple of " << m);
  JSA_CHECK(beta > T(0), "softplus_stacked: beta must be positive, got " << beta);
  JSA_CHECK(c <= kMaxWidth, "softplus_stacked: " << c << " columns, at most " << kMaxWidth);
  Var y = t.node(n, c, {x});
  const Block<T>& X = t.value(x);
  Block<T>& Y = t.value(y);
  const Index blocks = n / m;
  // log(1 + e^bz) = max(bz, 0) + log1p(e^-|bz|) and sigmoid(bz) = 1 / (1 + e^-bz)
  // written with e = e^-|bz| <= 1: neither overflows for any bz.
  parallel_rows(m, [&](Index r0, Index r1) {
    RowArray<T> bz(c), e(c), s1(c);
    for (Index i = r0; i < r1; ++i) {
      bz = beta * X.row(i).array();
      e = (-bz.abs()).exp();
      Y.row(i).array() = (bz.max(T(0)) + e.log1p()) / beta;
      if (blocks == 1) continue;
      sigmoid_from(bz.data(), e.data(), s1.data(), c);
      for (Index k = 1; k < blocks; ++k) Y.row(k * m + i).array() = s1 * X.row(k * m + i).array();
    }
  });
  // Every entry of dX is written, so when this is its first writer (an MLP's
  // pre-activation has no other consumer) it is assigned, not zeroed and added to.
  t.on_backward(y, [x, m, blocks, beta, c](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& dY = t.grad(y);
    bool first = false;
    Block<T>& dX = t.grad_to_overwrite(x, &first);
    parallel_rows(m, [&](Index r0, Index r1) {
      RowArray<T> bz(c), e(c), s1(c), s2(c), dz(c);
      for (Index i = r0; i < r1; ++i) {
        bz = beta * X.row(i).array();
        e = (-bz.abs()).exp();
        sigmoid_from(bz.data(), e.data(), s1.data(), c);
        dz = dY.row(i).array() * s1;
        if (blocks > 1) {
          s2 = beta * s1 * (T(1) - s1);
          for (Index k = 1; k < blocks; ++k) {
            dz += dY.row(k * m + i).array() * X.row(k * m + i).array() * s2;
            if (first)
              dX.row(k * m + i).array() = dY.row(k * m + i).array() * s1;
            else
              dX.row(k * m + i).array() += dY.row(k * m + i).array() * s1;
          }
        }
        if (first)
          dX.row(i).array() = dz;
        else
          dX.row(i).array() += dz;
      }
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
