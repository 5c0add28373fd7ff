#include "model/tool/template_coverage.h"

#include <algorithm>
#include <cmath>

#include "engine/check.h"
#include "io/geometry/nearest.h"

namespace jsa {

namespace {

Block<double> first_points(const Block<double>& pool, Index samples) {
  return pool.topLeftCorner(std::min(samples, pool.rows()), 3);
}

// Mean distance from `points` to the nearest of `images`.
double mean_distance(const Block<double>& points, const Block<double>& images) {
  std::vector<int> index;
  std::vector<double> d2;
  nearest(points, images, index, &d2);
  double sum = 0;
  for (double v : d2) sum += std::sqrt(v);
  return sum / double(std::max<size_t>(d2.size(), 1));
}

}  // namespace

CoverageChoice template_by_coverage(const std::vector<Mesh>& meshes,
                                    const std::vector<Normalization>& frames,
                                    const std::vector<Block<double>>& pools,
                                    const SpectralStartOptions& o, Index samples) {
  const size_t n = meshes.size();
  JSA_CHECK(n >= 1 && frames.size() == n && pools.size() == n,
            "template_by_coverage: one frame and one pool per mesh");
  const std::vector<LaplaceBasis> bases = laplace_bases(meshes, o.functions, "--template-coverage");
  CoverageChoice c;
  c.sums.assign(n, 0.0);
  for (size_t t = 0; t < n; ++t) {
    SpectralStart start = spectral_start(meshes, frames, int(t), o, &bases);
    // The candidate's samples, each carried by its nearest vertex's image:
    // area-uniform, so a template with more vertices is not favoured.
    const Block<double> own = first_points(pools[t], samples);
    std::vector<int> vertex;
    nearest(own, start.template_vertices, vertex);
    Block<double> images(own.rows(), 3);
    for (size_t j = 0; j < n; ++j) {
      if (j == t) continue;
      for (Index r = 0; r < own.rows(); ++r) images.row(r) = start.images[j].row(vertex[size_t(r)]);
      c.sums[t] += mean_distance(first_points(pools[j], samples), images);
    }
    if (t == 0 || c.sums[t] < c.sums[size_t(c.shape)]) {
      c.shape = int(t);
      c.start = std::move(start);
    }
  }
  return c;
}

}  // namespace jsa
