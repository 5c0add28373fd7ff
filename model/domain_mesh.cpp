#include "model/domain_mesh.h"

#include <algorithm>
#include <cmath>

#include "engine/ops.h"

namespace jsa {

DomainMesh mesh_domain(const Atlas<float>& atlas, const DomainMeshOptions& o) {
  JSA_CHECK(o.resolution >= 2, "resolution must be >= 2");
  const auto mu = atlas.params.value(atlas.domain.means());
  const double s = atlas.domain.sigma();
  DomainMesh out;
  out.lo = mu.colwise().minCoeff().cast<double>().array() - 3 * s;
  out.hi = mu.colwise().maxCoeff().cast<double>().array() + 3 * s;
  const Eigen::RowVector2d extent = out.hi - out.lo;
  const double h = std::max(extent(0), extent(1)) / o.resolution;
  const int nx = int(std::ceil(extent(0) / h)) + 1, ny = int(std::ceil(extent(1) / h)) + 1;

  // P on the grid's nodes and at the means (for the relative level).
  Block<double> nodes(Index(nx) * ny, 2);
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j) nodes.row(Index(i) * ny + j) << out.lo(0) + i * h, out.lo(1) + j * h;
  const std::vector<double> p = atlas.domain.density(atlas.params, nodes);
  std::vector<double> at_means = atlas.domain.density(atlas.params, mu.cast<double>());
  std::nth_element(at_means.begin(), at_means.begin() + at_means.size() / 2, at_means.end());
  out.level = o.threshold * at_means[at_means.size() / 2];

  // A cell is inside when its four corners are; its two triangles keep uv's orientation.
  std::vector<int> id(nodes.rows(), -1);
  std::vector<Eigen::Vector3i> tris;
  double inside_mass = 0, total_mass = 0;
  auto node = [&](int i, int j) { return Index(i) * ny + j; };
  for (int i = 0; i + 1 < nx; ++i)
    for (int j = 0; j + 1 < ny; ++j) {
      const Index a = node(i, j), b = node(i + 1, j), c = node(i + 1, j + 1), d = node(i, j + 1);
      const double cell_mass = 0.25 * (p[a] + p[b] + p[c] + p[d]) * h * h;
      total_mass += cell_mass;
      if (p[a] < out.level || p[b] < out.level || p[c] < out.level || p[d] < out.level) continue;
      inside_mass += cell_mass;
      for (Index v : {a, b, c, d})
        if (id[v] < 0) id[v] = 0;
      tris.push_back({int(a), int(b), int(c)});
      tris.push_back({int(a), int(c), int(d)});
    }
  int count = 0;
  for (auto& v : id)
    if (v >= 0) v = count++;
  out.uv.resize(count, 2);
  for (Index k = 0; k < nodes.rows(); ++k)
    if (id[k] >= 0) out.uv.row(id[k]) = nodes.row(k);
  out.faces.resize(Index(tris.size()), 3);
  for (size_t f = 0; f < tris.size(); ++f)
    for (int c = 0; c < 3; ++c) out.faces(Index(f), c) = id[tris[f](c)];
  out.mass_fraction = total_mass > 0 ? inside_mass / total_mass : 0;
  return out;
}

void evaluate_surface(Atlas<float>& atlas, const Block<double>& uv, Block<double>& points,
                      Block<double>& normals) {
  points.resize(uv.rows(), 3);
  normals.resize(uv.rows(), 3);
  Tape<float> t;
  const Index batch = 8192;
  for (Index b = 0; b < uv.rows(); b += batch) {
    const Index n = std::min(batch, uv.rows() - b);
    t.clear();
    Var x = t.constant(uv.middleRows(b, n).cast<float>());
    SurfacePoints s = atlas.phi.evaluate(t, atlas.params, x, true);
    points.middleRows(b, n) = t.value(s.points).cast<double>();
    normals.middleRows(b, n) = t.value(s.normals).cast<double>().rowwise().normalized();
  }
}

}  // namespace jsa
