#include "losses/metrics/emd.h"

#include <chrono>
#include <cmath>
#include <string>

#include "engine/check.h"
#include "engine/parallel.h"
#include "losses/metrics/assignment.h"

namespace jsa {
namespace {

void require_oriented_points(const Block<double>& points, const Block<double>& normals,
                             const char* what) {
  if (normals.rows() != points.rows() || normals.cols() != points.cols())
    throw InputError(std::string("EMD: ") + what + " has " + std::to_string(points.rows()) + " x " +
                     std::to_string(points.cols()) + " points but " +
                     std::to_string(normals.rows()) + " x " + std::to_string(normals.cols()) +
                     " normals; give one normal per point");
  if (!points.allFinite() || !normals.allFinite())
    throw InputError(std::string("EMD: ") + what +
                     " has a non-finite coordinate; remove NaN/inf points first");
}

}  // namespace

Block<double> squared_distance_costs(const Block<double>& a, const Block<double>& b) {
  JSA_CHECK(a.cols() == b.cols(), "point sets of different dimension");
  const Index m = a.rows(), n = b.rows(), c = a.cols();
  Block<double> out(m, n);
  parallel_rows(
      m,
      [&](Index begin, Index end) {
        for (Index i = begin; i < end; ++i) {
          const double* x = a.data() + i * c;
          double* row = out.data() + i * n;
          if (c == 3) {  // the common case, unrolled
            for (Index j = 0; j < n; ++j) {
              const double* y = b.data() + j * 3;
              const double d0 = x[0] - y[0], d1 = x[1] - y[1], d2 = x[2] - y[2];
              row[j] = d0 * d0 + d1 * d1 + d2 * d2;
            }
          } else {
            for (Index j = 0; j < n; ++j) {
              const double* y = b.data() + j * c;
              double s = 0;
              for (Index d = 0; d < c; ++d) s += (x[d] - y[d]) * (x[d] - y[d]);
              row[j] = s;
            }
          }
        }
      },
      64);
  return out;
}

EmdMetrics emd_metrics(const Block<double>& pred_points, const Block<double>& pred_normals,
                       const Block<double>& true_points, const Block<double>& true_normals,
                       std::vector<int>* association) {
  const auto t0 = std::chrono::steady_clock::now();
  if (pred_points.rows() != true_points.rows())
    throw InputError("EMD needs the same number of points on both sides: prediction has " +
                     std::to_string(pred_points.rows()) + ", ground truth has " +
                     std::to_string(true_points.rows()) + "; sample M' points from each");
  if (pred_points.rows() == 0) throw InputError("EMD: both point sets are empty");
  if (pred_points.cols() != true_points.cols())
    throw InputError("EMD: prediction has " + std::to_string(pred_points.cols()) +
                     " coordinates per point, ground truth " + std::to_string(true_points.cols()));
  require_oriented_points(pred_points, pred_normals, "prediction");
  require_oriented_points(true_points, true_normals, "ground truth");

  const Assignment sigma = assign_lapjv(squared_distance_costs(pred_points, true_points));

  // Sums in row order: deterministic.
  EmdMetrics out;
  const Index m = pred_points.rows();
  for (Index i = 0; i < m; ++i) {
    const int j = sigma.column_of_row[i];
    const double d2 = (pred_points.row(i) - true_points.row(j)).squaredNorm();
    out.spatial += std::sqrt(d2);
    out.spatial_squared += d2;
    out.normal += (pred_normals.row(i) - true_normals.row(j)).norm();
  }
  out.spatial /= double(m);
  out.spatial_squared /= double(m);
  out.normal /= double(m);
  if (association) *association = sigma.column_of_row;
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace jsa
