#include "model/atlas.h"

namespace jsa {

template <class T>
Atlas<T>::Atlas(const AtlasOptions& o) : options_(o) {
  domain = Domain<T>(params, DomainOptions{o.gaussians, o.gaussian_noise});
  phi = Parametrization<T>(params, MlpShape{2, 3, o.width, o.hidden_layers}, T(o.alpha));
  psi = Chart<T>(params, MlpShape{6, 2, o.width, o.hidden_layers});
}

template <class T>
void Atlas<T>::initialize(Rng& rng) {
  // Separate streams, so changing one network's size leaves the others' draws alone.
  Rng r_mu = rng.stream(1), r_phi = rng.stream(2), r_psi = rng.stream(3);
  domain.initialize(params, r_mu);
  phi.initialize(params, r_phi);
  psi.initialize(params, r_psi);
}

template class Atlas<float>;
template class Atlas<double>;

}  // namespace jsa
