#include "io/geometry/uv_pack.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "engine/check.h"

namespace jsa {
namespace {

struct Box {
  double w = 0, h = 0;
};

// Shelf placement at scale s: lower-left corners, or false if it does not fit.
bool shelf(const std::vector<Box>& box, const std::vector<int>& order, double s, double p,
           std::vector<Eigen::RowVector2d>& corner) {
  double x = p, y = p, shelf_h = 0;
  for (int i : order) {
    const double W = s * box[size_t(i)].w, H = s * box[size_t(i)].h;
    if (W + 2 * p > 1) return false;
    if (x + W + p > 1) {
      y += shelf_h + p;
      x = p;
      shelf_h = 0;
    }
    corner[size_t(i)] << x, y;
    x += W + p;
    shelf_h = std::max(shelf_h, H);
  }
  return y + shelf_h + p <= 1;
}

}  // namespace

PackResult pack_charts(std::vector<Block<double>>& charts, const std::vector<double>& area,
                       const PackOptions& o) {
  JSA_CHECK(charts.size() == area.size(), "pack_charts: one area per chart");
  JSA_CHECK(o.texture_size > 0 && o.padding >= 0, "pack_charts: texture_size > 0, padding >= 0");
  PackResult r;
  const size_t n = charts.size();
  if (n == 0) return r;
  // Principal axis horizontal, then the box's lower-left corner at the origin.
  std::vector<Box> box(n);
  for (size_t i = 0; i < n; ++i) {
    Block<double>& c = charts[i];
    if (c.rows() == 0) continue;
    const Eigen::RowVector2d mean = c.colwise().mean();
    Block<double> centred = c.rowwise() - mean;
    const Eigen::Matrix2d cov = centred.transpose() * centred;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
    Eigen::Vector2d axis = eig.eigenvectors().col(1);  // largest eigenvalue
    if (!axis.allFinite() || axis.norm() == 0) axis = Eigen::Vector2d(1, 0);
    Eigen::Matrix2d R;  // rotates axis onto +x: a proper rotation
    R << axis.x(), axis.y(), -axis.y(), axis.x();
    c = centred * R.transpose();
    const Eigen::RowVector2d lo = c.colwise().minCoeff(), hi = c.colwise().maxCoeff();
    c = c.rowwise() - lo;
    box[i] = {hi(0) - lo(0), hi(1) - lo(1)};
  }
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return box[size_t(a)].h > box[size_t(b)].h; });
  double largest = 0, box_area = 0;
  for (const Box& b : box) largest = std::max({largest, b.w, b.h}), box_area += b.w * b.h;
  std::vector<Eigen::RowVector2d> corner(n);
  double padding = o.padding;
  double best = 0;
  for (int attempt = 0; attempt < 40; ++attempt) {
    const double p = padding / o.texture_size;
    // Scale bounds: nothing fits above (1 - 2p) / largest nor above the area bound.
    double hi = largest > 0 ? (1 - 2 * p) / largest : 1;
    if (box_area > 0) hi = std::min(hi, 1 / std::sqrt(box_area));
    double lo = 0;
    if (hi > 0 && shelf(box, order, hi, p, corner)) lo = hi;
    for (int it = 0; it < 60 && lo < hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (hi - lo <= 1e-12 * hi) break;
      (shelf(box, order, mid, p, corner) ? lo : hi) = mid;
    }
    if (lo > 0 && shelf(box, order, lo, p, corner)) {
      best = lo;
      break;
    }
    padding *= 0.5;
    if (padding < 1e-3) padding = 0;
  }
  JSA_CHECK(best > 0, "pack_charts: no scale fits");
  if (padding < o.padding)
    r.warnings.push_back(std::to_string(n) + " charts do not fit with " +
                         std::to_string(o.padding) + " texels of padding at " +
                         std::to_string(o.texture_size) + " texels; used " +
                         std::to_string(padding));
  double used = 0;
  for (size_t i = 0; i < n; ++i) {
    charts[i] = (best * charts[i]).rowwise() + corner[i];
    used += best * best * area[i];
  }
  r.scale = best;
  r.efficiency = used;
  r.padding = padding;
  return r;
}

}  // namespace jsa
