// The 2D domain P: a mixture of K Gaussians with learnable means mu_k, a fixed
// sigma = 1/sqrt(K) and equal weights 1/K (Eq. 4).
//
// Sampling uses the reparameterization trick (Sec. 3.2): pick a component i
// uniformly, draw e ~ N(0, sigma^2 I), return x = mu_i + e. The draw (i, e) is
// parameter-free, so x is differentiable in mu_i: dx/dmu_i = I. On the tape this
// is gather_rows(mu, i) + constant e.
#pragma once
#include <vector>

#include "engine/parameters.h"
#include "engine/rng.h"
#include "engine/tape.h"

namespace jsa {

struct DomainOptions {
  int gaussians = 10000;       // K (paper: 10^4)
  bool gaussian_noise = true;  // false: sample the means themselves (Table 1, row 6-8)
};

template <class T>
class Domain {
 public:
  Domain() = default;
  Domain(Parameters<T>& params, const DomainOptions& options);
  // mu_k ~ U([0, 1]^2), as the paper initialises them.
  void initialize(Parameters<T>& params, Rng& rng) const;
  // M samples x_P (M x 2) on the tape; `component` receives each sample's i.
  Var sample(Tape<T>& t, Parameters<T>& params, Index count, Rng& rng,
             std::vector<int>* component = nullptr) const;
  T sigma() const { return sigma_; }
  int gaussians() const { return options_.gaussians; }
  int means() const { return mu_; }  // parameter index of mu (K x 2)
  const DomainOptions& options() const { return options_; }
  // P(x) of Eq. 4 at the rows of x (N x 2), by brute force over the K means
  // restricted to a 6-sigma window (the rest contributes < 1e-7 relative).
  std::vector<double> density(const Parameters<T>& params, const Block<double>& x) const;

 private:
  DomainOptions options_;
  int mu_ = -1;
  T sigma_ = T(0);
};

}  // namespace jsa
