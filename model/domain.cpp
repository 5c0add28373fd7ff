#include "model/domain.h"

#include <algorithm>
#include <cmath>

#include "engine/ops.h"
#include "engine/parallel.h"

namespace jsa {

template <class T>
Domain<T>::Domain(Parameters<T>& params, const DomainOptions& options)
    : options_(options), sigma_(T(1.0 / std::sqrt(double(options.gaussians)))) {
  JSA_CHECK(options.gaussians > 0, "the domain needs at least one Gaussian");
  mu_ = params.add("domain.mu", options.gaussians, 2);
}

template <class T>
void Domain<T>::initialize(Parameters<T>& params, Rng& rng) const {
  auto mu = params.value(mu_);
  for (Index i = 0; i < mu.size(); ++i) mu.data()[i] = T(rng.uniform());
}

// x_m = mu_{i_m} + e_m,  i_m ~ U{0..K-1},  e_m ~ N(0, sigma^2 I)    (Eq. 4)
template <class T>
Var Domain<T>::sample(Tape<T>& t, Parameters<T>& params, Index count, Rng& rng,
                      std::vector<int>* component) const {
  // The draws go straight into tape storage: the components into a vector the
  // tape keeps for this op (workspace), the noise into its constant node.
  std::vector<int>& index = t.template workspace<std::vector<int>>();
  index.resize(static_cast<size_t>(count));
  const Var noise_node = t.constant(Block<T>::Zero(count, 2));
  Block<T>& noise = t.value(noise_node);
  for (Index m = 0; m < count; ++m) {
    index[m] = int(rng.below(uint64_t(options_.gaussians)));
    noise(m, 0) = options_.gaussian_noise ? T(sigma_ * rng.normal()) : T(0);
    noise(m, 1) = options_.gaussian_noise ? T(sigma_ * rng.normal()) : T(0);
  }
  if (component) *component = index;
  Var mu = params.on(t, mu_);
  return add(t, gather_rows(t, mu, index), noise_node);
}

template <class T>
std::vector<double> Domain<T>::density(const Parameters<T>& params, const Block<double>& x) const {
  const auto mu = params.value(mu_);
  const double s = double(sigma_), inv2s2 = 1.0 / (2 * s * s);
  const double norm = 1.0 / (2 * M_PI * s * s * double(options_.gaussians));
  const double window = 6 * s;
  // Bucket the means on a grid of cell `window` so each query visits 3x3 cells.
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (Index k = 0; k < mu.rows(); ++k)
    for (int c = 0; c < 2; ++c) {
      lo[c] = std::min(lo[c], double(mu(k, c)));
      hi[c] = std::max(hi[c], double(mu(k, c)));
    }
  const int gx = std::max(1, int((hi[0] - lo[0]) / window) + 1);
  const int gy = std::max(1, int((hi[1] - lo[1]) / window) + 1);
  std::vector<std::vector<int>> cell(size_t(gx) * gy);
  auto cell_of = [&](double v, int c, int g) {
    return std::clamp(int((v - lo[c]) / window), 0, g - 1);
  };
  for (Index k = 0; k < mu.rows(); ++k)
    cell[size_t(cell_of(mu(k, 0), 0, gx)) * gy + cell_of(mu(k, 1), 1, gy)].push_back(int(k));
  std::vector<double> p(size_t(x.rows()), 0.0);
  parallel_rows(
      x.rows(),
      [&](Index r0, Index r1) {
        for (Index r = r0; r < r1; ++r) {
          const double qx = x(r, 0), qy = x(r, 1);
          if (qx < lo[0] - window || qx > hi[0] + window || qy < lo[1] - window ||
              qy > hi[1] + window)
            continue;
          const int cx = int(std::floor((qx - lo[0]) / window)),
                    cy = int(std::floor((qy - lo[1]) / window));
          double acc = 0;
          for (int i = cx - 1; i <= cx + 1; ++i)
            for (int j = cy - 1; j <= cy + 1; ++j) {
              if (i < 0 || j < 0 || i >= gx || j >= gy) continue;
              for (int k : cell[size_t(i) * gy + j]) {
                const double dx = qx - mu(k, 0), dy = qy - mu(k, 1);
                acc += std::exp(-(dx * dx + dy * dy) * inv2s2);
              }
            }
          p[size_t(r)] = acc * norm;
        }
      },
      256);
  return p;
}

template class Domain<float>;
template class Domain<double>;

}  // namespace jsa
