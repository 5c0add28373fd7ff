// Statistics of Domain::sample (Eq. 4, model/domain.h): the component of each
// sample is uniform over the K Gaussians, and its offset from that Gaussian's
// mean has spread sigma = 1/sqrt(K) in each coordinate. The bounds are
// statistical: each would fail a correct sampler with probability about 1e-6,
// and the draws are seeded, so the outcome is fixed; a wrong sigma or a biased
// choice of component fails them by far.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/tape.h"
#include "model/domain.h"

using namespace jsa;

TEST_CASE("Domain::sample: uniform components, per-component spread sigma = 1/sqrt(K)",
          "[domain]") {
  const int k = 16;
  const Index n = 160000;  // 10^4 samples per component
  Parameters<double> params;
  Domain<double> domain(params, DomainOptions{k, true});
  Rng init(1);
  domain.initialize(params, init);
  Tape<double> t;
  Rng rng(2);
  std::vector<int> component;
  const Block<double> x = t.value(domain.sample(t, params, n, rng, &component));
  REQUIRE(component.size() == size_t(n));
  const auto mu = params.value(domain.means());
  const double sigma = 1.0 / std::sqrt(double(k));
  CHECK(domain.sigma() == sigma);

  // Uniform choice: Pearson's chi-square over the K counts, K - 1 = 15 degrees
  // of freedom; P(chi2_15 > 56.49) = 1e-6.
  std::vector<double> count(size_t(k), 0.0);
  for (int i : component) {
    REQUIRE((i >= 0 && i < k));
    count[size_t(i)] += 1;
  }
  const double expected = double(n) / k;
  double chi2 = 0;
  for (double c : count) chi2 += (c - expected) * (c - expected) / expected;
  INFO("chi-square of the component counts: " << chi2 << " (bound 56.49, 15 dof, p = 1e-6)");
  CHECK(chi2 < 56.49);

  // Spread: for each component, the offsets x - mu_i of its ~10^4 samples
  // (both coordinates, ~2 10^4 values) have mean 0 and variance sigma^2. The
  // sample variance of N normal values has relative standard error sqrt(2/N)
  // and the mean has standard error sigma/sqrt(N): bounds at 5 standard errors
  // (two-sided p = 6e-7 each; 32 checks per coordinate pair).
  for (int c = 0; c < k; ++c) {
    double sum = 0, sum2 = 0, values = 0;
    for (Index m = 0; m < n; ++m) {
      if (component[size_t(m)] != c) continue;
      for (int d = 0; d < 2; ++d) {
        const double e = x(m, d) - mu(c, d);
        sum += e;
        sum2 += e * e;
        values += 1;
      }
    }
    const double mean = sum / values, variance = sum2 / values - mean * mean;
    INFO("component " << c << ": " << values << " offsets, mean " << mean << ", variance / sigma^2 "
                      << variance / (sigma * sigma));
    CHECK(std::abs(mean) < 5 * sigma / std::sqrt(values));
    CHECK(std::abs(variance / (sigma * sigma) - 1) < 5 * std::sqrt(2 / values));
  }
}

TEST_CASE("Domain::sample without noise returns the means themselves", "[domain]") {
  Parameters<double> params;
  Domain<double> domain(params, DomainOptions{8, false});
  Rng init(3);
  domain.initialize(params, init);
  Tape<double> t;
  Rng rng(4);
  std::vector<int> component;
  const Block<double> x = t.value(domain.sample(t, params, 100, rng, &component));
  const auto mu = params.value(domain.means());
  for (Index m = 0; m < x.rows(); ++m)
    REQUIRE((x.row(m) - mu.row(component[size_t(m)])).norm() == 0.0);
}
