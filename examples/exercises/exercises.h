// The three exercises (minitorch style): each function below is a piece of the
// engine you write yourself in the .cpp file of the same name next to this
// header. Blank versions with TODOs live here; finished ones in solutions/.
// Build with -DJSATLAS_EXERCISES=ON (add -DJSATLAS_EXERCISE_SOLUTIONS=ON to build
// the solutions instead) and run `ctest --test-dir build -R exercise`: the tests
// tagged [exercise] in exercises_test.cpp fail until the piece is right.
//
//   1. tanh_stacked.cpp   an op with its tangent rule and its dual rule
//   2. normalize_rows.cpp a pull-back: d(x / |x|)
//   3. isometry_grad.cpp  a loss gradient by hand: dL_iso / dJ
//
// Read docs/engine.md first (the tape, stacked tangents, the softplus pull-back
// derived line by line); the engine's own ops (engine/ops_*.cpp) are the model.
#pragma once
#include "engine/dual.h"
#include "engine/tape.h"

namespace jsa::exercise {

using Dual2 = Dual<double, 2>;

// 1a. The dual rule: tanh(a + u e) = tanh(a) + (1 - tanh(a)^2) u e.
Dual2 tanh(const Dual2& x);

// 1b. tanh on stacked rows [z; x_1; x_2] (each block m rows, the value block
//     first, as softplus_stacked in engine/ops_linear.cpp): y_0 = tanh(z),
//     y_k = tanh'(z) x_k, and the pull-back into z and every x_k.
//     tanh' = 1 - tanh^2 ;  tanh'' = -2 tanh (1 - tanh^2).
Var tanh_stacked(Tape<double>& t, Var x, Index m);

// 2. y_i = x_i / sqrt(|x_i|^2 + eps) row by row (N x C), eps = 1e-12: the
//    forward is written; write the pull-back.
Var normalize_rows(Tape<double>& t, Var x);

// 3. L_iso = (1/N) sum_i (E_i - 1)^2 + 2 F_i^2 + (G_i - 1)^2 with
//    E = <J_u, J_u>, F = <J_u, J_v>, G = <J_v, J_v> (Eq. 10 as implemented,
//    losses/isometry.cpp). Return L_iso and write dL/dJ_u and dL/dJ_v (N x 3
//    each), by hand: no tape.
double isometry_grad(const Block<double>& du, const Block<double>& dv, Block<double>& d_du,
                     Block<double>& d_dv);

}  // namespace jsa::exercise
