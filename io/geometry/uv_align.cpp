#include "io/geometry/uv_align.h"

#include <cmath>

#include "engine/check.h"

namespace jsa {

Similarity2 fit_similarity(const Block<double>& from, const Block<double>& to,
                           const std::vector<double>& w, double min_scale, double max_scale) {
  JSA_CHECK(from.rows() == to.rows() && from.cols() == 2 && to.cols() == 2,
            "fit_similarity: N x 2 and N x 2");
  const Index n = from.rows();
  auto weight = [&](Index i) { return w.empty() ? 1.0 : w[size_t(i)]; };
  double W = 0;
  Eigen::RowVector2d cf = Eigen::RowVector2d::Zero(), ct = Eigen::RowVector2d::Zero();
  // Points of weight 0 are left out entirely (their coordinates may be NaN).
  for (Index i = 0; i < n; ++i) {
    if (!(weight(i) > 0)) continue;
    W += weight(i);
    cf += weight(i) * from.row(i);
    ct += weight(i) * to.row(i);
  }
  Similarity2 s;
  if (!(W > 0)) return s;
  cf /= W, ct /= W;
  // In complex numbers: minimise sum w |z to_i - (a + ib) z from_i|^2 over
  // a + ib = scale e^{i theta}: a + ib = sum w conj(x) y / sum w |x|^2.
  double dot = 0, cross = 0, norm = 0;
  for (Index i = 0; i < n; ++i) {
    if (!(weight(i) > 0)) continue;
    const Eigen::RowVector2d x = from.row(i) - cf, y = to.row(i) - ct;
    dot += weight(i) * x.dot(y);
    cross += weight(i) * (x(0) * y(1) - x(1) * y(0));
    norm += weight(i) * x.squaredNorm();
  }
  if (norm > 0 && (dot != 0 || cross != 0)) {
    const double r = std::hypot(dot, cross);
    s.scale = r / norm;
    s.rotation << dot / r, -cross / r, cross / r, dot / r;
  }
  // Clamped, the scale no longer minimises the sum; the rotation and the
  // centroids still do, for any fixed scale.
  s.scale = std::min(std::max(s.scale, min_scale), max_scale);
  s.translation = ct - s.scale * cf * s.rotation.transpose();
  return s;
}

}  // namespace jsa
