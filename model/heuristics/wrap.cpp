// Beyond the paper: see model/heuristics/wrap.h (one switch in FitOptions).
#include "model/heuristics/wrap.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "engine/adam.h"
#include "engine/ops.h"

namespace jsa {

void octahedral_sphere(double u, double v, double point[3], double normal[3]) {
  const double s = 2 * u - 1, t = 2 * v - 1;
  const double z = 1 - std::abs(s) - std::abs(t);
  double o[3] = {s, t, z};
  if (z < 0) {
    o[0] = std::copysign(1 - std::abs(t), s);
    o[1] = std::copysign(1 - std::abs(s), t);
  }
  const double r = std::sqrt(o[0] * o[0] + o[1] * o[1] + o[2] * o[2]);  // >= 1/sqrt(3)
  for (int i = 0; i < 3; ++i) point[i] = normal[i] = o[i] / r;
}

void Ellipsoid::map(double u, double v, double point[3], double normal[3]) const {
  double d[3], n[3];
  octahedral_sphere(u, v, d, n);
  // p = c + R diag(a) d; its outward normal is R diag(1/a) d, normalised (the
  // gradient of |diag(1/a) R^T (p - c)|^2).
  double m[3], g[3], norm = 0;
  for (int i = 0; i < 3; ++i) {
    m[i] = radii[i] * d[i];
    g[i] = d[i] / radii[i];
  }
  for (int i = 0; i < 3; ++i) {
    point[i] = center[i];
    normal[i] = 0;
    for (int k = 0; k < 3; ++k) {
      point[i] += axes[i][k] * m[k];
      normal[i] += axes[i][k] * g[k];
    }
    norm += normal[i] * normal[i];
  }
  norm = std::sqrt(norm);
  for (int i = 0; i < 3; ++i) normal[i] /= norm;
}

Ellipsoid enclosing_ellipsoid(const Block<float>& pool) {
  JSA_CHECK(pool.rows() > 0 && pool.cols() >= 3, "enclosing_ellipsoid: empty pool");
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (Index i = 0; i < pool.rows(); ++i) c += pool.row(i).leftCols(3).transpose().cast<double>();
  c /= double(pool.rows());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (Index i = 0; i < pool.rows(); ++i) {
    const Eigen::Vector3d d = pool.row(i).leftCols(3).transpose().cast<double>() - c;
    cov += d * d.transpose();
  }
  cov /= double(pool.rows());
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  // Ascending eigenvalues: the largest axis becomes x, the smallest z (the
  // poles of W face the shape's thinnest direction; its seams lie on the -z side).
  Eigen::Matrix3d r;
  r.col(0) = eig.eigenvectors().col(2);
  r.col(1) = eig.eigenvectors().col(1);
  r.col(2) = r.col(0).cross(r.col(1));  // a rotation (det +1), whatever the solver's signs
  Ellipsoid e;
  const double largest = std::sqrt(3 * std::max(eig.eigenvalues()(2), 0.0));
  for (int k = 0; k < 3; ++k) {
    e.center[k] = c(k);
    for (int i = 0; i < 3; ++i) e.axes[i][k] = r(i, k);
    e.radii[k] = std::max(std::sqrt(3 * std::max(eig.eigenvalues()(2 - k), 0.0)), 0.2 * largest);
  }
  if (!(largest > 0)) e.radii[0] = e.radii[1] = e.radii[2] = 1;  // all points equal: any sphere
  return e;
}

WrapReport wrap_initialize(Atlas<float>& atlas, const std::vector<Block<float>>& pools, int steps,
                           Index points, double lr, Rng& rng,
                           const std::function<bool()>& cancelled) {
  JSA_CHECK(int(pools.size()) == atlas.shapes(),
            "wrap_initialize: " << pools.size() << " pools for " << atlas.shapes() << " shapes");
  WrapReport report;
  if (steps <= 0) return report;
  std::vector<Ellipsoid> ellipsoids;
  for (const Block<float>& pool : pools) ellipsoids.push_back(enclosing_ellipsoid(pool));
  const float alpha = atlas.phi.alpha();
  Adam<float> adam;  // its own moments: training starts from fresh ones
  Tape<float> t;
  Block<float> uv(points, 2), wrap(points, 3), wrap6(points, 6);
  for (int step = 0; step < steps; ++step) {
    if (cancelled && cancelled()) break;
    t.clear();
    Var total;
    double phi_sq = 0, psi_sq = 0;
    for (int shape = 0; shape < atlas.shapes(); ++shape) {
      for (Index i = 0; i < points; ++i) {
        double p[3], n[3];
        uv(i, 0) = float(rng.uniform(0, 1));
        uv(i, 1) = float(rng.uniform(0, 1));
        ellipsoids[size_t(shape)].map(uv(i, 0), uv(i, 1), p, n);
        for (int k = 0; k < 3; ++k) {
          wrap(i, k) = wrap6(i, k) = float(p[k]);
          wrap6(i, 3 + k) = alpha * float(n[k]);
        }
      }
      // |phi(u, v) - W(u, v)|^2 and |psi(W, alpha n_W) - (u, v)|^2, means over points.
      Var x = t.constant(uv);
      Var phi_err = sub(t,
                        atlas.phi
                            .evaluate(t, atlas.params, x, false, atlas.phi_code(t, shape),
                                      atlas.phi_nodes(t, shape))
                            .points,
                        t.constant(wrap));
      Var psi_err = sub(
          t, atlas.psi.evaluate(t, atlas.params, t.constant(wrap6), atlas.psi_code(t, shape)), x);
      Var phi_loss = scale(t, sum(t, square(t, phi_err)), 1.0f / float(points));
      Var psi_loss = scale(t, sum(t, square(t, psi_err)), 1.0f / float(points));
      phi_sq += t.scalar(phi_loss);
      psi_sq += t.scalar(psi_loss);
      Var both = add(t, phi_loss, psi_loss);
      total = total.valid() ? add(t, total, both) : both;
    }
    atlas.params.zero_grad();
    t.backward(total);
    adam.step(atlas.params, lr);
    report.phi_error = std::sqrt(phi_sq / atlas.shapes());
    report.psi_error = std::sqrt(psi_sq / atlas.shapes());
    report.steps = step + 1;
  }
  return report;
}

}  // namespace jsa
