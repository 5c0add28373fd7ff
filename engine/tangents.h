// Forward-mode Jacobians as ordinary tape ops: the stacked-tangent convention.
//
// To get J = [∂f/∂u, ∂f/∂v] of an MLP f at N points x (N x D, u and v its first
// two columns), push 3N rows through the network instead of N:
//
//        rows 0..N    [ x   ]   value            -> f(x)          (N x C)
//        rows N..2N   [ e_u ]   tangent along u  -> J_u = ∂f/∂u   (N x C)
//        rows 2N..3N  [ e_v ]   tangent along v  -> J_v = ∂f/∂v   (N x C)
//
// A linear layer maps tangents by W alone (d(xW + b) = dx W): the same GEMM on
// all 3N rows, with the bias on the value rows only (linear(..., bias_rows = N)).
// ReLU multiplies every block by the mask of the value block (relu_masked).
// Each layer stays one GEMM, and because these are tape ops, losses on J (the
// normals of Eq. 2, the isometry of Eq. 10) get exact gradients by backward().
#pragma once
#include "engine/ops.h"

namespace jsa {

// [x; e_u; e_v] (3N x D), tangent rows constant (one-hot in column 0 or 1).
template <class T>
Var stack_tangents(Tape<T>& t, Var x);

// The three N-row blocks of a stacked output.
struct Stacked {
  Var value, du, dv;
};
template <class T>
Stacked unstack(Tape<T>& t, Var y);

}  // namespace jsa
