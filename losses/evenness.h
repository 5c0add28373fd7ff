// L_even: how evenly the samples phi(x_P) cover the surface (beyond the paper;
// issue 21, docs/results.md). The paper's terms ask phi(x_P) to lie on the
// surface and to reach all of it (L_6D, Eq. 7), not to be spread evenly over
// it: a region where phi crowds the domain is as good for Chamfer as one where
// it spreads it thin, and the EMD of Table 1 (Eq. 13), an exact assignment, is
// what sees the difference.
//
// P's density (Eq. 4), with every mean's weight 1/K:
//   p(x) = 1/(2 pi sigma^2 K) sum_k exp(-|x - mu_k|^2 / (2 sigma^2))
// A sample x of P lands on the surface at phi(x) with the density (change of
// variables through the 3x2 Jacobian J = [J_u, J_v] of Eq. 1)
//   q(x) = p(x) / |J_u x J_v|.
// The samples are uniform on the surface iff q is constant, so
//   L_even = Var_m[ log q(x_m) ] = mean_m (l_m - mean l)^2,
//   l_m = log p(x_m) - 1/2 log |J_u x J_v|^2(x_m),
// which is free of the surface's area (a constant of log q) and of the scale
// of either log. Gradients reach phi (through the area element) and the domain
// (the means, and x_m through the reparameterization).
#pragma once
#include "engine/tape.h"

namespace jsa {

struct MixtureDensityOptions {
  // Terms of the sum with exp(-|x - mu_k|^2 / (2 sigma^2)) < tolerance are
  // dropped (less than K tolerance in all; see evenness.cpp for the bound).
  double tolerance = 1e-7;
};

// log p(x_n) + log(2 pi sigma^2 K) for every row of x (N x 2) under the
// mixture with means mu (K x 2, K >= 1): N x 1, differentiable in x and mu;
// sigma > 0 is a constant. Means are found with a uniform grid (cells of the
// cut-off radius); a point with no mean within the cut-off (far out in a tail)
// falls back to the exact sum. Deterministic for any thread count.
template <class T>
Var mixture_log_density(Tape<T>& t, Var x, Var mu, T sigma, const MixtureDensityOptions& o = {});

// The oracle: every pair, in double, value only (N x 1, same constant as above).
template <class T>
Block<double> mixture_log_density_exact(const Block<T>& x, const Block<T>& mu, T sigma);

// L_even at the samples x (M x 2) with phi's Jacobian columns du, dv (M x 3)
// there: a 1 x 1 node.
template <class T>
Var evenness_loss(Tape<T>& t, Var x, Var mu, T sigma, Var du, Var dv,
                  const MixtureDensityOptions& o = {});

}  // namespace jsa
