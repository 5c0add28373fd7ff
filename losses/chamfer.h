// The Chamfer distance, Eq. (6), with squared distances and a mean in both
// directions; L_6D (Eq. 7) and L_2D (Eq. 8) are this op on 6- and 2-column blocks:
//
//   CD(X, Y) = 1/N sum_i min_j |x_i - y_j|^2  +  1/M sum_j min_i |y_j - x_i|^2
//
// X: N x C, Y: M x C. The nearest-neighbour assignment is piecewise constant, so
// the gradient flows only through the matched pairs: with a_i the match of x_i in
// Y and b_j the match of y_j in X,
//   dL/dx_i = 2/N (x_i - y_{a_i}) - 2/M sum_{j : b_j = i} (y_j - x_i)
//   dL/dy_j = 2/M (y_j - x_{b_j}) - 2/N sum_{i : a_i = j} (x_i - y_j)
#pragma once
#include <vector>

#include "engine/tape.h"
#include "io/geometry/nearest.h"

namespace jsa {

// The association behind a Chamfer value, for evaluation (correspondences,
// F-scores, per-point errors).
template <class T>
struct ChamferMatches {
  std::vector<int> x_to_y;            // N: a_i, the row of Y nearest to x_i
  std::vector<int> y_to_x;            // M: b_j, the row of X nearest to y_j
  std::vector<T> x_squared_distance;  // N: |x_i - y_{a_i}|^2
  std::vector<T> y_squared_distance;  // M: |y_j - x_{b_j}|^2
};

// CD(x, y) as a 1 x 1 tape node, differentiable in x and y (either may be a
// constant). If matches is given it is filled with the association.
// coverage: the weight w of the second direction, 1/M sum_j |y_j - x_{b_j}|^2
// (every target reached by some x_i); 1 is Eq. 6.
template <class T>
Var chamfer(Tape<T>& t, Var x, Var y, ChamferMatches<T>* matches = nullptr, double coverage = 1);

// The dense variant of L_6D: the x -> Y direction searches `surface`, a fixed
// pool far larger than this step's M (all of the shape's samples, indexed once),
// the Y -> x direction searches x as above:
//
//   CD_dense(X, Y) = 1/N sum_i min_{p in S} |x_i - p|^2  +  1/M sum_j min_i |y_j - x_i|^2
//
// Why: with M = 2500 samples a surface point's nearest target is about the
// sample spacing away (~0.02 of the radius) in a random direction, so the
// first term's pull is mostly noise; against 2 x 10^5 samples it points at
// the surface itself, spacing ~0.005. The second term keeps its M targets:
// it is the one that asks for coverage. The pool is a constant (no gradient);
// matches->x_to_y then indexes surface.points().
template <class T>
Var chamfer(Tape<T>& t, Var x, Var y, const NearestIndex<T>& surface,
            ChamferMatches<T>* matches = nullptr, double coverage = 1);

// The same value without a tape (evaluation). Sums accumulate in double.
template <class T>
double chamfer_distance(const Block<T>& x, const Block<T>& y, ChamferMatches<T>* matches = nullptr);

}  // namespace jsa
