// Normalised Gaussian kernels on stacked tangent rows, as one op: the weights
// of a displacement carried by nodes in the domain (model/parametrize.cpp).
// Built from the op library they took twenty nodes of n columns each (and as
// many pull-backs), which made a joint step with 256 nodes 1.7x dearer; here
// every row's weights come from one pass over its n kernels, and the pull-back
// needs no block of its own: what it sums over the kernels are dot products.
#include "engine/check.h"
#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

// Forward, for a value row x and each of its tangent rows dx (row i + j m):
//   a_k  = -|x - c_k|^2 / (2 sigma^2),  w_k = exp(a_k) / sum_l exp(a_l)
//   b_k  = da_k = (c_k - x) . dx / sigma^2
//   dw_k = w_k (b_k - beta),  beta = sum_l w_l b_l
// (the softmax's derivative). The rows of the output: [w; dw_1; ...].
//
// Pull-back, with S_k = dL/dw_k and R_k = dL/d(dw_k) of one tangent row:
//   dL/dw_k += R_k (b_k - beta) - b_k rho,  rho = sum_l w_l R_l
//   dL/db_k  = w_k (R_k - rho) =: q_k,  dL/d(dx) = sum_k q_k c_k / sigma^2
// (sum_k q_k = rho - rho = 0: the part of b_k that all k share, -x . dx,
// moves no weight, so it carries no gradient, to dx or to x), and through the
// softmax, dL/da_k = w_k (S_k - sum_l w_l S_l), whose sum over k vanishes too,
// so dL/dx = sum_k w_k (S_k - sum_l w_l S_l) c_k / sigma^2.
// Only sums over k of w_k S_k, w_k S_k c_k and q_k c_k are needed.
template <class T>
Var gaussian_weights_stacked(Tape<T>& t, Var x, Index m, const Block<T>& centres, T sigma) {
  const Index rows = t.rows(x);
  JSA_CHECK(t.cols(x) == 2 && centres.cols() == 2 && centres.rows() > 0,
            "gaussian_weights_stacked needs N x 2 points and n x 2 centres, got "
                << rows << "x" << t.cols(x) << " and " << centres.rows() << "x" << centres.cols());
  JSA_CHECK(sigma > 0, "gaussian_weights_stacked needs sigma > 0, got " << sigma);
  const Index value_rows = m < 0 ? rows : m;
  JSA_CHECK(value_rows > 0 && rows % value_rows == 0,
            "gaussian_weights_stacked: " << rows << " rows are not blocks of " << value_rows);
  const Index blocks = rows / value_rows - 1;  // tangent blocks
  const Index n = centres.rows();
  Var y = t.node(rows, n, {x});
  // The centres as two contiguous rows (cx, cy), kept on the tape for the pull-back.
  const Var c = t.constant(centres.transpose());
  const T inv_s2 = T(1) / (sigma * sigma);
  {
    const Block<T>& X = t.value(x);
    const Block<T>& C = t.value(c);
    Block<T>& Y = t.value(y);
    parallel_rows(value_rows, [&](Index b0, Index b1) {
      for (Index i = b0; i < b1; ++i) {
        auto w = Y.row(i).array();
        const T x0 = X(i, 0), x1 = X(i, 1);
        w = -T(0.5) * inv_s2 *
            ((C.row(0).array() - x0).square() + (C.row(1).array() - x1).square());
        // w is unchanged by a shift of a's row: by its largest entry, no row
        // underflows (the sum is >= 1).
        w = (w - w.maxCoeff()).exp();
        w /= w.sum();
        for (Index j = 1; j <= blocks; ++j) {
          const Index p = j * value_rows + i;
          const T d0 = X(p, 0), d1 = X(p, 1);
          auto dw = Y.row(p).array();
          dw = (C.row(0).array() * d0 + C.row(1).array() * d1 - (x0 * d0 + x1 * d1)) * inv_s2;  // b
          const T beta = (w * dw).sum();
          dw = w * (dw - beta);
        }
      }
    });
  }
  t.on_backward(y, [x, c, value_rows, blocks, inv_s2](Tape<T>& t, Var y) {
    const Block<T>& X = t.value(x);
    const Block<T>& C = t.value(c);
    const Block<T>& Y = t.value(y);
    const Block<T>& G = t.grad(y);
    Block<T>& GX = t.grad(x);
    const auto cx = C.row(0).array(), cy = C.row(1).array();
    parallel_rows(value_rows, [&](Index b0, Index b1) {
      for (Index i = b0; i < b1; ++i) {
        const auto w = Y.row(i).array();
        const T x0 = X(i, 0), x1 = X(i, 1);
        // sum_k w_k S_k {1, cx_k, cy_k}, S starting at the value row's gradient
        T ws = (w * G.row(i).array()).sum();
        T wsx = (w * G.row(i).array() * cx).sum();
        T wsy = (w * G.row(i).array() * cy).sum();
        for (Index j = 1; j <= blocks; ++j) {
          const Index p = j * value_rows + i;
          const T d0 = X(p, 0), d1 = X(p, 1);
          const auto r = G.row(p).array();
          const auto b = (cx * d0 + cy * d1 - (x0 * d0 + x1 * d1)) * inv_s2;
          const T beta = (w * b).sum(), rho = (w * r).sum();
          const auto e = r * (b - beta) - b * rho;  // this row's part of S
          ws += (w * e).sum();
          wsx += (w * e * cx).sum();
          wsy += (w * e * cy).sum();
          const auto q = w * (r - rho);
          GX(p, 0) += (q * cx).sum() * inv_s2;
          GX(p, 1) += (q * cy).sum() * inv_s2;
        }
        const T wcx = (w * cx).sum(), wcy = (w * cy).sum();
        GX(i, 0) += (wsx - ws * wcx) * inv_s2;
        GX(i, 1) += (wsy - ws * wcy) * inv_s2;
      }
    });
  });
  return y;
}

template Var gaussian_weights_stacked<float>(Tape<float>&, Var, Index, const Block<float>&, float);
template Var gaussian_weights_stacked<double>(Tape<double>&, Var, Index, const Block<double>&,
                                              double);

}  // namespace jsa
