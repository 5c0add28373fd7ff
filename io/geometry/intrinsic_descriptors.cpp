#include "io/geometry/intrinsic_descriptors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <utility>
#include <vector>

#include "engine/check.h"
#include "engine/parallel.h"
#include "io/geometry/nearest.h"

namespace jsa {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The graph as compressed rows: the neighbours of v are
// neighbour[start[v] .. start[v + 1]), with the lengths of the edges.
struct Graph {
  std::vector<int> start, neighbour;
  std::vector<double> length;
  Index size() const { return Index(start.size()) - 1; }
};

Graph graph_of(const Block<double>& nodes, const std::vector<std::pair<int, int>>& edges) {
  const Index n = nodes.rows();
  std::vector<std::vector<int>> adjacent(static_cast<size_t>(n));
  for (const auto& [a, b] : edges) {
    adjacent[size_t(a)].push_back(b);
    adjacent[size_t(b)].push_back(a);
  }
  Graph g;
  g.start.assign(size_t(n) + 1, 0);
  for (Index v = 0; v < n; ++v) {
    std::vector<int>& a = adjacent[size_t(v)];
    std::sort(a.begin(), a.end());
    a.erase(std::unique(a.begin(), a.end()), a.end());
    g.start[size_t(v) + 1] = g.start[size_t(v)] + int(a.size());
    for (int w : a) {
      g.neighbour.push_back(w);
      g.length.push_back((nodes.row(v) - nodes.row(w)).norm());
    }
  }
  return g;
}

// Shortest paths from `source` along the graph (Dijkstra).
void distances_from(const Graph& g, int source, std::vector<double>& d) {
  d.assign(size_t(g.size()), kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  d[size_t(source)] = 0;
  queue.push({0.0, source});
  while (!queue.empty()) {
    const auto [dv, v] = queue.top();
    queue.pop();
    if (dv > d[size_t(v)]) continue;
    for (int e = g.start[size_t(v)]; e < g.start[size_t(v) + 1]; ++e) {
      const int w = g.neighbour[size_t(e)];
      const double dw = dv + g.length[size_t(e)];
      if (dw < d[size_t(w)]) {
        d[size_t(w)] = dw;
        queue.push({dw, w});
      }
    }
  }
}

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
    double area = 0;
    for (Index f = 0; f < mesh.faces.rows(); ++f) {
      const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
      edges.push_back({std::min(a, b), std::max(a, b)});
      edges.push_back({std::min(b, c), std::max(b, c)});
      edges.push_back({std::min(a, c), std::max(a, c)});
      const Eigen::Vector3d ab = (mesh.vertices.row(b) - mesh.vertices.row(a)).transpose();
      const Eigen::Vector3d ac = (mesh.vertices.row(c) - mesh.vertices.row(a)).transpose();
      area += 0.5 * ab.cross(ac).norm();
    }
    // sqrt(A / 4 pi): 1 for the unit sphere; a pose does not change the area.
    unit = std::sqrt(area / (4 * M_PI));
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
  const Graph g = graph_of(out.nodes, edges);
  const Index n = g.size();

  // Farthest-point sources: the first is the node farthest from node 0, each
  // next one the node farthest from all chosen so far (unreached nodes first,
  // so every connected component gets a source); ties: the lowest index.
  const int s = int(std::min<Index>(o.sources, n));
  std::vector<std::vector<double>> from(static_cast<size_t>(s));
  std::vector<double> nearest_source, d0;
  distances_from(g, 0, d0);
  auto farthest = [&](const std::vector<double>& d) {
    int best = 0;
    for (Index v = 1; v < n; ++v)
      if (d[size_t(v)] > d[size_t(best)]) best = int(v);
    return best;
  };
  for (Index v = 0; v < n; ++v)
    if (d0[size_t(v)] == kInf) d0[size_t(v)] = -1;  // the first source: within node 0's component
  int next = farthest(d0);
  nearest_source.assign(size_t(n), kInf);
  for (int k = 0; k < s; ++k) {
    distances_from(g, next, from[size_t(k)]);
    for (Index v = 0; v < n; ++v)
      nearest_source[size_t(v)] = std::min(nearest_source[size_t(v)], from[size_t(k)][size_t(v)]);
    next = farthest(nearest_source);
  }

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
