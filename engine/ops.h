// The op library. Each op appends one node to the tape; its pull-back sits right
// below its forward in the .cpp files, with the local derivative in a comment:
//   ops_linear.cpp      linear (X W + b), relu, relu_masked, softplus_stacked
//                       (the last two on stacked tangents)
//   ops_linear_softplus.cpp  linear_softplus_stacked: linear then
//                       softplus_stacked as one op, in row tiles (the hidden
//                       layers of the softplus MLPs)
//   ops_elementwise.cpp add/sub/mul (row broadcasting), scale, offset, square,
//                       sqrt, exp, log, sin_cos
//   ops_rows.cpp        concat/slice of columns and rows, gather rows by index
//   ops_reduce.cpp      sum, mean, row_dot, row_norm, row_normalize, cross3
//   ops_kernels.cpp     gaussian_weights_stacked: normalised Gaussian kernels
//                       in the plane, with their tangent rows
// Shapes use one alphabet: N rows (points), C columns (channels).
// A new op with its own kernel uses the custom-op hook Tape::node/on_backward.
#pragma once
#include <vector>

#include "engine/tape.h"

namespace jsa {

// ---- linear algebra (ops_linear.cpp) ----
// Y = X W + b. X: N x Cin, W: Cin x Cout, b: 1 x Cout (or invalid Var for none).
// bias_rows >= 0 adds b only to the first bias_rows rows: the stacked-tangent
// convention, where rows past the value block are derivatives and carry no bias.
template <class T>
Var linear(Tape<T>& t, Var x, Var w, Var b, Index bias_rows = -1);
// y = max(x, 0).
template <class T>
Var relu(Tape<T>& t, Var x);
// ReLU on stacked rows [value; tangent_1; ...], each block mask_rows tall: the
// mask [value > 0] of the value block multiplies every block (chain rule for
// d relu(z) = [z > 0] dz).
template <class T>
Var relu_masked(Tape<T>& t, Var x, Index mask_rows);
// Softplus log(1 + e^(beta z)) / beta on stacked rows (block height m): the value
// block z goes through it, each tangent block is multiplied by its derivative
// sigmoid(beta z). A smooth ReLU (beta -> infinity gives ReLU back).
template <class T>
Var softplus_stacked(Tape<T>& t, Var x, Index m, T beta);

// ---- one softplus layer (ops_linear_softplus.cpp) ----
// softplus_stacked(linear(H, W, b, m), m, beta) as one op: H: N x Cin (N a
// multiple of m), W: Cin x Cout, b: 1 x Cout (on the value rows 0..m) or
// invalid. The GEMM's output is processed in tiles of `tile` points (rows p..p
// + tile of every block); 0 sizes them to stay in L2. Keeps Y only, not H W + b.
template <class T>
Var linear_softplus_stacked(Tape<T>& t, Var h, Var w, Var b, Index m, T beta, Index tile = 0);

// ---- elementwise (ops_elementwise.cpp) ----
// b is either the shape of a, or 1 x C and then broadcast over a's rows,
// or N x 1 and then broadcast over a's columns, or 1 x 1.
template <class T>
Var add(Tape<T>& t, Var a, Var b);
template <class T>
Var sub(Tape<T>& t, Var a, Var b);
template <class T>
Var mul(Tape<T>& t, Var a, Var b);
template <class T>
Var scale(Tape<T>& t, Var x, T c);  // c x
template <class T>
Var offset(Tape<T>& t, Var x, T c);  // x + c
template <class T>
Var square(Tape<T>& t, Var x);
// sqrt(x + eps): eps keeps the derivative 1/(2 sqrt(x + eps)) finite at x = 0.
template <class T>
Var sqrt(Tape<T>& t, Var x, T eps = T(1e-12));
template <class T>
Var exp(Tape<T>& t, Var x);
// The natural logarithm; x > 0 (the caller's floor: no eps here).
template <class T>
Var log(Tape<T>& t, Var x);
// [sin x, cos x]: N x C -> N x 2C, the two halves of random Fourier features
// (model/chart.h).
template <class T>
Var sin_cos(Tape<T>& t, Var x);

// ---- rows and columns (ops_rows.cpp) ----
// xs: a braced list {a, b} or a vector (VarList, engine/tape.h).
template <class T>
Var concat_cols(Tape<T>& t, VarList xs);
template <class T>
Var slice_cols(Tape<T>& t, Var x, Index begin, Index count);
template <class T>
Var concat_rows(Tape<T>& t, VarList xs);
template <class T>
Var slice_rows(Tape<T>& t, Var x, Index begin, Index count);
// y_i = x_{index_i}; the pull-back scatter-adds, serially, so it is deterministic.
template <class T>
Var gather_rows(Tape<T>& t, Var x, const std::vector<int>& index);

// ---- reductions and per-row geometry (ops_reduce.cpp) ----
template <class T>
Var sum(Tape<T>& t, Var x);  // 1 x 1
template <class T>
Var mean(Tape<T>& t, Var x);  // 1 x 1
template <class T>
Var row_sum(Tape<T>& t, Var x);  // N x 1
template <class T>
Var row_dot(Tape<T>& t, Var a, Var b);  // N x 1: <a_i, b_i>
// sqrt(|x_i|^2 + eps), N x 1 (eps as in sqrt above).
template <class T>
Var row_norm(Tape<T>& t, Var x, T eps = T(1e-12));
// x_i / sqrt(|x_i|^2 + eps), N x C.
template <class T>
Var row_normalize(Tape<T>& t, Var x, T eps = T(1e-12));
template <class T>
Var cross3(Tape<T>& t, Var a, Var b);  // N x 3: a_i x b_i

// ---- kernels (ops_kernels.cpp) ----
// The normalised Gaussian weights of n centres in the plane (a partition of
// unity): x: N x 2 stacked rows [x; dx_1; ...] with m value rows (m < 0: all
// rows are values), centres: n x 2 (constants), sigma > 0. Returns N x n:
//   w_k(x) = g_k(x) / sum_l g_l(x),  g_k(x) = exp(-|x - c_k|^2 / (2 sigma^2))
// on the value rows and dw_k = grad w_k . dx on the tangent rows.
template <class T>
Var gaussian_weights_stacked(Tape<T>& t, Var x, Index m, const Block<T>& centres, T sigma);

}  // namespace jsa
