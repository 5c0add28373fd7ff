// Beyond the paper: a discrete choice of phi's global orientation (mirror the
// domain when most normals face inward), which the paper does not make; one
// switch, FitOptions::orient_every (--orient-every, 0 = off).
//
// The global orientation of the parametrization.
//
// phi maps an oriented plane onto the surface, so n = J_u x J_v (Eq. 2) points
// consistently to one side of every fold-free patch; which side is decided by
// the random initialisation. Both choices give the same L_3D, and with
// alpha = 0.01 the normal part of L_6D (Eq. 7) is too weak a force to turn a
// whole surface inside out one small step at a time: a run that starts
// inside-out stays so (measured on a SHREC ant: docs/method.md).
// The choice is discrete, so we make it directly. Mirroring the domain,
// (u, v) -> (v, u), reparametrizes the same surface with every normal negated:
//   phi'(u, v) = phi(v, u)      swap the rows of phi's first weight matrix,
//   mu'_k = (mu_k,v, mu_k,u)    the same density P, mirrored,
//   psi'(x, n) = swap(psi(x, n)) swap the columns of psi's output layer (and of
//                                the code weights W_f when they feed that layer),
// which keeps psi' the inverse of phi' and leaves every loss but the normal
// terms unchanged. The trainer mirrors when most normals face away from the
// target's (back_facing_fraction > 1/2).
#pragma once
#include <vector>

#include "model/atlas.h"

namespace jsa {

// Mirrors the domain of `atlas` in place, as above. `aligned`: other buffers laid
// out like atlas.params.values() (Adam's moments), mirrored the same way.
template <class T>
void mirror_domain(Atlas<T>& atlas, const std::vector<std::vector<T>*>& aligned = {});

// The fraction of `count` points x ~ P whose normal n(x) faces away from the
// normal of its nearest target (n . n_S < 0). targets: rows [x_S, alpha n_S].
double back_facing_fraction(Atlas<float>& atlas, const Block<float>& targets, Index count, Rng& rng,
                            int shape = 0);

}  // namespace jsa
