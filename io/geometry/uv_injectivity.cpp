#include "io/geometry/uv_injectivity.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "io/geometry/triangle_frame.h"
#include "io/geometry/uv_cut.h"

namespace jsa {
namespace {

Eigen::Vector2d at(const Block<double>& uv, int v) { return uv.row(v).transpose(); }

double orient(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return signed_area2(a, b, c);
}

bool on_segment(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) &&
         std::min(a.y(), b.y()) <= p.y() && p.y() <= std::max(a.y(), b.y());
}

// Closed segments [a, b] and [c, d] share a point (exact predicates on doubles).
bool segments_meet(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c,
                   const Eigen::Vector2d& d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
               o4 = orient(c, d, b);
  if (((o1 > 0 && o2 < 0) || (o1 < 0 && o2 > 0)) && ((o3 > 0 && o4 < 0) || (o3 < 0 && o4 > 0)))
    return true;
  if (o1 == 0 && on_segment(a, b, c)) return true;
  if (o2 == 0 && on_segment(a, b, d)) return true;
  if (o3 == 0 && on_segment(c, d, a)) return true;
  if (o4 == 0 && on_segment(c, d, b)) return true;
  return false;
}

}  // namespace

Index count_inverted(const Faces& local, const Block<double>& uv, double min_area2) {
  Index n = 0;
  for (Index f = 0; f < local.rows(); ++f)
    n += !(signed_area2(at(uv, local(f, 0)), at(uv, local(f, 1)), at(uv, local(f, 2))) > min_area2);
  return n;
}

bool boundary_self_intersects(const Faces& local, const Block<double>& uv) {
  return boundary_self_intersects(boundary_loops(local, uv.rows()), uv);
}

bool boundary_self_intersects(const std::vector<std::vector<int>>& loops, const Block<double>& uv) {
  std::vector<std::pair<int, int>> seg;
  for (const auto& loop : loops)
    for (size_t i = 0; i < loop.size(); ++i) seg.push_back({loop[i], loop[(i + 1) % loop.size()]});
  if (seg.size() < 4) return false;
  Eigen::Vector2d lo = at(uv, seg[0].first), hi = lo;
  double mean_len = 0;
  for (const auto& [a, b] : seg) {
    lo = lo.cwiseMin(at(uv, a)), hi = hi.cwiseMax(at(uv, a));
    mean_len += (at(uv, a) - at(uv, b)).norm();
  }
  mean_len /= double(seg.size());
  // Cells about one mean segment long, at most ~4 cells per segment overall.
  const double extent = std::max(hi.x() - lo.x(), hi.y() - lo.y());
  const double cell = std::max({mean_len, extent / std::sqrt(4.0 * double(seg.size())), 1e-300});
  const long long nx = std::max(1LL, (long long)((hi.x() - lo.x()) / cell) + 1);
  std::unordered_map<long long, std::vector<int>> grid;
  auto cell_of = [&](double x, double y) {
    return std::pair<long long, long long>{(long long)((x - lo.x()) / cell),
                                           (long long)((y - lo.y()) / cell)};
  };
  for (size_t s = 0; s < seg.size(); ++s) {
    const Eigen::Vector2d a = at(uv, seg[s].first), b = at(uv, seg[s].second);
    const auto [x0, y0] = cell_of(std::min(a.x(), b.x()), std::min(a.y(), b.y()));
    const auto [x1, y1] = cell_of(std::max(a.x(), b.x()), std::max(a.y(), b.y()));
    for (long long x = x0; x <= x1; ++x)
      for (long long y = y0; y <= y1; ++y) grid[y * nx + x].push_back(int(s));
  }
  // Visit cells in key order so that the answer does not depend on hashing.
  std::vector<long long> keys;
  keys.reserve(grid.size());
  for (const auto& kv : grid) keys.push_back(kv.first);
  std::sort(keys.begin(), keys.end());
  for (long long key : keys) {
    const std::vector<int>& in = grid[key];
    for (size_t i = 0; i < in.size(); ++i)
      for (size_t j = i + 1; j < in.size(); ++j) {
        const auto [a, b] = seg[size_t(in[i])];
        const auto [c, d] = seg[size_t(in[j])];
        if (a == c || a == d || b == c || b == d) continue;
        if (segments_meet(at(uv, a), at(uv, b), at(uv, c), at(uv, d))) return true;
      }
  }
  return false;
}

}  // namespace jsa
