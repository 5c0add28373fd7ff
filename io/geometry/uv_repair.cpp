#include "io/geometry/uv_repair.h"

#include <cmath>
#include <limits>
#include <queue>

#include "io/geometry/sparse_spd.h"
#include "io/geometry/triangle_frame.h"
#include "io/geometry/uv_injectivity.h"
#include "io/geometry/uv_tutte.h"

namespace jsa {

// Round k >= 1 of the repair frees every vertex within kRepairRadius 2^(k-1)
// sqrt(chart area) of an unusable face.
constexpr double kRepairRadius = 0.05;

const char* to_string(ChartStart s) {
  switch (s) {
    case ChartStart::psi:
      return "psi";
    case ChartStart::repaired:
      return "repaired";
    case ChartStart::lscm:
      return "lscm";
    case ChartStart::inherited:
      return "inherited";
    case ChartStart::tutte:
      return "tutte";
    default:
      return "failed";
  }
}

bool lscm_fill(const Block<double>& positions, const Faces& local, const std::vector<char>& free,
               Block<double>& uv) {
  const Index V = positions.rows();
  std::vector<int> slot(size_t(V), -1);
  int n = 0;
  for (Index v = 0; v < V; ++v)
    if (free[size_t(v)]) slot[size_t(v)] = n++;
  if (n == 0) return true;
  // Conformality on each triangle (frame x, y): u_x = v_y and u_y = -v_x, as two
  // residual rows weighted by sqrt(area); unknowns u at 2 slot, v at 2 slot + 1.
  std::vector<Eigen::Triplet<double>> trip;
  trip.reserve(size_t(36 * std::min<Index>(local.rows(), 6 * Index(n))));
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(2 * n);
  for (Index f = 0; f < local.rows(); ++f) {
    bool touches = false;
    for (int k = 0; k < 3; ++k) touches |= free[size_t(local(f, k))] != 0;
    if (!touches) continue;
    const TriangleFrame t = triangle_frame(positions.row(local(f, 0)).transpose(),
                                           positions.row(local(f, 1)).transpose(),
                                           positions.row(local(f, 2)).transpose());
    if (!(t.area > 0)) continue;
    // Both rows summed into the face's 6 x 6 block first: half the triplets.
    int var[6];
    Eigen::Matrix<double, 6, 6> block = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> load = Eigen::Matrix<double, 6, 1>::Zero();
    for (int r = 0; r < 2; ++r) {
      Eigen::Matrix<double, 6, 1> coef;
      double fixed_part = 0;
      for (int k = 0; k < 3; ++k) {
        const int v = local(f, k);
        const double cu = r == 0 ? t.grad(0, k) : t.grad(1, k);
        const double cv = r == 0 ? -t.grad(1, k) : t.grad(0, k);
        coef(2 * k) = cu, coef(2 * k + 1) = cv;
        if (slot[size_t(v)] >= 0) {
          var[2 * k] = 2 * slot[size_t(v)], var[2 * k + 1] = 2 * slot[size_t(v)] + 1;
        } else {
          var[2 * k] = var[2 * k + 1] = -1;
          fixed_part += cu * uv(v, 0) + cv * uv(v, 1);
        }
      }
      block += t.area * coef * coef.transpose();
      load -= t.area * fixed_part * coef;
    }
    for (int i = 0; i < 6; ++i) {
      if (var[i] < 0) continue;
      rhs(var[i]) += load(i);
      for (int j = 0; j < 6; ++j)
        if (var[j] >= 0) trip.push_back({var[i], var[j], block(i, j)});
    }
  }
  Eigen::SparseMatrix<double> H(2 * n, 2 * n);
  H.setFromTriplets(trip.begin(), trip.end());
  std::vector<Eigen::Triplet<double>>().swap(trip);
  SpdSolver solver;
  if (!solver.compute(H)) return false;
  const Eigen::VectorXd x = solver.solve(rhs);
  if (!x.allFinite()) return false;
  // A singular system can still factor with tiny pivots: check the residual.
  if ((H * x - rhs).norm() > 1e-6 * std::max(1.0, rhs.norm())) return false;
  for (Index v = 0; v < V; ++v)
    if (slot[size_t(v)] >= 0) uv.row(v) << x(2 * slot[size_t(v)]), x(2 * slot[size_t(v)] + 1);
  return true;
}

namespace {

// Surface distance (3D edge lengths along the chart's edges, Dijkstra) from
// the vertices with seed[v] set; +inf where no seed is reached.
std::vector<double> distance_from(const Block<double>& positions, const Faces& local,
                                  const std::vector<char>& seed) {
  const Index V = positions.rows();
  std::vector<std::vector<std::pair<int, double>>> arcs(static_cast<size_t>(V));
  for (Index f = 0; f < local.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = local(f, k), b = local(f, (k + 1) % 3);
      const double len = (positions.row(a) - positions.row(b)).norm();
      arcs[size_t(a)].push_back({b, len});
      arcs[size_t(b)].push_back({a, len});
    }
  std::vector<double> dist(static_cast<size_t>(V), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> heap;
  for (Index v = 0; v < V; ++v)
    if (seed[size_t(v)]) dist[size_t(v)] = 0, heap.push({0.0, int(v)});
  while (!heap.empty()) {
    const auto [d, v] = heap.top();
    heap.pop();
    if (d > dist[size_t(v)]) continue;
    for (const auto& [w, len] : arcs[size_t(v)])
      if (d + len < dist[size_t(w)]) dist[size_t(w)] = d + len, heap.push({d + len, w});
  }
  return dist;
}

// LSCM with a free boundary: two far-apart vertices pinned (at psi's UVs when
// they are finite and distinct, so the result lands near psi's placement).
bool lscm_free_boundary(const Block<double>& positions, const Faces& local,
                        const Block<double>& psi, Block<double>& uv) {
  const Index V = positions.rows();
  if (V < 3) return false;
  auto farthest = [&](Index from) {
    Index best = from;
    double d = -1;
    for (Index v = 0; v < V; ++v) {
      const double x = (positions.row(v) - positions.row(from)).squaredNorm();
      if (x > d) d = x, best = v;
    }
    return best;
  };
  const Index a = farthest(0), b = farthest(a);
  if (a == b) return false;
  uv = Block<double>::Zero(V, 2);
  const bool psi_pins =
      psi.row(a).allFinite() && psi.row(b).allFinite() && (psi.row(a) - psi.row(b)).norm() > 0;
  if (psi_pins) {
    uv.row(a) = psi.row(a), uv.row(b) = psi.row(b);
  } else {
    uv.row(b) << (positions.row(a) - positions.row(b)).norm(), 0;
  }
  std::vector<char> free(size_t(V), 1);
  free[size_t(a)] = free[size_t(b)] = 0;
  return lscm_fill(positions, local, free, uv);
}

}  // namespace

ChartStartResult start_chart_uv(const Block<double>& positions, const Faces& local,
                                const Block<double>& psi, const std::vector<char>& usable,
                                int max_rings, bool tutte) {
  ChartStartResult r;
  const Index V = positions.rows();
  bool all_usable = true;
  for (char u : usable) all_usable &= u != 0;
  if (all_usable && psi.allFinite() && chart_is_injective(local, psi)) {
    r.uv = psi;
    r.start = ChartStart::psi;
    return r;
  }
  // Free: the vertices of unusable faces, grown each round by a ring and by a
  // surface distance (a share of the chart's size), whichever frees more: rings
  // alone shrink with the triangles, so on a fine mesh they would free too
  // little around the same fold of psi.
  std::vector<char> unusable_vertex(size_t(V), 0);
  for (Index f = 0; f < local.rows(); ++f)
    if (!usable[size_t(f)])
      for (int k = 0; k < 3; ++k) unusable_vertex[size_t(local(f, k))] = 1;
  std::vector<char> free = unusable_vertex;
  double area = 0;
  for (Index f = 0; f < local.rows(); ++f) {
    const Eigen::Vector3d p0 = positions.row(local(f, 0)).transpose(),
                          p1 = positions.row(local(f, 1)).transpose(),
                          p2 = positions.row(local(f, 2)).transpose();
    area += 0.5 * (p1 - p0).cross(p2 - p0).norm();
  }
  std::vector<double> dist;
  Index last_inverted = std::numeric_limits<Index>::max();
  for (int ring = 0; ring <= max_rings; ++ring) {
    Index fixed = 0;
    for (char c : free) fixed += c == 0;
    if (fixed < 2) break;
    if (ring > 0) {
      std::vector<char> grown = free;
      for (Index f = 0; f < local.rows(); ++f) {
        bool any = false;
        for (int k = 0; k < 3; ++k) any |= free[size_t(local(f, k))] != 0;
        if (any)
          for (int k = 0; k < 3; ++k) grown[size_t(local(f, k))] = 1;
      }
      if (dist.empty()) dist = distance_from(positions, local, unusable_vertex);
      const double radius = kRepairRadius * std::ldexp(1.0, ring - 1) * std::sqrt(area);
      for (Index v = 0; v < V; ++v)
        if (dist[size_t(v)] <= radius) grown[size_t(v)] = 1;
      free.swap(grown);
      Index still = 0;
      for (char c : free) still += c == 0;
      // Once most of the chart is free little of psi's layout is left to keep:
      // the chart's own conformal map below does as well, at one solve.
      if (still < 2 || still < V / 2) break;
    }
    bool any_free = false;
    for (char c : free) any_free |= c != 0;
    if (!any_free) break;  // psi's UVs are usable everywhere but overlap: nothing local to repair
    Block<double> uv = psi;
    const bool ok = lscm_fill(positions, local, free, uv);
    if (ok && uv.allFinite() && chart_is_injective(local, uv)) {
      r.uv = std::move(uv);
      r.start = ChartStart::repaired;
      r.rings = ring;
      return r;
    }
    // A wider repair that leaves no fewer triangles inverted is not converging
    // on psi's layout (psi overlaps itself across the chart): stop growing.
    const Index inverted = ok ? count_inverted(local, uv) : V;
    if (inverted >= last_inverted) break;
    last_inverted = inverted;
  }
  // Nothing of psi's worth keeping locally: the chart's own conformal map
  // (free boundary), placed by the caller's alignment onto psi.
  {
    Block<double> uv;
    if (lscm_free_boundary(positions, local, psi, uv) && uv.allFinite() &&
        chart_is_injective(local, uv)) {
      r.uv = std::move(uv);
      r.start = ChartStart::lscm;
      return r;
    }
  }
  if (!tutte) return r;  // failed, without Tutte's embedding
  Block<double> uv = tutte_embedding(positions, local);
  if (uv.allFinite() && chart_is_injective(local, uv)) {
    r.uv = std::move(uv);
    r.start = ChartStart::tutte;
    return r;
  }
  r.uv = std::move(uv);
  r.start = ChartStart::failed;
  return r;
}

}  // namespace jsa
