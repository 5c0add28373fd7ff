// Beyond the paper: see model/heuristics/reseed.h (one switch in FitOptions).
#include "model/heuristics/reseed.h"

#include <algorithm>

#include "io/geometry/nearest.h"

namespace jsa {

ReseedReport reseed_flipped_means(Atlas<float>& atlas, const std::vector<Block<float>>& targets,
                                  const std::vector<int>& shapes, Rng& rng,
                                  const std::vector<std::vector<float>*>& moments,
                                  int samples_per_mean) {
  JSA_CHECK(!targets.empty() && targets.size() == shapes.size(),
            "reseed: one target block per shape");
  JSA_CHECK(samples_per_mean > 0, "reseed: samples_per_mean must be positive");
  const int mu_index = atlas.domain.means();
  auto mu = atlas.params.value(mu_index);
  const Index K = mu.rows(), S = samples_per_mean;
  const double sigma = double(atlas.domain.sigma());
  // S draws of every component N(mu_k, sigma^2 I): rows k*S .. k*S + S - 1.
  Block<double> uv(K * S, 2);
  for (Index k = 0; k < K; ++k)
    for (Index j = 0; j < S; ++j)
      for (int c = 0; c < 2; ++c) uv(k * S + j, c) = double(mu(k, c)) + sigma * rng.normal();

  std::vector<double> back(size_t(K), 0.0);
  std::vector<char> facing(size_t(K * S), 1);  // of the first shape
  Block<double> first_points;
  std::vector<int> nn;
  for (size_t s = 0; s < shapes.size(); ++s) {
    JSA_CHECK(targets[s].cols() == 6 && targets[s].rows() > 0, "reseed: targets must be M x 6");
    Block<double> points, normals;
    evaluate_surface(atlas, uv, points, normals, shapes[s]);
    const Block<double> target_points = targets[s].leftCols(3).cast<double>();
    nearest(points, target_points, nn);
    for (Index i = 0; i < K * S; ++i) {
      const bool away =
          normals.row(i).dot(targets[s].row(nn[size_t(i)]).rightCols(3).cast<double>()) < 0;
      back[size_t(i / S)] += away ? 1.0 : 0.0;
      if (s == 0) facing[size_t(i)] = away ? 0 : 1;
    }
    if (s == 0) first_points = std::move(points);
  }
  ReseedReport report;
  std::vector<Index> flipped;
  double total = 0;
  for (Index k = 0; k < K; ++k) {
    total += back[size_t(k)];
    if (back[size_t(k)] > 0.5 * double(S * Index(shapes.size()))) flipped.push_back(k);
  }
  report.back_facing = total / double(K * S * Index(shapes.size()));
  report.flipped = int(flipped.size());
  if (flipped.empty()) return report;

  // The correctly facing surface: samples of components that stay, facing the target.
  std::vector<char> moved(size_t(K), 0);
  for (Index k : flipped) moved[size_t(k)] = 1;
  std::vector<Index> good;
  for (Index i = 0; i < K * S; ++i)
    if (!moved[size_t(i / S)] && facing[size_t(i)]) good.push_back(i);
  if (good.empty()) return report;  // nothing faces the right way: leave it to the global mirror
  Block<double> good_points(Index(good.size()), 3);
  for (size_t g = 0; g < good.size(); ++g) good_points.row(Index(g)) = first_points.row(good[g]);
  const Block<double> target_points = targets[0].leftCols(3).cast<double>();
  std::vector<double> d2;
  nearest(target_points, good_points, nn, &d2);
  // Holes first: targets drawn with probability proportional to d^2.
  std::vector<double> cumulative(d2.size());
  double sum = 0;
  for (size_t t = 0; t < d2.size(); ++t) cumulative[t] = (sum += d2[t]);
  for (Index k : flipped) {
    size_t t = size_t(rng.below(uint64_t(d2.size())));
    if (sum > 0)
      t = size_t(std::upper_bound(cumulative.begin(), cumulative.end(), rng.uniform() * sum) -
                 cumulative.begin());
    t = std::min(t, d2.size() - 1);
    const Index from = good[size_t(nn[t])];
    for (int c = 0; c < 2; ++c) mu(k, c) = float(uv(from, c) + 0.5 * sigma * rng.normal());
  }
  // Fresh Adam moments for the moved means (rows of the K x 2 row-major block).
  const size_t offset = atlas.params.entry(mu_index).offset;
  for (std::vector<float>* m : moments) {
    if (!m || m->empty()) continue;
    JSA_CHECK(m->size() == atlas.params.size(), "reseed: a buffer does not match the parameters");
    for (Index k : flipped) (*m)[offset + size_t(2 * k)] = (*m)[offset + size_t(2 * k) + 1] = 0.0f;
  }
  return report;
}

}  // namespace jsa
