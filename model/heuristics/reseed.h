// Beyond the paper: moving P's Gaussians off back-facing flaps to the holes of
// the surface, which the paper does not do; one switch,
// FitOptions::reseed_every (--reseed, 0 = off, the default).
//
// Moving the Gaussians of back-facing flaps to where the surface is missing.
//
// The reconstruction is phi(supp P) (Sec. 3.1): only the parts of the domain
// that P samples are surface. Training from a random start often drapes a flap
// of the domain over the shape with its orientation reversed, n(x) = J_u x J_v
// (Eq. 2) pointing into the shape: a fold, which no small gradient step undoes
// (the flap would have to pass through itself). With alpha = 0.01 such a flap
// costs L_6D (Eq. 7) little, and it shows up as back-facing pairs in the normal
// metric (on a SHREC ant, ~10% of the surface; per Gaussian the back-facing
// fraction is bimodal: whole components lie on flaps).
//
// The mixture P can drop a flap without touching phi: move its components.
// Every so often we sample S points from each component N(mu_k, sigma^2 I),
// and a component whose samples mostly face away from their nearest target
// normal (fraction > 1/2) is flipped. Each flipped mean is moved to the domain
// position of the correctly facing sample nearest to a target that the
// correctly facing surface covers worst (targets drawn with probability
// proportional to the squared distance to that surface), plus N(0, (sigma/2)^2).
// The moved component then samples the border of the good surface next to a
// hole, where L_6D's target-to-surface term pulls phi outward to fill it.
// Adam's moments of a moved mean are reset. phi and psi are not changed.
//
// In a collection P is shared: a component is flipped when its fraction,
// averaged over the shapes given, exceeds 1/2; holes are measured on the first.
#pragma once
#include <vector>

#include "model/atlas.h"

namespace jsa {

struct ReseedReport {
  int flipped = 0;         // components moved
  double back_facing = 0;  // fraction of all component samples facing away, before the move
};

// targets: one block per shape in `shapes`, rows [x_S, alpha n_S] (any normal
// scale > 0). `moments`: Adam's buffers laid out like atlas.params.values()
// (empty ones are skipped). samples_per_mean: S above.
ReseedReport reseed_flipped_means(Atlas<float>& atlas, const std::vector<Block<float>>& targets,
                                  const std::vector<int>& shapes, Rng& rng,
                                  const std::vector<std::vector<float>*>& moments,
                                  int samples_per_mean = 8);

}  // namespace jsa
