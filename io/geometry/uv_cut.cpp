#include "io/geometry/uv_cut.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <queue>

#include "engine/check.h"
#include "io/geometry/triangle_frame.h"

namespace jsa {
namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(int n) : parent(size_t(n)) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int x) {
    while (parent[size_t(x)] != x) x = parent[size_t(x)] = parent[size_t(parent[size_t(x)])];
    return x;
  }
  void unite(int a, int b) {
    a = find(a), b = find(b);
    if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);  // smallest id wins: deterministic
  }
};

Eigen::Vector3d pos(const Block<double>& p, int v) { return p.row(v).transpose(); }
Eigen::Vector2d uv_of(const Block<double>& uv, int v) { return uv.row(v).transpose(); }

// Faces of `chart` reachable from `seed` through inner edges (neighbour within the chart).
std::vector<int> bfs_order(int seed, const std::vector<int>& neighbour,
                           const std::vector<int>& face_chart, int chart, std::vector<int>& dist) {
  std::vector<int> order{seed};
  dist[size_t(seed)] = 0;
  for (size_t h = 0; h < order.size(); ++h) {
    const int f = order[h];
    for (int k = 0; k < 3; ++k) {
      const int nb = neighbour[size_t(3 * f + k)];
      if (nb < 0) continue;
      const int g = nb / 3;
      if (face_chart[size_t(g)] != chart || dist[size_t(g)] >= 0) continue;
      dist[size_t(g)] = dist[size_t(f)] + 1;
      order.push_back(g);
    }
  }
  return order;
}

}  // namespace

ChartMesh build_chart_mesh(const Faces& faces, const std::vector<int>& chart_faces,
                           const std::vector<int>& neighbour, const std::vector<int>& face_chart,
                           int chart) {
  ChartMesh m;
  m.faces = chart_faces;
  std::sort(m.faces.begin(), m.faces.end());
  const int n = int(m.faces.size());
  auto local_of = [&](int g) {
    return int(std::lower_bound(m.faces.begin(), m.faces.end(), g) - m.faces.begin());
  };
  UnionFind uf(3 * n);
  for (int i = 0; i < n; ++i) {
    const int g = m.faces[size_t(i)];
    for (int k = 0; k < 3; ++k) {
      const int nb = neighbour[size_t(3 * g + k)];
      if (nb < 0 || face_chart[size_t(nb / 3)] != chart) continue;
      const int j = local_of(nb / 3), l = nb % 3;
      // Edge k of g runs a -> b; edge l of the neighbour runs b -> a.
      uf.unite(3 * i + k, 3 * j + (l + 1) % 3);
      uf.unite(3 * i + (k + 1) % 3, 3 * j + l);
    }
  }
  std::vector<int> id(size_t(3 * n), -1);
  m.local.resize(n, 3);
  for (int c = 0; c < 3 * n; ++c) {
    const int r = uf.find(c);
    if (id[size_t(r)] < 0) {
      id[size_t(r)] = int(m.vertex.size());
      m.vertex.push_back(faces(m.faces[size_t(r / 3)], r % 3));
    }
    m.local(c / 3, c % 3) = id[size_t(r)];
  }
  m.usable.assign(size_t(n), 1);
  return m;
}

std::vector<std::vector<int>> boundary_loops(const Faces& local, Index vertex_count) {
  // Half-edges a -> b whose twin b -> a is absent are on the boundary.
  std::vector<std::pair<long long, int>> half;  // (key a * V + b, face)
  half.reserve(size_t(3 * local.rows()));
  const long long V = vertex_count;
  for (Index f = 0; f < local.rows(); ++f)
    for (int k = 0; k < 3; ++k) half.push_back({local(f, k) * V + local(f, (k + 1) % 3), int(f)});
  std::sort(half.begin(), half.end());
  auto has = [&](long long key) {
    auto it = std::lower_bound(half.begin(), half.end(), std::make_pair(key, -1));
    return it != half.end() && it->first == key;
  };
  std::vector<int> next(size_t(vertex_count), -1);
  for (const auto& [key, f] : half) {
    const long long a = key / V, b = key % V;
    if (!has(b * V + a)) next[size_t(a)] = int(b);
  }
  std::vector<std::vector<int>> loops;
  std::vector<char> seen(size_t(vertex_count), 0);
  for (Index v = 0; v < vertex_count; ++v) {
    if (next[size_t(v)] < 0 || seen[size_t(v)]) continue;
    std::vector<int> loop;
    int w = int(v);
    while (w >= 0 && !seen[size_t(w)]) {
      seen[size_t(w)] = 1;
      loop.push_back(w);
      w = next[size_t(w)];
    }
    loops.push_back(std::move(loop));
  }
  return loops;
}

ChartTopology chart_topology(const ChartMesh& chart) {
  const Faces& L = chart.local;
  std::vector<std::pair<int, int>> edges;
  edges.reserve(size_t(3 * L.rows()));
  for (Index f = 0; f < L.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = L(f, k), b = L(f, (k + 1) % 3);
      edges.push_back({std::min(a, b), std::max(a, b)});
    }
  std::sort(edges.begin(), edges.end());
  const Index E = std::unique(edges.begin(), edges.end()) - edges.begin();
  ChartTopology t;
  t.euler = int(Index(chart.vertex.size()) - E + L.rows());
  t.boundary_loops = int(boundary_loops(L, Index(chart.vertex.size())).size());
  return t;
}

namespace {

// A genus-0 chart that is not a disk (psi's slits and the holes left by other
// charts inside it, or no boundary at all) made one by cutting along shortest
// edge paths instead of splitting it: from the longest boundary loop, the
// shortest path (3D length, Dijkstra over the chart's inner edges) to the
// nearest loop not yet joined, then from everything joined so far to the next
// one, until all are joined (a tree of cuts: one boundary loop). A closed chart
// is cut along the path between two far-apart vertices. The cut edges are
// unglued in `neighbour`. Returns the number of paths cut (0: not genus 0).
int cut_along_paths(const ChartMesh& m, const Block<double>& positions,
                    std::vector<int>& neighbour) {
  const ChartTopology t = chart_topology(m);
  if (t.is_disk() || 2 - t.euler - t.boundary_loops != 0) return 0;
  const int V = int(m.vertex.size());
  struct Arc {
    int to, half;
    double length;
  };
  std::vector<std::vector<Arc>> arcs(static_cast<size_t>(V));
  for (Index i = 0; i < m.local.rows(); ++i)
    for (int k = 0; k < 3; ++k) {
      const int h = 3 * m.faces[size_t(i)] + k;
      if (neighbour[size_t(h)] < 0) continue;  // a boundary edge: nothing to cut
      const int a = m.local(i, k), b = m.local(i, (k + 1) % 3);
      const double len =
          (pos(positions, m.vertex[size_t(a)]) - pos(positions, m.vertex[size_t(b)])).norm();
      arcs[size_t(a)].push_back({b, h, len});
    }
  // Dijkstra from every vertex with joined[v]; stops at the first vertex with
  // goal(v). Returns it (-1 if none) with parent half-edges to trace the path.
  std::vector<double> dist(static_cast<size_t>(V));
  std::vector<int> parent(static_cast<size_t>(V)), from(static_cast<size_t>(V));
  auto dijkstra = [&](const std::vector<char>& joined, auto goal) {
    std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
    std::fill(parent.begin(), parent.end(), -1);
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
    for (int v = 0; v < V; ++v)
      if (joined[size_t(v)]) dist[size_t(v)] = 0, heap.push({0.0, v});
    int last = -1;
    while (!heap.empty()) {
      const auto [d, v] = heap.top();
      heap.pop();
      if (d > dist[size_t(v)]) continue;
      last = v;
      if (!joined[size_t(v)] && goal(v)) return v;
      for (const Arc& a : arcs[size_t(v)])
        if (d + a.length < dist[size_t(a.to)]) {
          dist[size_t(a.to)] = d + a.length;
          parent[size_t(a.to)] = a.half;
          from[size_t(a.to)] = v;
          heap.push({dist[size_t(a.to)], a.to});
        }
    }
    return goal(-1) ? last : -1;  // goal(-1): "the farthest vertex will do"
  };
  auto cut_path = [&](int v, std::vector<char>& joined) {
    while (parent[size_t(v)] >= 0) {
      const int h = parent[size_t(v)], twin = neighbour[size_t(h)];
      neighbour[size_t(h)] = -1;
      if (twin >= 0) neighbour[size_t(twin)] = -1;
      joined[size_t(v)] = 1;
      v = from[size_t(v)];
    }
  };
  std::vector<char> joined(size_t(V), 0);
  if (t.boundary_loops == 0) {
    joined[0] = 1;
    const int a = dijkstra(joined, [](int v) { return v < 0; });
    std::fill(joined.begin(), joined.end(), 0);
    joined[size_t(a)] = 1;
    const int b = dijkstra(joined, [](int v) { return v < 0; });
    if (b < 0 || b == a) return 0;
    cut_path(b, joined);
    return 1;
  }
  std::vector<std::vector<int>> loops = boundary_loops(m.local, V);
  std::stable_sort(loops.begin(), loops.end(),
                   [](const auto& x, const auto& y) { return x.size() > y.size(); });
  std::vector<int> loop_of(size_t(V), -1);
  for (size_t l = 0; l < loops.size(); ++l)
    for (int v : loops[l]) loop_of[size_t(v)] = int(l);
  for (int v : loops[0]) joined[size_t(v)] = 1;
  std::vector<char> loop_joined(loops.size(), 0);
  loop_joined[0] = 1;
  int paths = 0;
  for (size_t n = 1; n < loops.size(); ++n) {
    const int v = dijkstra(joined, [&](int w) {
      return w >= 0 && loop_of[size_t(w)] >= 0 && !loop_joined[size_t(loop_of[size_t(w)])];
    });
    if (v < 0) break;  // a loop out of reach (cannot happen in a connected chart)
    const int l = loop_of[size_t(v)];
    cut_path(v, joined);
    for (int w : loops[size_t(l)]) joined[size_t(w)] = 1;
    loop_joined[size_t(l)] = 1;
    ++paths;
  }
  return paths;
}

// A torn edge with the same chart on both sides is a slit in that chart. Where
// a slit ends inside the chart (its end vertex has no other boundary edge of
// the chart) the vertex keeps its full 3D angle around it, so any near-
// isometric flattening folds the two sides over each other there and the
// chart's boundary crosses itself. Such an edge is glued back (its faces are
// unusable under psi anyway, so the repair lays them out), and so on along the
// slit until it ends on the chart's boundary or closes a loop. Returns the
// number of edges glued.
Index close_slit_ends(const Faces& faces, const std::vector<int>& face_chart,
                      const std::vector<int>& torn_link, std::vector<int>& neighbour) {
  const int F = int(faces.rows());
  Index V = 0;
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) V = std::max<Index>(V, faces(f, k) + 1);
  // The chart's boundary half-edges at each vertex (both ends of each).
  std::vector<std::vector<int>> at(static_cast<size_t>(V));
  for (int f = 0; f < F; ++f)
    if (face_chart[size_t(f)] >= 0)
      for (int k = 0; k < 3; ++k)
        if (neighbour[size_t(3 * f + k)] < 0) {
          at[size_t(faces(f, k))].push_back(3 * f + k);
          at[size_t(faces(f, (k + 1) % 3))].push_back(3 * f + k);
        }
  auto slit_twin = [&](int h) {
    const int t = torn_link[size_t(h)];
    return t >= 0 && neighbour[size_t(h)] < 0 &&
                   face_chart[size_t(t / 3)] == face_chart[size_t(h / 3)]
               ? t
               : -1;
  };
  // v ends a slit in the chart of half-edge h when the chart's boundary
  // half-edges at v are exactly h and its twin.
  auto tip_edge = [&](int v) {
    for (int h : at[size_t(v)]) {
      const int t = slit_twin(h);
      if (t < 0) continue;
      const int chart = face_chart[size_t(h / 3)];
      int others = 0;
      for (int g : at[size_t(v)])
        if (g != h && g != t && face_chart[size_t(g / 3)] == chart) ++others;
      if (others == 0) return h;
    }
    return -1;
  };
  std::vector<int> queue;
  for (Index v = 0; v < V; ++v)
    if (!at[size_t(v)].empty()) queue.push_back(int(v));
  Index glued = 0;
  while (!queue.empty()) {
    const int v = queue.back();
    queue.pop_back();
    const int h = tip_edge(v);
    if (h < 0) continue;
    const int t = torn_link[size_t(h)];
    neighbour[size_t(h)] = t;
    neighbour[size_t(t)] = h;
    ++glued;
    for (int e : {h, t}) {
      const int f = e / 3, k = e % 3;
      for (int w : {faces(f, k), faces(f, (k + 1) % 3)}) {
        auto& list = at[size_t(w)];
        list.erase(std::remove(list.begin(), list.end(), e), list.end());
      }
    }
    // The slit's other end may now end inside the chart.
    queue.push_back(faces(h / 3, h % 3));
    queue.push_back(faces(h / 3, (h % 3 + 1) % 3));
  }
  return glued;
}

}  // namespace

CutResult cut_charts(const Block<double>& positions, const Faces& faces, const Block<double>& uv,
                     const CutOptions& o) {
  JSA_CHECK(uv.rows() == positions.rows() && uv.cols() == 2, "cut_charts: one UV per vertex");
  const int F = int(faces.rows());
  CutResult out;

  // Degenerate faces: a repeated index or no 3D area (relative to the mean).
  std::vector<double> area(size_t(F), 0);
  double total_area = 0;
  for (int f = 0; f < F; ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (a == b || b == c || a == c) continue;
    area[size_t(f)] =
        0.5 *
        (pos(positions, b) - pos(positions, a)).cross(pos(positions, c) - pos(positions, a)).norm();
    total_area += area[size_t(f)];
  }
  std::vector<char> valid(size_t(F), 0);
  for (int f = 0; f < F; ++f) {
    valid[size_t(f)] = area[size_t(f)] > 1e-12 * total_area / std::max(F, 1);
    if (!valid[size_t(f)]) out.skipped_faces.push_back(f);
  }
  if (!out.skipped_faces.empty())
    out.warnings.push_back(std::to_string(out.skipped_faces.size()) +
                           " degenerate face(s) (repeated vertex or zero area) skipped: each gets "
                           "its own collapsed UVs");

  // Glue faces along edges: group the half-edges by their unordered vertex pair.
  std::vector<std::pair<std::pair<int, int>, int>> half;  // ((min, max), 3 f + k)
  half.reserve(size_t(3 * F));
  for (int f = 0; f < F; ++f) {
    if (!valid[size_t(f)]) continue;
    for (int k = 0; k < 3; ++k) {
      const int a = faces(f, k), b = faces(f, (k + 1) % 3);
      half.push_back({{std::min(a, b), std::max(a, b)}, 3 * f + k});
    }
  }
  std::sort(half.begin(), half.end());
  std::vector<int> neighbour(size_t(3 * F), -1), torn_link(size_t(3 * F), -1);
  double uv_area = 0;
  for (int f = 0; f < F; ++f)
    if (valid[size_t(f)])
      uv_area += 0.5 * std::abs(signed_area2(uv_of(uv, faces(f, 0)), uv_of(uv, faces(f, 1)),
                                             uv_of(uv, faces(f, 2))));
  const double uv_scale = uv_area > 0 ? std::sqrt(total_area / uv_area) : 1.0;
  for (size_t i = 0; i < half.size();) {
    size_t j = i;
    while (j < half.size() && half[j].first == half[i].first) ++j;
    const size_t n = j - i;
    if (n == 1) {
      ++out.boundary_edges;
    } else if (n > 2) {
      ++out.nonmanifold_edges;
    } else {
      const int h0 = half[i].second, h1 = half[i + 1].second;
      const int a0 = faces(h0 / 3, h0 % 3), a1 = faces(h1 / 3, h1 % 3);
      if (a0 == a1) {
        ++out.inconsistent_edges;  // both faces run the edge the same way
      } else {
        const auto [a, b] = half[i].first;
        const double len3 = (pos(positions, a) - pos(positions, b)).norm();
        const double len2 = uv_scale * (uv_of(uv, a) - uv_of(uv, b)).norm();
        if (len2 > o.torn_ratio * len3) {
          ++out.torn_edges;
          torn_link[size_t(h0)] = h1;
          torn_link[size_t(h1)] = h0;
        } else {
          neighbour[size_t(h0)] = h1;
          neighbour[size_t(h1)] = h0;
        }
      }
    }
    i = j;
  }
  if (out.nonmanifold_edges > 0)
    out.warnings.push_back(std::to_string(out.nonmanifold_edges) +
                           " non-manifold edge(s) (more than two faces): cut as seams");
  if (out.inconsistent_edges > 0)
    out.warnings.push_back(std::to_string(out.inconsistent_edges) +
                           " edge(s) between inconsistently oriented faces: cut as seams");

  // Usable faces and their orientation under psi; the majority (by 3D area) is +1.
  std::vector<int> sign(size_t(F), 0);
  std::vector<char> usable(size_t(F), 0);
  double positive = 0, negative = 0;
  for (int f = 0; f < F; ++f) {
    if (!valid[size_t(f)]) continue;
    const TriangleFrame t = triangle_frame(pos(positions, faces(f, 0)), pos(positions, faces(f, 1)),
                                           pos(positions, faces(f, 2)));
    const Eigen::Matrix2d J =
        uv_scale *
        uv_jacobian(t, uv_of(uv, faces(f, 0)), uv_of(uv, faces(f, 1)), uv_of(uv, faces(f, 2)));
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-12)) continue;
    sign[size_t(f)] = det > 0 ? 1 : -1;
    (det > 0 ? positive : negative) += area[size_t(f)];
    const double energy = J.squaredNorm() + J.inverse().squaredNorm();
    usable[size_t(f)] = std::isfinite(energy) && energy < o.max_face_energy;
  }
  const int majority = positive >= negative ? 1 : -1;
  // A face with a torn edge straddles psi's cut: its UVs span the cut, never usable.
  for (size_t i = 0; i < half.size(); ++i) {
    const int h = half[i].second;
    const auto [a, b] = half[i].first;
    const double len3 = (pos(positions, a) - pos(positions, b)).norm();
    const double len2 = uv_scale * (uv_of(uv, a) - uv_of(uv, b)).norm();
    if (len2 > o.torn_ratio * len3) usable[size_t(h / 3)] = 0;
  }

  // Orientation regions: usable faces of one sign joined across glued edges.
  UnionFind regions(F);
  for (int f = 0; f < F; ++f) {
    if (!usable[size_t(f)]) continue;
    for (int k = 0; k < 3; ++k) {
      const int nb = neighbour[size_t(3 * f + k)];
      if (nb >= 0 && usable[size_t(nb / 3)] && sign[size_t(nb / 3)] == sign[size_t(f)])
        regions.unite(f, nb / 3);
    }
  }
  std::vector<double> region_area(size_t(F), 0);
  std::vector<int> region_faces(size_t(F), 0);
  for (int f = 0; f < F; ++f)
    if (usable[size_t(f)]) {
      region_area[size_t(regions.find(f))] += area[size_t(f)];
      ++region_faces[size_t(regions.find(f))];
    }
  // Cores, largest first (ties by smallest face id): each is one chart's seed.
  std::vector<int> cores;
  for (int f = 0; f < F; ++f)
    if (usable[size_t(f)] && regions.find(f) == f && region_faces[size_t(f)] >= o.min_core_faces &&
        region_area[size_t(f)] >= o.min_core_area_fraction * total_area)
      cores.push_back(f);
  std::stable_sort(cores.begin(), cores.end(),
                   [&](int a, int b) { return region_area[size_t(a)] > region_area[size_t(b)]; });
  std::vector<int> face_chart(size_t(F), -1), core_of_region(size_t(F), -1);
  for (size_t c = 0; c < cores.size(); ++c) core_of_region[size_t(cores[c])] = int(c);
  std::vector<int> chart_sign;
  std::deque<int> queue;
  for (int f = 0; f < F; ++f) {
    if (!usable[size_t(f)]) continue;
    const int c = core_of_region[size_t(regions.find(f))];
    if (c >= 0) face_chart[size_t(f)] = c;
  }
  for (size_t c = 0; c < cores.size(); ++c) chart_sign.push_back(sign[size_t(cores[c])]);
  // Multi-source growth in chart order, then face order: each other face joins
  // the core it is fewest dual steps from (ties to the larger core).
  for (int f = 0; f < F; ++f)
    if (face_chart[size_t(f)] >= 0) queue.push_back(f);
  std::vector<char> core_face(size_t(F), 0);
  for (int f = 0; f < F; ++f) core_face[size_t(f)] = face_chart[size_t(f)] >= 0;
  auto grow = [&]() {
    while (!queue.empty()) {
      const int f = queue.front();
      queue.pop_front();
      for (int k = 0; k < 3; ++k) {
        const int nb = neighbour[size_t(3 * f + k)];
        if (nb < 0) continue;
        const int g = nb / 3;
        if (face_chart[size_t(g)] >= 0 || !valid[size_t(g)]) continue;
        face_chart[size_t(g)] = face_chart[size_t(f)];
        queue.push_back(g);
      }
    }
  };
  grow();
  // Faces cut off from every core by torn edges only (psi's UVs are unusable
  // on both sides of a torn edge, so the tear says nothing there): they join
  // the chart they touch across the torn edge, glued along the edge they
  // enter by, and are laid out by the repair as an extension of that chart.
  for (int f = 0; f < F; ++f)
    if (face_chart[size_t(f)] >= 0) queue.push_back(f);
  while (!queue.empty()) {
    const int f = queue.front();
    queue.pop_front();
    for (int k = 0; k < 3; ++k) {
      const int h = 3 * f + k;
      const int nb = neighbour[size_t(h)] >= 0 ? neighbour[size_t(h)] : torn_link[size_t(h)];
      if (nb < 0) continue;
      const int g = nb / 3;
      if (face_chart[size_t(g)] >= 0 || !valid[size_t(g)]) continue;
      face_chart[size_t(g)] = face_chart[size_t(f)];
      neighbour[size_t(h)] = nb;
      neighbour[size_t(nb)] = h;
      queue.push_back(g);
    }
  }
  // Faces no core reaches (components with no usable region): charts of their own.
  for (int f = 0; f < F; ++f) {
    if (!valid[size_t(f)] || face_chart[size_t(f)] >= 0) continue;
    face_chart[size_t(f)] = int(chart_sign.size());
    chart_sign.push_back(majority);
    queue.push_back(f);
    grow();
  }
  // An edge glued inside a chart is a chart edge; edges between charts are seams.
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) {
      const int nb = neighbour[size_t(3 * f + k)];
      if (nb >= 0 && face_chart[size_t(nb / 3)] != face_chart[size_t(f)])
        neighbour[size_t(3 * f + k)] = -1;
    }
  out.slits_closed = close_slit_ends(faces, face_chart, torn_link, neighbour);

  // Charts as meshes; split those that are not disks.
  const int initial = int(chart_sign.size());
  std::vector<std::vector<int>> members(static_cast<size_t>(initial));
  for (int f = 0; f < F; ++f)
    if (face_chart[size_t(f)] >= 0) members[size_t(face_chart[size_t(f)])].push_back(f);
  struct Pending {
    std::vector<int> faces;
    int id, sign, depth;
    bool paths_tried = false;
  };
  std::vector<Pending> stack;
  for (int c = initial - 1; c >= 0; --c)
    stack.push_back({members[size_t(c)], c, chart_sign[size_t(c)], 0});
  int next_id = initial;
  std::vector<int> dist(size_t(F), -1);
  while (!stack.empty()) {
    Pending p = std::move(stack.back());
    stack.pop_back();
    ChartMesh m = build_chart_mesh(faces, p.faces, neighbour, face_chart, p.id);
    m.orientation = p.sign;
    if (chart_topology(m).is_disk()) {
      for (size_t i = 0; i < m.faces.size(); ++i) {
        const int g = m.faces[i];
        m.usable[i] = usable[size_t(g)] && sign[size_t(g)] == p.sign && core_face[size_t(g)];
      }
      out.charts.push_back(std::move(m));
      continue;
    }
    // Genus 0: one chart, cut along shortest paths between its boundary loops.
    if (!p.paths_tried) {
      const int paths = cut_along_paths(m, positions, neighbour);
      if (paths > 0) {
        out.path_cuts += paths;
        p.paths_tried = true;
        stack.push_back(std::move(p));
        continue;
      }
    }
    ++out.split_charts;
    if (p.depth >= o.max_split_depth || p.faces.size() < 2) {
      // Last resort: every face a chart of its own (a single triangle is a disk).
      for (int g : p.faces) {
        for (int k = 0; k < 3; ++k) {
          const int nb = neighbour[size_t(3 * g + k)];
          if (nb >= 0) neighbour[size_t(nb)] = -1;
          neighbour[size_t(3 * g + k)] = -1;
        }
        face_chart[size_t(g)] = next_id;
        stack.push_back({{g}, next_id++, p.sign, p.depth + 1});
      }
      continue;
    }
    // Two far-apart seeds (a double sweep of breadth-first search), then each
    // face goes to the nearer seed: two connected halves.
    for (int g : p.faces) dist[size_t(g)] = -1;
    std::vector<int> order = bfs_order(p.faces[0], neighbour, face_chart, p.id, dist);
    const int s1 = order.back();
    for (int g : p.faces) dist[size_t(g)] = -1;
    order = bfs_order(s1, neighbour, face_chart, p.id, dist);
    const int s2 = order.back();
    std::vector<int> d1(p.faces.size()), d2(p.faces.size());
    for (size_t i = 0; i < p.faces.size(); ++i) d1[i] = dist[size_t(p.faces[i])];
    for (int g : p.faces) dist[size_t(g)] = -1;
    bfs_order(s2, neighbour, face_chart, p.id, dist);
    for (size_t i = 0; i < p.faces.size(); ++i) d2[i] = dist[size_t(p.faces[i])];
    std::vector<int> a, b;
    for (size_t i = 0; i < p.faces.size(); ++i) {
      // Faces the seeds cannot reach (the chart is disconnected): their own piece.
      if (d1[i] < 0) {
        b.push_back(p.faces[i]);
        continue;
      }
      (d1[i] <= d2[i] ? a : b).push_back(p.faces[i]);
    }
    if (b.empty()) {  // one face only reachable: split off the farthest face
      b.push_back(a.back());
      a.pop_back();
    }
    const int ida = next_id++, idb = next_id++;
    for (int g : a) face_chart[size_t(g)] = ida;
    for (int g : b) face_chart[size_t(g)] = idb;
    for (int g : p.faces)
      for (int k = 0; k < 3; ++k) {
        const int nb = neighbour[size_t(3 * g + k)];
        if (nb >= 0 && face_chart[size_t(nb / 3)] != face_chart[size_t(g)]) {
          neighbour[size_t(nb)] = -1;
          neighbour[size_t(3 * g + k)] = -1;
        }
      }
    stack.push_back({b, idb, p.sign, p.depth + 1});
    stack.push_back({a, ida, p.sign, p.depth + 1});
  }
  for (int f = 0; f < F; ++f) out.unusable_faces += valid[size_t(f)] && !usable[size_t(f)];
  return out;
}

}  // namespace jsa

namespace jsa {

std::vector<ChartMesh> split_chart(const ChartMesh& m, const Block<double>* positions,
                                   const Block<double>* uv) {
  const int n = int(m.faces.size());
  if (n < 2) return {};
  // Local adjacency: half-edges glued when the chart has the twin b -> a.
  std::vector<std::pair<std::pair<int, int>, int>> half;
  for (int f = 0; f < n; ++f)
    for (int k = 0; k < 3; ++k)
      half.push_back({{m.local(f, k), m.local(f, (k + 1) % 3)}, 3 * f + k});
  std::sort(half.begin(), half.end());
  std::vector<int> neighbour(size_t(3 * n), -1);
  for (const auto& [edge, h] : half) {
    auto it = std::lower_bound(half.begin(), half.end(),
                               std::make_pair(std::make_pair(edge.second, edge.first), -1));
    if (it != half.end() && it->first == std::make_pair(edge.second, edge.first))
      neighbour[size_t(h)] = it->second;
  }
  std::vector<int> side(static_cast<size_t>(n));
  if (positions) {
    // Distances between face centroids along the dual graph (Dijkstra): the
    // border between the halves follows the surface, not the mesh's rows, so
    // the seam is shorter and straighter than a breadth-first one.
    std::vector<Eigen::Vector3d> centre(static_cast<size_t>(n));
    for (int f = 0; f < n; ++f) {
      centre[size_t(f)].setZero();
      for (int k = 0; k < 3; ++k)
        centre[size_t(f)] += pos(*positions, m.vertex[size_t(m.local(f, k))]);
      centre[size_t(f)] /= 3;
    }
    std::vector<double> dist(static_cast<size_t>(n));
    auto sweep = [&](int seed) {
      std::fill(dist.begin(), dist.end(), std::numeric_limits<double>::infinity());
      using Item = std::pair<double, int>;
      std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
      dist[size_t(seed)] = 0;
      heap.push({0.0, seed});
      int last = seed;
      while (!heap.empty()) {
        const auto [d, f] = heap.top();
        heap.pop();
        if (d > dist[size_t(f)]) continue;
        last = f;
        for (int k = 0; k < 3; ++k) {
          const int nb = neighbour[size_t(3 * f + k)];
          if (nb < 0) continue;
          const int g = nb / 3;
          const double w = d + (centre[size_t(f)] - centre[size_t(g)]).norm();
          if (w < dist[size_t(g)]) dist[size_t(g)] = w, heap.push({w, g});
        }
      }
      return last;
    };
    const int s1 = sweep(0);
    const int s2 = sweep(s1);
    const std::vector<double> d1 = dist;
    sweep(s2);
    for (int f = 0; f < n; ++f)
      side[size_t(f)] = std::isfinite(d1[size_t(f)]) && d1[size_t(f)] <= dist[size_t(f)] ? 1 : 0;
  } else {
    std::vector<int> chart_of(size_t(n), 0), dist(size_t(n), -1);
    auto sweep = [&](int seed) {
      std::fill(dist.begin(), dist.end(), -1);
      return bfs_order(seed, neighbour, chart_of, 0, dist);
    };
    const int s1 = sweep(0).back();
    const std::vector<int> d1 = (sweep(s1), dist);
    const int s2 = sweep(s1).back();
    const std::vector<int> d2 = (sweep(s2), dist);
    for (int f = 0; f < n; ++f)
      side[size_t(f)] = d1[size_t(f)] >= 0 && d1[size_t(f)] <= d2[size_t(f)] ? 0 : 1;
  }
  // Sub-charts in the local numbering, then mapped back to input ids.
  Faces as_faces = m.local;
  std::vector<ChartMesh> out;
  for (int s = 0; s < 2; ++s) {
    std::vector<int> members;
    for (int f = 0; f < n; ++f)
      if (side[size_t(f)] == s) members.push_back(f);
    if (members.empty()) return {};
    std::vector<int> glued = neighbour;
    for (int f = 0; f < n; ++f)
      for (int k = 0; k < 3; ++k) {
        const int nb = glued[size_t(3 * f + k)];
        if (nb >= 0 && side[size_t(nb / 3)] != side[size_t(f)]) glued[size_t(3 * f + k)] = -1;
      }
    // build_chart_mesh reads edge l of the neighbour as running b -> a, as here.
    ChartMesh sub = build_chart_mesh(as_faces, members, glued, side, s);
    if (!chart_topology(sub).is_disk() && positions) {
      // A half of a chart that was made a disk by cuts (slits joined by paths)
      // can cut a path in two and keep a hole: join its loops by paths too.
      Block<double> local_positions(Index(m.vertex.size()), 3);
      for (size_t v = 0; v < m.vertex.size(); ++v)
        local_positions.row(Index(v)) = positions->row(m.vertex[v]);
      if (cut_along_paths(sub, local_positions, glued) > 0)
        sub = build_chart_mesh(as_faces, members, glued, side, s);
    }
    if (!chart_topology(sub).is_disk()) return {};
    for (size_t i = 0; i < sub.faces.size(); ++i) {
      const int f = sub.faces[i];
      sub.usable[i] = m.usable[size_t(f)];
      sub.faces[i] = m.faces[size_t(f)];
    }
    if (uv) {
      sub.inherited_uv.resize(Index(sub.vertex.size()), 2);
      for (size_t v = 0; v < sub.vertex.size(); ++v)
        sub.inherited_uv.row(Index(v)) = uv->row(sub.vertex[v]);
    }
    for (int& v : sub.vertex) v = m.vertex[size_t(v)];
    sub.orientation = m.orientation;
    out.push_back(std::move(sub));
  }
  return out;
}

}  // namespace jsa
