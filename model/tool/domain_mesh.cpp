#include "model/tool/domain_mesh.h"

#include <algorithm>
#include <cmath>

#include "engine/ops.h"

namespace jsa {

TextureFrame texture_frame(const Atlas<float>& atlas) {
  const auto mu = atlas.params.value(atlas.domain.means());
  const double s = atlas.domain.sigma();
  const Eigen::RowVector2d lo = mu.colwise().minCoeff().cast<double>().array() - 3 * s;
  const Eigen::RowVector2d hi = mu.colwise().maxCoeff().cast<double>().array() + 3 * s;
  return {lo, std::max(hi(0) - lo(0), hi(1) - lo(1))};
}

Block<double> TextureFrame::to_texture(const Block<double>& uv) const {
  return (uv.rowwise() - lo) / side;
}

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
    for (int j = 0; j < ny; ++j)
      nodes.row(Index(i) * ny + j) << out.lo(0) + i * h, out.lo(1) + j * h;
  const std::vector<double> p = atlas.domain.density(atlas.params, nodes);
  std::vector<double> at_means = atlas.domain.density(atlas.params, mu.cast<double>());
  std::nth_element(at_means.begin(), at_means.begin() + at_means.size() / 2, at_means.end());
  out.level = o.threshold * at_means[at_means.size() / 2];

  // Marching squares: in each cell, walk the corners counter-clockwise and keep
  // the inside corners plus the points where P crosses the level on the cell's
  // edges (linear interpolation). The kept points lie on the cell's boundary in
  // cyclic order, so they form a convex polygon: a fan triangulates it and keeps
  // uv's counter-clockwise orientation. Corners and crossings are shared between
  // neighbouring cells, so the triangulation has no cracks inside the domain.
  auto node = [&](int i, int j) { return Index(i) * ny + j; };
  std::vector<int> corner_id(size_t(nodes.rows()), -1), edge_id(2 * size_t(nodes.rows()), -1);
  std::vector<Eigen::RowVector2d> verts;
  auto corner_vertex = [&](Index v) {
    if (corner_id[v] < 0) {
      corner_id[v] = int(verts.size());
      verts.push_back(nodes.row(v));
    }
    return corner_id[v];
  };
  // The crossing on the edge from node v to node w (axis 0: +i, axis 1: +j).
  auto crossing_vertex = [&](Index v, Index w, int axis) {
    const Index from = std::min(v, w), to = std::max(v, w);
    int& id = edge_id[2 * size_t(from) + axis];
    if (id < 0) {
      const double t = (out.level - p[from]) / (p[to] - p[from]);
      id = int(verts.size());
      verts.push_back(nodes.row(from) +
                      std::clamp(t, 0.0, 1.0) * (nodes.row(to) - nodes.row(from)));
    }
    return id;
  };
  std::vector<Eigen::Vector3i> tris;
  auto fan = [&](const std::vector<int>& poly) {
    for (size_t k = 1; k + 1 < poly.size(); ++k) tris.push_back({poly[0], poly[k], poly[k + 1]});
  };
  for (int i = 0; i + 1 < nx; ++i)
    for (int j = 0; j + 1 < ny; ++j) {
      const Index c[4] = {node(i, j), node(i + 1, j), node(i + 1, j + 1), node(i, j + 1)};
      const int axis[4] = {0, 1, 0, 1};  // edge c[k] -> c[k+1] runs along i, j, i, j
      bool in[4];
      int inside = 0;
      double cell = 0;
      for (int k = 0; k < 4; ++k) {
        in[k] = p[c[k]] >= out.level;
        inside += in[k];
        cell += 0.25 * p[c[k]];
      }
      if (inside == 0) continue;
      const bool saddle = inside == 2 && in[0] == in[2];
      if (saddle && cell < out.level) {
        // Two separate corners: each with its own two crossings.
        for (int k = 0; k < 4; ++k) {
          if (!in[k]) continue;
          const int prev = (k + 3) % 4, next = (k + 1) % 4;
          fan({corner_vertex(c[k]), crossing_vertex(c[k], c[next], axis[k]),
               crossing_vertex(c[prev], c[k], axis[prev])});
        }
        continue;
      }
      std::vector<int> poly;
      for (int k = 0; k < 4; ++k) {
        const int next = (k + 1) % 4;
        if (in[k]) poly.push_back(corner_vertex(c[k]));
        if (in[k] != in[next]) poly.push_back(crossing_vertex(c[k], c[next], axis[k]));
      }
      fan(poly);
    }
  out.uv.resize(Index(verts.size()), 2);
  for (size_t v = 0; v < verts.size(); ++v) out.uv.row(Index(v)) = verts[v];
  out.faces.resize(Index(tris.size()), 3);
  for (size_t f = 0; f < tris.size(); ++f) out.faces.row(Index(f)) = tris[f].transpose();
  // P's mass inside the domain: grid nodes above the level, against all nodes
  // (the grid spans the means +- 3 sigma, so it holds all but ~0.3% of P).
  double inside_mass = 0, total_mass = 0;
  for (size_t v = 0; v < p.size(); ++v) {
    total_mass += p[v];
    if (p[v] >= out.level) inside_mass += p[v];
  }
  out.mass_fraction = total_mass > 0 ? inside_mass / total_mass : 0;
  return out;
}

}  // namespace jsa
