#include "io/geometry/geodesic.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>

namespace jsa {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}  // namespace

EdgeGraph edge_graph(const Block<double>& nodes, const std::vector<std::pair<int, int>>& edges) {
  const Index n = nodes.rows();
  std::vector<std::vector<int>> adjacent(static_cast<size_t>(n));
  for (const auto& [a, b] : edges) {
    adjacent[size_t(a)].push_back(b);
    adjacent[size_t(b)].push_back(a);
  }
  EdgeGraph g;
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

std::vector<std::pair<int, int>> face_edges(const Mesh& mesh) {
  std::vector<std::pair<int, int>> edges;
  edges.reserve(size_t(mesh.faces.rows()) * 3);
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const int a = mesh.faces(f, 0), b = mesh.faces(f, 1), c = mesh.faces(f, 2);
    edges.push_back({std::min(a, b), std::max(a, b)});
    edges.push_back({std::min(b, c), std::max(b, c)});
    edges.push_back({std::min(a, c), std::max(a, c)});
  }
  return edges;
}

double surface_area(const Mesh& mesh) {
  double area = 0;
  for (Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::Vector3d a = mesh.vertices.row(mesh.faces(f, 0)).transpose();
    const Eigen::Vector3d ab = mesh.vertices.row(mesh.faces(f, 1)).transpose() - a;
    const Eigen::Vector3d ac = mesh.vertices.row(mesh.faces(f, 2)).transpose() - a;
    area += 0.5 * ab.cross(ac).norm();
  }
  return area;
}

void distances_from(const EdgeGraph& g, int source, std::vector<double>& d) {
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

std::vector<int> farthest_nodes(const EdgeGraph& g, int n,
                                std::vector<std::vector<double>>& distances) {
  const Index size = g.size();
  const int count = int(std::min<Index>(n, size));
  distances.assign(size_t(count), {});
  std::vector<int> chosen;
  if (count == 0) return chosen;
  auto farthest = [&](const std::vector<double>& d) {
    int best = 0;
    for (Index v = 1; v < size; ++v)
      if (d[size_t(v)] > d[size_t(best)]) best = int(v);
    return best;
  };
  std::vector<double> d0;
  distances_from(g, 0, d0);
  for (double& d : d0)
    if (d == kInf) d = -1;  // the first node: within node 0's component
  int next = farthest(d0);
  std::vector<double> nearest_chosen(size_t(size), kInf);
  for (int k = 0; k < count; ++k) {
    chosen.push_back(next);
    distances_from(g, next, distances[size_t(k)]);
    for (Index v = 0; v < size; ++v)
      nearest_chosen[size_t(v)] =
          std::min(nearest_chosen[size_t(v)], distances[size_t(k)][size_t(v)]);
    next = farthest(nearest_chosen);
  }
  return chosen;
}

}  // namespace jsa
