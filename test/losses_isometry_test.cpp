// VALUES of L_iso (Eq. 10, losses/isometry.h) on Jacobians whose metric is
// known: zero for an isometry, the closed form for a stretch and a shear. (Its
// gradients are checked with the MLP's tangents in engine_tangents_test.cpp.)
// L_metric's values and its gradient against central differences.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/gradcheck.h"
#include "engine/rng.h"
#include "engine/tape.h"
#include "losses/isometry.h"
#include "test/normal_draws.h"

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
    Eigen::Vector3d a = test_support::normal_vector3(rng), b = test_support::normal_vector3(rng);
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

TEST_CASE("metric_mismatch: 0 for isometric pairs, the closed form for a stretch", "[isometry]") {
  // (J_u, J_v) and a rotation of it have the same metric: L_metric = 0.
  Rng rng(2);
  const Index m = 40;
  Block<double> du = Block<double>::Zero(m, 3), dv = Block<double>::Zero(m, 3);
  for (Index i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) du(i, k) = rng.normal(), dv(i, k) = rng.normal();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Block<double> du_r = du * r, dv_r = dv * r;
  auto mismatch = [](const Block<double>& a, const Block<double>& b, const Block<double>& c,
                     const Block<double>& d) {
    Tape<double> t;
    return t.scalar(metric_mismatch(t, t.constant(a), t.constant(b), t.constant(c), t.constant(d)));
  };
  CHECK(std::abs(mismatch(du, dv, du_r, dv_r)) < 1e-24);
  // (a e1, b e2) against (e1, e2): (a^2 - 1)^2 + (b^2 - 1)^2, F = 0 on both;
  // against a shear (e1, s e1 + e2): E equal, F differs by s, G by s^2.
  Block<double> a1 = Block<double>::Zero(2, 3), a2 = Block<double>::Zero(2, 3);
  Block<double> b1 = Block<double>::Zero(2, 3), b2 = Block<double>::Zero(2, 3);
  a1(0, 0) = 2, a2(0, 1) = 0.5;                // row 0: stretch (2, 0.5)
  a1(1, 0) = 1, a2(1, 1) = 1;                  // row 1: the identity
  b1(0, 0) = 1, b2(0, 1) = 1;                  // row 0: the identity
  b1(1, 0) = 1, b2(1, 0) = 0.3, b2(1, 1) = 1;  // row 1: shear s = 0.3
  const double row0 = std::pow(4.0 - 1, 2) + std::pow(0.25 - 1, 2);
  const double row1 = 2 * 0.3 * 0.3 + std::pow(0.09, 2);
  CHECK(mismatch(a1, a2, b1, b2) == Approx((row0 + row1) / 2).epsilon(1e-14));
}

// Four 12 x 3 blocks of standard normal entries: (J_u, J_v) of two shapes.
static std::vector<Block<double>> four_jacobian_blocks(uint64_t seed) {
  Rng rng(seed);
  std::vector<Block<double>> in;
  for (int k = 0; k < 4; ++k) {
    Block<double> b(12, 3);
    for (Index i = 0; i < b.rows(); ++i)
      for (int c = 0; c < 3; ++c) b(i, c) = rng.normal();
    in.push_back(b);
  }
  return in;
}

TEST_CASE("metric_mismatch gradient passes the finite-difference check", "[isometry]") {
  // With respect to all four Jacobian blocks, default tolerances (relative
  // 1e-5, absolute 1e-8, step 1e-6 relative, double precision). The loss is a
  // polynomial in its inputs, so the central differences are exact up to
  // rounding and the check has no kinks to avoid.
  const std::vector<Block<double>> in = four_jacobian_blocks(3);
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) {
        return metric_mismatch(t, v[0], v[1], v[2], v[3]);
      },
      in);
  INFO(r.report);
  CHECK(r.ok);
}

TEST_CASE("conformal_metric_mismatch: 0 up to a scale per point, the closed form otherwise",
          "[isometry]") {
  // A rotated copy scaled by a different factor on every row: the forms are
  // proportional row by row, so the conformal mismatch is 0 (the isometric one is not).
  Rng rng(4);
  const Index m = 30;
  Block<double> du(m, 3), dv(m, 3);
  for (Index i = 0; i < m; ++i)
    for (int k = 0; k < 3; ++k) du(i, k) = rng.normal(), dv(i, k) = rng.normal();
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(3, -1, 2).normalized()).toRotationMatrix();
  Block<double> du_s = du * r, dv_s = dv * r;
  for (Index i = 0; i < m; ++i) {
    const double c = 0.5 + 0.1 * double(i);
    du_s.row(i) *= c;
    dv_s.row(i) *= c;
  }
  auto run = [](bool conformal, const Block<double>& a, const Block<double>& b,
                const Block<double>& c, const Block<double>& d) {
    Tape<double> t;
    const Var v0 = t.constant(a), v1 = t.constant(b), v2 = t.constant(c), v3 = t.constant(d);
    return t.scalar(conformal ? conformal_metric_mismatch(t, v0, v1, v2, v3)
                              : metric_mismatch(t, v0, v1, v2, v3));
  };
  CHECK(std::abs(run(true, du, dv, du_s, dv_s)) < 1e-24);
  CHECK(run(false, du, dv, du_s, dv_s) > 1e-2);
  // One row, a stretch (2, 1) against the identity: g_a = (4, 0, 1)/sqrt17,
  // g_b = (1, 0, 1)/sqrt2, |g_a - g_b|^2 = 2 - 2 (4 + 1) / sqrt(34).
  Block<double> a1 = Block<double>::Zero(1, 3), a2 = Block<double>::Zero(1, 3);
  Block<double> b1 = Block<double>::Zero(1, 3), b2 = Block<double>::Zero(1, 3);
  a1(0, 0) = 2, a2(0, 1) = 1, b1(0, 0) = 1, b2(0, 1) = 1;
  // (row_normalize adds eps = 1e-12 under its square root.)
  CHECK(run(true, a1, a2, b1, b2) == Approx(2 - 10 / std::sqrt(34.0)).epsilon(1e-10));
}

TEST_CASE("conformal_metric_mismatch gradient passes the finite-difference check", "[isometry]") {
  // All four Jacobian blocks, default tolerances (relative 1e-5, absolute 1e-8,
  // step 1e-6 relative, double precision). Smooth away from J = 0, which random
  // normal rows avoid.
  const std::vector<Block<double>> in = four_jacobian_blocks(5);
  const GradCheckResult r = check_gradients(
      [](Tape<double>& t, const std::vector<Var>& v) {
        return conformal_metric_mismatch(t, v[0], v[1], v[2], v[3]);
      },
      in);
  INFO(r.report);
  CHECK(r.ok);
}
