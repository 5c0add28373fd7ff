// The repulsion between the domain's Gaussian means, Eq. (11), over all ordered
// pairs including i = j, as the paper writes it:
//
//   L_rep = 1/K^2 sum_{i,j} exp(-|mu_i - mu_j| / sigma),      mu: K x 2
//
// Each unordered pair appears twice, so with d_ij = |mu_i - mu_j|
//   dL/dmu_i = 1/K^2 sum_{j != i} 2 (-1/sigma) exp(-d_ij/sigma) (mu_i - mu_j) / d_ij.
// |x| has no derivative at 0: a pair of distinct but coincident means (d_ij = 0)
// contributes exp(0) = 1 to L and zero to the gradient (the symmetric choice).
//
// The exact sum is O(K^2). The fast version drops pairs farther apart than the
// cut-off r_c = sigma ln(1/tolerance), found with a uniform grid (cells r_c / 4):
//  - value: each dropped pair has exp(-d/sigma) < tolerance, and there are fewer
//    than K^2 of them, so |L - L_exact| < tolerance;
//  - gradient: each dropped term of dL/dmu_i has norm 2/(K^2 sigma) exp(-d/sigma)
//    < 2 tolerance/(K^2 sigma), and there are at most K - 1 of them, so
//    |dL/dmu_i - exact|_2 < 2 tolerance / (K sigma) for every i.
// These bound the cut-off only; rounding in T adds its own error on top.
#pragma once
#include "engine/tape.h"

namespace jsa {

struct RepulsionOptions {
  double tolerance = 1e-7;  // bound on the absolute error of L_rep from the cut-off
};

// L_rep as a 1 x 1 tape node, differentiable in mu (K x 2); sigma > 0 is a constant.
// Value and gradient are computed together in the forward pass (the pair loop is
// the cost) and the pull-back only scales the stored gradient.
template <class T>
Var repulsion(Tape<T>& t, Var mu, T sigma, const RepulsionOptions& o = {});

// The cut-off kernel without a tape: returns L_rep and, if dmu is given, writes
// (not accumulates) dL/dmu into it, K x 2. Deterministic for any thread count.
template <class T>
double repulsion_cutoff(const Block<T>& mu, T sigma, Block<T>* dmu, const RepulsionOptions& o = {});

// The oracle: every ordered pair, accumulated in double. O(K^2).
template <class T>
double repulsion_exact(const Block<T>& mu, T sigma, Block<T>* dmu);

}  // namespace jsa
