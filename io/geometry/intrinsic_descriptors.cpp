#include "io/geometry/intrinsic_descriptors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "engine/check.h"
#include "engine/parallel.h"
#include "io/geometry/geodesic.h"
#include "io/geometry/nearest.h"

namespace jsa {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The q-quantile of sorted values (linear interpolation).
double quantile(const std::vector<double>& sorted, double q) {
  const double at = q * double(sorted.size() - 1);
  const size_t lo = size_t(std::floor(at)), hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (at - double(lo)) * (sorted[hi] - sorted[lo]);
}

}  // namespace

IntrinsicDescriptors intrinsic_descriptors(const Mesh& mesh, const IntrinsicOptions& o) {
  JSA_CHECK(o.sources >= 1 && o.neighbours >= 1,
            "intrinsic descriptors: sources and neighbours >= 1");
  JSA_CHECK(mesh.vertices.rows() > 0, "intrinsic descriptors of an empty shape");
  IntrinsicDescriptors out;
  std::vector<std::pair<int, int>> edges;
  double unit = 1;  // the length the distances are divided by
  if (!mesh.is_point_cloud()) {
    out.nodes = mesh.vertices;
    edges = face_edges(mesh);
    // sqrt(A / 4 pi): 1 for the unit sphere; a pose does not change the area.
    unit = std::sqrt(surface_area(mesh) / (4 * M_PI));
  } else {
    // A cloud: at most 4000 of its points (evenly by index), each joined to its
    // k nearest (brute force: 4000^2 distances).
    const Index n = mesh.vertices.rows(), g = std::min<Index>(n, 4000);
    out.nodes.resize(g, 3);
    for (Index i = 0; i < g; ++i) out.nodes.row(i) = mesh.vertices.row(i * n / g);
    const int k = int(std::min<Index>(o.neighbours, g - 1));
    std::vector<std::vector<int>> near(static_cast<size_t>(g));
    parallel_rows(g, [&](Index begin, Index end) {
      std::vector<std::pair<double, int>> d(static_cast<size_t>(g));
      for (Index i = begin; i < end; ++i) {
        for (Index j = 0; j < g; ++j)
          d[size_t(j)] = {(out.nodes.row(i) - out.nodes.row(j)).squaredNorm(), int(j)};
        std::partial_sort(d.begin(), d.begin() + k + 1, d.end());
        for (int m = 0; m <= k; ++m)
          if (d[size_t(m)].second != int(i)) near[size_t(i)].push_back(d[size_t(m)].second);
      }
    });
    for (Index i = 0; i < g; ++i)
      for (int j : near[size_t(i)])
        edges.push_back({int(std::min<Index>(i, j)), int(std::max<Index>(i, j))});
    const Eigen::RowVector3d mean = out.nodes.colwise().mean();
    unit = std::max(1e-12, (out.nodes.rowwise() - mean).rowwise().norm().maxCoeff());
  }
  JSA_CHECK(unit > 0 && std::isfinite(unit), "intrinsic descriptors: a shape of no area");
  const EdgeGraph g = edge_graph(out.nodes, edges);
  const Index n = g.size();

  // Farthest-point sources, so the sources spread evenly over the surface.
  std::vector<std::vector<double>> from;
  const int s = int(farthest_nodes(g, o.sources, from).size());

  out.values.resize(n, kIntrinsicChannels);
  parallel_rows(n, [&](Index begin, Index end) {
    std::vector<double> d;
    for (Index v = begin; v < end; ++v) {
      d.clear();
      for (int k = 0; k < s; ++k)
        if (from[size_t(k)][size_t(v)] < kInf) d.push_back(from[size_t(k)][size_t(v)] / unit);
      if (d.empty()) {  // a component without a source (more components than S)
        out.values.row(v).setZero();
        continue;
      }
      std::sort(d.begin(), d.end());
      double mean = 0;
      for (double x : d) mean += x;
      mean /= double(d.size());
      out.values(v, 0) = mean;
      out.values(v, 1) = quantile(d, 0.2);
      out.values(v, 2) = quantile(d, 0.8);
    }
  });
  return out;
}

Block<double> descriptors_at(const Block<double>& points, const Block<double>& nodes,
                             const Block<double>& values) {
  JSA_CHECK(nodes.rows() == values.rows() && nodes.rows() > 0, "descriptors_at: no nodes");
  std::vector<int> index;
  nearest(points, nodes, index);
  Block<double> out(points.rows(), values.cols());
  for (Index i = 0; i < points.rows(); ++i) out.row(i) = values.row(index[size_t(i)]);
  return out;
}

void rank_normalize(Block<double>& values) {
  const Index n = values.rows();
  if (n < 2) {
    values.setZero();
    return;
  }
  std::vector<Index> order(static_cast<size_t>(n));
  for (Index c = 0; c < values.cols(); ++c) {
    for (Index i = 0; i < n; ++i) order[size_t(i)] = i;
    std::sort(order.begin(), order.end(), [&](Index a, Index b) {
      return values(a, c) < values(b, c) || (values(a, c) == values(b, c) && a < b);
    });
    Index i = 0;
    while (i < n) {  // a run of equal values takes its mean rank
      Index j = i + 1;
      while (j < n && values(order[size_t(j)], c) == values(order[size_t(i)], c)) ++j;
      const double rank = 0.5 * double(i + j - 1) / double(n - 1);
      for (Index k = i; k < j; ++k) values(order[size_t(k)], c) = rank;
      i = j;
    }
  }
}

}  // namespace jsa
