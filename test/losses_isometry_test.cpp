// VALUES of L_iso (Eq. 10, losses/isometry.h) on Jacobians whose metric is
// known: zero for an isometry, the closed form for a stretch and a shear. (Its
// gradients are checked with the MLP's tangents in engine_tangents_test.cpp.)
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/rng.h"
#include "engine/tape.h"
#include "losses/isometry.h"

using namespace jsa;

namespace {

double iso(const Block<double>& du, const Block<double>& dv) {
  Tape<double> t;
  return t.scalar(isometry_loss(t, t.constant(du), t.constant(dv)));
}

}  // namespace

TEST_CASE("isometry_loss: 0 for an isometry (orthonormal J_u, J_v)", "[isometry]") {
  // Random rotations of (e1, e2): J^T J = I exactly up to rounding.
  Rng rng(1);
  const Index m = 50;
  Block<double> du(m, 3), dv(m, 3);
  for (Index i = 0; i < m; ++i) {
    Eigen::Vector3d a(rng.normal(), rng.normal(), rng.normal()),
        b(rng.normal(), rng.normal(), rng.normal());
    a.normalize();
    b = (b - b.dot(a) * a).normalized();
    du.row(i) = a.transpose();
    dv.row(i) = b.transpose();
  }
  CHECK(std::abs(iso(du, dv)) < 1e-28);
}

TEST_CASE("isometry_loss: closed forms for a stretch and a shear", "[isometry]") {
  // phi(u, v) = (a u, b v, 0): J_u = (a, 0, 0), J_v = (0, b, 0), so E = a^2,
  // F = 0, G = b^2 and |J^T J - I|_F^2 = (a^2 - 1)^2 + (b^2 - 1)^2.
  // phi(u, v) = (u + s v, v, 0): J_u = (1, 0, 0), J_v = (s, 1, 0), so E = 1,
  // F = s, G = 1 + s^2 and the term is 2 s^2 + s^4. L_iso is their mean.
  const double a[] = {2.0, 0.5, 1.0}, b[] = {1.0, 3.0, 0.25}, s = 0.7;
  Block<double> du = Block<double>::Zero(4, 3), dv = Block<double>::Zero(4, 3);
  double expected = 0;
  for (int i = 0; i < 3; ++i) {
    du(i, 0) = a[i];
    dv(i, 1) = b[i];
    expected += std::pow(a[i] * a[i] - 1, 2) + std::pow(b[i] * b[i] - 1, 2);
  }
  du(3, 0) = 1;
  dv(3, 0) = s;
  dv(3, 1) = 1;
  expected += 2 * s * s + std::pow(s, 4);
  expected /= 4;
  CHECK(iso(du, dv) == Approx(expected).epsilon(1e-14));
  // One stretched row alone: (2^2 - 1)^2 + (1 - 1)^2 = 9.
  CHECK(iso(du.topRows(1), dv.topRows(1)) == Approx(9.0).epsilon(1e-15));
}
