#include "model/tool/node_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/geometry/nearest.h"

namespace jsa {

namespace {

// n rows of `points` spread as far apart as they go (the first row first).
std::vector<Index> farthest_points(const Block<double>& points, Index n) {
  std::vector<Index> chosen{0};
  Eigen::VectorXd distance = (points.rowwise() - points.row(0)).rowwise().squaredNorm();
  while (Index(chosen.size()) < n) {
    Index next = 0;
    distance.maxCoeff(&next);
    chosen.push_back(next);
    distance = distance.cwiseMin((points.rowwise() - points.row(next)).rowwise().squaredNorm());
  }
  return chosen;
}

// One field's kernels: c_k the farthest points of the template's surface
// (their domain points x, so every part of it has nodes whatever the domain's
// stretch there), sigma = width x the centres' mean spacing in the domain.
// Returns the centres; writes them and sigma into the field's blocks.
Block<double> place_kernels(Atlas<float>& atlas, int field, int n, const Block<double>& x,
                            const Block<double>& points, double width, double& sigma) {
  const std::vector<Index> chosen = farthest_points(points, n);
  Block<double> centres(n, 2);
  for (int k = 0; k < n; ++k) centres.row(k) = x.row(chosen[size_t(k)]);
  double spacing = 0;
  for (int k = 0; k < n; ++k) {
    double nearest_sq = std::numeric_limits<double>::infinity();
    for (int j = 0; j < n; ++j)
      if (j != k)
        nearest_sq = std::min(nearest_sq, (centres.row(k) - centres.row(j)).squaredNorm());
    spacing += std::sqrt(nearest_sq);
  }
  sigma = width * spacing / n;
  JSA_CHECK(sigma > 0 && std::isfinite(sigma), "place_nodes: the centres coincide");
  atlas.params.value(atlas.phi.node_centres(field)) = centres.cast<float>();
  atlas.params.value(atlas.phi.node_sigma(field))(0, 0) = float(sigma);
  return centres;
}

}  // namespace

NodePlacementReport place_nodes(Atlas<float>& atlas, int template_shape,
                                const Block<float>* template_vertices,
                                const std::vector<Block<float>>* images,
                                const NodePlacementOptions& o) {
  Parametrization<float>& phi = atlas.phi;
  JSA_CHECK(phi.has_nodes(), "place_nodes: the atlas has no nodes (deform_nodes = 0)");
  const int n = atlas.options().deform_nodes;
  const int shapes = atlas.shapes();
  JSA_CHECK(o.samples >= std::max(n, atlas.options().fine_nodes),
            "place_nodes: fewer samples than nodes");
  // The template's surface at samples of P (its nodes are still off: sigma = 0).
  Rng rng(o.seed, 0x6e6f646573ULL);  // "nodes": a stream of its own
  Block<double> x, points, normals;
  sample_reconstruction(atlas, o.samples, rng, x, points, normals, template_shape);

  NodePlacementReport report;
  double sigma = 0;
  const Block<double> centres = place_kernels(atlas, 0, n, x, points, o.width, sigma);
  report.sigma = sigma;
  // The second field (AtlasOptions::fine_nodes) starts from zero: it learns
  // what the first, fitted to the registration or not, leaves.
  if (phi.has_nodes(1)) {
    place_kernels(atlas, 1, atlas.options().fine_nodes, x, points, o.fine_width, report.fine_sigma);
    atlas.params.value(atlas.params.find("nodes.fine.phi")).setZero();
  }
  report.target_rms.assign(size_t(shapes), 0.0);
  report.residual_rms.assign(size_t(shapes), 0.0);
  auto displacements = atlas.params.value(atlas.params.find("nodes.phi"));
  displacements.setZero();
  if (!template_vertices || !images) return report;
  JSA_CHECK(int(images->size()) == shapes, "place_nodes: one image block per shape");

  // G: w_k(x_s), the same rows for every shape (they share the domain), the
  // normalised kernels of model/parametrize.h.
  Block<double> g(o.samples, n);
  for (Index s = 0; s < o.samples; ++s) {
    for (int k = 0; k < n; ++k)
      g(s, k) = -0.5 * (x.row(s) - centres.row(k)).squaredNorm() / (sigma * sigma);
    g.row(s) = (g.row(s).array() - g.row(s).maxCoeff()).exp();
    g.row(s) /= g.row(s).sum();
  }
  Eigen::MatrixXd normal = g.transpose() * g;
  const double ridge = o.ridge * normal.trace() / n;
  normal.diagonal().array() += ridge;
  const Eigen::LDLT<Eigen::MatrixXd> solve(normal);
  // Each sample's template vertex: the registration is defined on them.
  std::vector<int> vertex;
  NearestIndex<float>(*template_vertices).query(points.cast<float>(), vertex);
  for (int i = 0; i < shapes; ++i) {
    if (i == template_shape) continue;
    const Block<float>& image = (*images)[size_t(i)];
    JSA_CHECK(image.rows() == template_vertices->rows() && image.cols() == 3,
              "place_nodes: shape " << i << "'s images, one per template vertex");
    // d_s = T_i(v_s) - v_s: where the map moves the sample's vertex.
    Block<double> d(o.samples, 3);
    for (Index s = 0; s < o.samples; ++s) {
      const int v = vertex[size_t(s)];
      d.row(s) = (image.row(v) - template_vertices->row(v)).cast<double>();
    }
    // min_t |G t - d|^2 + ridge |t|^2
    const Block<double> t = solve.solve(g.transpose() * d);
    displacements.middleRows(Index(i) * n, n) = t.cast<float>();
    report.target_rms[size_t(i)] = std::sqrt(d.squaredNorm() / double(o.samples));
    report.residual_rms[size_t(i)] = std::sqrt((g * t - d).squaredNorm() / double(o.samples));
  }
  return report;
}

}  // namespace jsa
