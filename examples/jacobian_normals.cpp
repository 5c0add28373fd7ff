// Example: the Jacobian J = [dphi/du, dphi/dv] (Eq. 1) and the normals (Eq. 2)
// of a parametrization, from one pass of stacked tangent rows [x; e_u; e_v]
// through phi (model/parametrize.h), checked against forward-mode dual numbers
// that evaluate the same weights point by point. Exits non-zero on a mismatch.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "engine/dual.h"
#include "model/parametrize.h"

using namespace jsa;
using D = Dual<double, 2>;

// phi at (u, v) with duals: seeding u and v as the two tangent directions makes
// the derivative slots of the result the columns of J.
std::vector<D> phi_dual(const Parameters<double>& p, const MlpShape& shape, double u, double v) {
  std::vector<D> h = {D::variable(u, 0), D::variable(v, 1)};
  for (int k = 0; k <= shape.hidden_layers; ++k) {
    const auto w = p.value(p.find("phi.w" + std::to_string(k)));
    const auto b = p.value(p.find("phi.b" + std::to_string(k)));
    std::vector<D> out(size_t(w.cols()));
    for (Index j = 0; j < w.cols(); ++j) {
      D z(b(0, j));
      for (Index i = 0; i < w.rows(); ++i) z += h[size_t(i)] * D(w(i, j));
      out[size_t(j)] = k < shape.hidden_layers ? relu(z) : z;
    }
    h = out;
  }
  return h;
}

int main() try {
  const MlpShape shape{2, 3, 32, 3, 0};  // in, out, width, hidden layers, code size
  Parameters<double> p;
  const Parametrization<double> phi(p, shape, 0.01);  // alpha = 0.01
  Rng rng(5);
  phi.initialize(p, rng);

  const Index m = 8;  // M domain points
  Block<double> x(m, 2);
  for (Index i = 0; i < m; ++i) x.row(i) << rng.uniform(), rng.uniform();
  Tape<double> t;
  const SurfacePoints s = phi.evaluate(t, p, t.constant(x), /*with_jacobian=*/true);

  double worst = 0;
  for (Index i = 0; i < m; ++i) {
    const std::vector<D> f = phi_dual(p, shape, x(i, 0), x(i, 1));
    Eigen::Vector3d ju, jv;
    for (int c = 0; c < 3; ++c) {
      ju[c] = f[size_t(c)].v[0];
      jv[c] = f[size_t(c)].v[1];
      worst = std::max(worst, std::abs(t.value(s.points)(i, c) - f[size_t(c)].a));
      worst = std::max(worst, std::abs(t.value(s.du)(i, c) - ju[c]));
      worst = std::max(worst, std::abs(t.value(s.dv)(i, c) - jv[c]));
    }
    // Eq. 2, with the tape's guard: row_normalize divides by sqrt(|c|^2 + 1e-12)
    // (engine/ops.h) so that a degenerate J has a finite gradient.
    const Eigen::Vector3d cross = ju.cross(jv);
    const Eigen::Vector3d n = phi.alpha() * cross / std::sqrt(cross.squaredNorm() + 1e-12);
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(t.value(s.normals)(i, c) - n[c]));
    if (i < 3)
      std::printf("x = (%.3f, %.3f)  J_u = (% .4f % .4f % .4f)  n/alpha = (% .4f % .4f % .4f)\n",
                  x(i, 0), x(i, 1), ju[0], ju[1], ju[2], n[0] / phi.alpha(), n[1] / phi.alpha(),
                  n[2] / phi.alpha());
  }
  std::printf("largest difference, tape vs duals (phi, J_u, J_v, n): %.2e\n", worst);
  const bool ok = worst < 1e-12;  // the same arithmetic in another order: rounding only
  std::printf("%s\n", ok ? "ok" : "FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {  // JSA_CHECK and InputError throw
  std::fprintf(stderr, "example_jacobian_normals: %s\n", e.what());
  return 1;
}
