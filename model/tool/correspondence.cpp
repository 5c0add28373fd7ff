#include "model/tool/correspondence.h"

#include <limits>

#include "io/geometry/nearest.h"
#include "io/geometry/vertex_normals.h"
#include "model/tool/chart_mesh.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/evaluate.h"

namespace jsa {

Block<double> vertex_normals_of(const Mesh& mesh) {
  if (mesh.has_normals()) return mesh.normals.rowwise().normalized();
  return area_weighted_vertex_normals(mesh.vertices, mesh.faces);
}

namespace {

// Minimises |phi_I(u) - p|^2 over u from the start uv: Levenberg-Marquardt per
// point, (J^T J + lambda diag(J^T J)) du = J^T (p - phi(u)); a step that does not
// lower the residual is undone and lambda grows tenfold, else lambda shrinks.
void refine_inverse(Atlas<float>& atlas, int shape, const Block<double>& p, int steps,
                    Block<double>& uv) {
  const Index n = p.rows();
  std::vector<double> lambda(size_t(n), 1e-3),
      best(size_t(n), std::numeric_limits<double>::infinity());
  Block<double> best_uv = uv, q, normals, du, dv;
  for (int k = 0; k <= steps; ++k) {
    evaluate_surface(atlas, uv, q, normals, shape, &du, &dv);  // phi_I(u) and its Jacobian
    for (Index i = 0; i < n; ++i) {
      const Eigen::RowVector3d r = p.row(i) - q.row(i);
      const double e = r.squaredNorm();
      if (e <= best[size_t(i)]) {
        best[size_t(i)] = e;
        best_uv.row(i) = uv.row(i);
        lambda[size_t(i)] = std::max(1e-6, lambda[size_t(i)] * 0.3);
      } else {
        lambda[size_t(i)] *= 10;
        uv.row(i) = best_uv.row(i);
        continue;  // the Jacobian below belongs to the rejected point: step again next round
      }
      if (k == steps) continue;
      const double a = du.row(i).squaredNorm(), b = du.row(i).dot(dv.row(i)),
                   c = dv.row(i).squaredNorm();
      const double l = lambda[size_t(i)];
      const double a2 = a * (1 + l), c2 = c * (1 + l), det = a2 * c2 - b * b;
      if (!(det > 0)) continue;
      const double gu = du.row(i).dot(r), gv = dv.row(i).dot(r);
      uv(i, 0) += (c2 * gu - b * gv) / det;
      uv(i, 1) += (a2 * gv - b * gu) / det;
    }
  }
  uv = best_uv;
}

}  // namespace

Block<double> correspond(Atlas<float>& atlas, int from, int to, const Block<double>& p_unit,
                         const Block<double>& normals, const CorrespondenceOptions& o) {
  Block<double> uv;
  if (o.use_chart) {
    // x = psi_I([p, alpha n])
    Block<double> x6(p_unit.rows(), 6);
    x6.leftCols(3) = p_unit;
    x6.rightCols(3) = atlas.options().alpha * normals.rowwise().normalized();
    uv = chart_points(atlas, x6, from);
    if (o.refine_steps > 0) refine_inverse(atlas, from, p_unit, o.refine_steps, uv);
  } else {
    // The nearest-sample rule: argmin over samples x ~ P of |phi_I(x) - p|.
    Rng rng(o.seed, 20);
    Block<double> samples, points, sample_normals;
    sample_reconstruction(atlas, o.nearest_samples, rng, samples, points, sample_normals, from);
    std::vector<int> nn;
    nearest(p_unit, points, nn);
    uv.resize(p_unit.rows(), 2);
    for (Index i = 0; i < p_unit.rows(); ++i) uv.row(i) = samples.row(nn[size_t(i)]);
  }
  Block<double> q, qn;
  evaluate_surface(atlas, uv, q, qn, to);  // q = phi_J(x)
  return q;
}

KeypointError keypoint_error(Atlas<float>& atlas, const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames,
                             const std::vector<std::vector<int>>& keypoints,
                             const CorrespondenceOptions& o,
                             const std::vector<double>& thresholds) {
  const CorrespondenceMap map = [&](int from, int to, const Block<double>& p,
                                    const Block<double>& n) {
    return correspond(atlas, from, to, p, n, o);
  };
  return keypoint_error(map, meshes, frames, keypoints, thresholds);
}

KeypointError keypoint_error(const CorrespondenceMap& map, const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames,
                             const std::vector<std::vector<int>>& keypoints,
                             const std::vector<double>& thresholds) {
  const size_t n = meshes.size();
  JSA_CHECK(frames.size() == n && keypoints.size() == n,
            "one mesh, frame and keypoint list per shape");
  const size_t k = keypoints[0].size();
  for (size_t i = 0; i < n; ++i)
    if (keypoints[i].size() != k)
      throw InputError("keypoint files differ in length: shape 0 has " + std::to_string(k) +
                       ", shape " + std::to_string(i) + " has " +
                       std::to_string(keypoints[i].size()));
  KeypointError e;
  e.thresholds = thresholds;
  e.within.assign(thresholds.size(), 0.0);
  e.pair_mean.assign(n, std::vector<double>(n, 0.0));
  e.keypoint_mean.assign(k, 0.0);
  e.keypoint_self.assign(k, 0.0);
  double total = 0, total_squared = 0;
  for (size_t i = 0; i < n; ++i) {
    const Block<double> unit = frames[i].to_unit(meshes[i].vertices);
    const Block<double> normals = frames[i].normals_to_unit(vertex_normals_of(meshes[i]));
    Block<double> p(Index(k), 3), pn(Index(k), 3);
    for (size_t m = 0; m < k; ++m) {
      p.row(Index(m)) = unit.row(keypoints[i][m]);
      pn.row(Index(m)) = normals.row(keypoints[i][m]);
    }
    for (size_t j = 0; j < n; ++j) {
      const Block<double> q = map(int(i), int(j), p, pn);
      const Block<double> target = frames[j].to_unit(meshes[j].vertices);
      if (i == j) {  // the self-map: what reconstruction and inversion alone cost
        double self = 0;
        for (size_t m = 0; m < k; ++m) {
          const double d = (q.row(Index(m)) - unit.row(keypoints[i][m])).norm();
          self += d;
          e.keypoint_self[m] += d / double(n);
        }
        e.pair_mean[i][i] = self / double(k);
        e.self_mean += e.pair_mean[i][i] / double(n);
        continue;
      }
      double pair = 0;
      for (size_t m = 0; m < k; ++m) {
        const double d = (q.row(Index(m)) - target.row(keypoints[j][m])).norm();
        pair += d;
        total_squared += d * d;
        e.keypoint_mean[m] += d;
        for (size_t t = 0; t < thresholds.size(); ++t)
          if (d <= thresholds[t]) e.within[t] += 1;
      }
      e.pair_mean[i][j] = pair / double(k);
      total += pair;
      ++e.pairs;
    }
  }
  e.keypoints = Index(k);
  const double count = double(e.pairs) * double(k);
  if (count > 0) {
    e.mean = total / count;
    e.mean_squared = total_squared / count;
    for (double& w : e.within) w /= count;
    for (double& w : e.keypoint_mean) w /= double(e.pairs);
  }
  return e;
}

}  // namespace jsa
