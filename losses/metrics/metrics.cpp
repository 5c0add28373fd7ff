#include "losses/metrics/metrics.h"

#include <cmath>
#include <vector>

#include "engine/check.h"
#include "io/geometry/nearest.h"

namespace jsa {
namespace {

// Mean distance and mean normal distance from each row of a to its nearest row of b.
void one_way(const Block<double>& ap, const Block<double>& an, const Block<double>& bp,
             const Block<double>& bn, double& spatial, double& normal, double& back) {
  std::vector<int> nn;
  std::vector<double> d2;
  nearest(ap, bp, nn, &d2);
  spatial = normal = back = 0;
  for (Index i = 0; i < ap.rows(); ++i) {
    spatial += std::sqrt(d2[i]);
    normal += (an.row(i) - bn.row(nn[i])).norm();
    back += an.row(i).dot(bn.row(nn[i])) < 0 ? 1 : 0;
  }
  spatial /= double(ap.rows());
  normal /= double(ap.rows());
  back /= double(ap.rows());
}

}  // namespace

SurfaceMetrics surface_metrics(const Block<double>& pp, const Block<double>& pn,
                               const Block<double>& tp, const Block<double>& tn) {
  JSA_CHECK(pp.rows() > 0 && tp.rows() > 0 && pp.rows() == pn.rows() && tp.rows() == tn.rows(),
            "surface_metrics needs non-empty oriented point sets");
  double s1, n1, b1, s2, n2, b2;
  one_way(pp, pn, tp, tn, s1, n1, b1);
  one_way(tp, tn, pp, pn, s2, n2, b2);
  return {0.5 * (s1 + s2), 0.5 * (n1 + n2), 0.5 * (b1 + b2)};
}

}  // namespace jsa
