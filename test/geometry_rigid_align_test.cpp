// Tests for io/geometry/rigid_align (built in the model room until the rooms
// layout puts the nearest index beside it): a posed copy of an asymmetric shape
// is turned back, never mirrored, and the same inputs give the same rotation.
#include <catch2/catch.hpp>

#include "engine/rng.h"
#include "io/geometry/rigid_align.h"
#include "test/normal_draws.h"

namespace {

// Points on an ellipsoid of radii 1, 0.6, 0.35 with a bump towards
// (0.6, 0.5, 0.4): three distinct principal axes, and no symmetry that a
// rotation could map onto itself, so the pose is unique. Centred at the mean.
jsa::Block<double> lumpy(jsa::Index n, uint64_t seed) {
  jsa::Rng rng(seed);
  jsa::Block<double> p(n, 3);
  const Eigen::RowVector3d bump = Eigen::RowVector3d(0.6, 0.5, 0.4).normalized();
  for (jsa::Index i = 0; i < n; ++i) {
    Eigen::RowVector3d d = test_support::normal_vector3(rng).transpose();
    d.normalize();
    const double lift = 1 + 0.5 * std::exp(-8 * (d - bump).squaredNorm());
    // Per coordinate: GCC 12's -Warray-bounds misreads Eigen's AVX-512 row copy.
    const double x[3] = {lift * d(0), lift * 0.6 * d(1), lift * 0.35 * d(2)};
    for (int k = 0; k < 3; ++k) p(i, k) = x[k];
  }
  p.rowwise() -= p.colwise().mean();
  return p;
}

Eigen::Matrix3d random_rotation(jsa::Rng& rng) {
  Eigen::Quaterniond q = test_support::normal_quaternion(rng);
  q.normalize();
  return q.toRotationMatrix();
}

}  // namespace

TEST_CASE("a randomly posed copy of an asymmetric shape is turned back", "[model][rigid_align]") {
  // Two independent samples of the shape, so no point has an exact partner.
  const jsa::Block<double> fixed = lumpy(3000, 1), sample = lumpy(3000, 2);
  jsa::Rng rng(5);
  for (int trial = 0; trial < 6; ++trial) {
    const Eigen::Matrix3d a = random_rotation(rng);
    const jsa::Block<double> moving = sample * a;  // posed: x' = x A, so the answer is A^T
    const jsa::RigidAlignment r = jsa::rigid_align(moving, fixed);
    INFO("trial " << trial << ": applied " << jsa::rotation_angle_degrees(a) << " deg");
    CHECK(r.rotation.determinant() == Approx(1).margin(1e-9));
    // The angle left between found and true: the two samples' spacing (~0.03)
    // bounds how well nearest pairs pin the pose; 2 degrees is a tenth of it
    // over the unit radius, and a wrong candidate would be off by 90 or 180.
    CHECK(jsa::rotation_angle_degrees(r.rotation.transpose() * a.transpose()) < 2.0);
    // The bump sets the pose apart: every other candidate ends at a clearly
    // larger Chamfer (about 3x here).
    CHECK(r.chamfer < 0.5 * r.runner_up);
  }
}

TEST_CASE("rigid_align never reflects, and is deterministic", "[model][rigid_align]") {
  // A mirrored copy: the best proper rotation cannot undo it, but must stay proper.
  const jsa::Block<double> fixed = lumpy(2000, 3);
  jsa::Block<double> mirrored = lumpy(2000, 4);
  mirrored.col(0) *= -1;
  const jsa::RigidAlignment m = jsa::rigid_align(mirrored, fixed);
  CHECK(m.rotation.determinant() == Approx(1).margin(1e-9));
  CHECK((m.rotation * m.rotation.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() <
        1e-9);

  jsa::Rng rng(9);
  const jsa::Block<double> moving = lumpy(2000, 5) * random_rotation(rng);
  const jsa::RigidAlignment a = jsa::rigid_align(moving, fixed),
                            b = jsa::rigid_align(moving, fixed);
  CHECK(a.rotation == b.rotation);
  CHECK(a.chamfer == b.chamfer);
}

TEST_CASE("close eigenvalues add the axis orders as candidates", "[model][rigid_align]") {
  // Radii 1, 0.97, 0.5 and a bump between the first two axes: their eigenvalues
  // are within a few percent, so the axes' order is not defined and more than
  // the 4 sign candidates (and the input pose) are tried; the pose is still found.
  jsa::Rng rng(2);
  const Eigen::RowVector3d bump = Eigen::RowVector3d(0.5, 0.5, 0.7).normalized();
  auto round = [&](jsa::Index n) {
    jsa::Block<double> p(n, 3);
    for (jsa::Index i = 0; i < n; ++i) {
      Eigen::RowVector3d d = test_support::normal_vector3(rng).transpose();
      d.normalize();
      const double lift = 1 + 0.4 * std::exp(-8 * (d - bump).squaredNorm());
      const double x[3] = {lift * d(0), lift * 0.97 * d(1), lift * 0.5 * d(2)};
      for (int k = 0; k < 3; ++k) p(i, k) = x[k];
    }
    p.rowwise() -= p.colwise().mean();
    return p;
  };
  const jsa::Block<double> fixed = round(3000), sample = round(3000);
  const Eigen::Matrix3d a = random_rotation(rng);
  const jsa::RigidAlignment r = jsa::rigid_align(sample * a, fixed);
  CHECK(r.candidates > 5);
  // Only the bump pins the turn about the short axis, so two independent
  // samples agree on it to a few degrees (3.1 here), not to the 2 above.
  CHECK(jsa::rotation_angle_degrees(r.rotation.transpose() * a.transpose()) < 5.0);
  const jsa::RigidAlignment distinct = jsa::rigid_align(lumpy(2000, 6), lumpy(2000, 7));
  CHECK(distinct.candidates == 5);  // the input's pose and the 4 sign candidates
}

TEST_CASE("a shape already in the pose of the first keeps it", "[model][rigid_align]") {
  // An ellipsoid without the bump is symmetric under half turns about its
  // axes: four poses score alike. Given in the right pose, the input's own is
  // kept rather than whichever symmetric candidate happens to score lowest.
  jsa::Rng rng(4);
  auto ellipsoid = [&](jsa::Index n) {
    jsa::Block<double> p(n, 3);
    for (jsa::Index i = 0; i < n; ++i) {
      Eigen::RowVector3d d = test_support::normal_vector3(rng).transpose();
      d.normalize();
      const double x[3] = {d(0), 0.6 * d(1), 0.35 * d(2)};
      for (int k = 0; k < 3; ++k) p(i, k) = x[k];
    }
    p.rowwise() -= p.colwise().mean();
    return p;
  };
  const jsa::Block<double> fixed = ellipsoid(2000), moving = ellipsoid(2000);
  const jsa::RigidAlignment r = jsa::rigid_align(moving, fixed);
  CHECK(r.input_chamfer <= 1.25 * r.chamfer);
  CHECK(r.angle_degrees() < 5.0);
}

TEST_CASE("trimmed ICP turns back a shape whose limb moved", "[model][rigid_align]") {
  // The lumpy body, and a copy whose bump ("limb": the points beyond x = 0.45)
  // swung 70 degrees about the z axis through (0.45, 0, 0), then posed. The
  // body still pins the pose; the limb's points have no partners near them.
  const jsa::Block<double> fixed = lumpy(3000, 11);
  jsa::Block<double> bent = lumpy(3000, 12);
  const double c = std::cos(70 * M_PI / 180), s = std::sin(70 * M_PI / 180);
  jsa::Index limb = 0;
  for (jsa::Index i = 0; i < bent.rows(); ++i) {
    if (bent(i, 0) <= 0.45) continue;
    const double x = bent(i, 0) - 0.45, y = bent(i, 1);
    bent(i, 0) = 0.45 + c * x - s * y;
    bent(i, 1) = s * x + c * y;
    ++limb;
  }
  REQUIRE(limb > 300);  // a limb, not a few points: 10-30% of the set
  REQUIRE(limb < 1000);
  jsa::Rng rng(21);
  const Eigen::Matrix3d a = random_rotation(rng);
  const jsa::Block<double> moving = bent * a;
  jsa::RigidAlignOptions o;
  o.keep_input = 0;
  o.trim = 0.6;
  const jsa::RigidAlignment r = jsa::rigid_align(moving, fixed, o);
  INFO("limb points " << limb << ", applied " << jsa::rotation_angle_degrees(a) << " deg");
  // The body's pose within 3 degrees (the limb would pull a plain fit off it).
  CHECK(jsa::rotation_angle_degrees(r.rotation.transpose() * a.transpose()) < 3.0);
  CHECK(r.rotation.determinant() == Approx(1).margin(1e-9));
  // A trim outside (0, 1] is an error, not a silent plain fit.
  o.trim = 0;
  CHECK_THROWS(jsa::rigid_align(moving, fixed, o));
  o.trim = 1.5;
  CHECK_THROWS(jsa::rigid_align(moving, fixed, o));
}

TEST_CASE("a near-tie between poses goes to the one whose neighbourhoods match",
          "[model][rigid_align]") {
  // An ellipsoid sampled twice as densely on one half (the stand-in for a part
  // with more surface, like an ant's legs at one end), that half slightly
  // slimmer (`thin`) or fatter than the other. Fixed: dense half at x > 0,
  // 4% fatter; moving: dense half at x > 0, 4% slimmer. Positions alone
  // prefer (by a hair) the half turn that puts the fat ends together; a
  // point's ball shares (the fraction of its set near it) prefer, clearly,
  // the pose that puts the dense ends together, and so does the tie rule.
  auto ellipsoid = [](jsa::Index n, uint64_t seed, double dense_scale, std::vector<char>& dense) {
    jsa::Rng rng(seed);
    jsa::Block<double> p(n, 3);
    dense.assign(size_t(n), 0);
    for (jsa::Index i = 0; i < n;) {
      Eigen::RowVector3d d = test_support::normal_vector3(rng).transpose();
      d.normalize();
      if (d(0) < 0 && rng.uniform(0, 1) > 0.5) continue;
      const double s = d(0) > 0 ? dense_scale : 1.0;
      dense[size_t(i)] = d(0) > 0;
      const double x[3] = {d(0), 0.6 * s * d(1), 0.35 * s * d(2)};
      for (int k = 0; k < 3; ++k) p(i, k) = x[k];
      ++i;
    }
    return p;  // centred at the ellipsoid's centre: the ends stay where they are
  };
  std::vector<char> dense_fixed, dense_moving;
  const jsa::Block<double> fixed = ellipsoid(3000, 31, 1.04, dense_fixed);
  const jsa::Block<double> sample = ellipsoid(3000, 32, 1 / 1.04, dense_moving);
  jsa::Rng rng(33);
  for (int trial = 0; trial < 4; ++trial) {
    const jsa::Block<double> moving = sample * random_rotation(rng);
    // The share of the moving dense half that lands on x > 0 (the fixed set's
    // dense half): near 1 for the poses that keep the ends, near 0 otherwise.
    auto dense_kept = [&](const Eigen::Matrix3d& r) {
      const jsa::Block<double> moved = moving * r;
      int on = 0, all = 0;
      for (jsa::Index i = 0; i < moved.rows(); ++i)
        if (dense_moving[size_t(i)]) on += moved(i, 0) > 0, ++all;
      return double(on) / all;
    };
    jsa::RigidAlignOptions o;
    o.keep_input = 0;
    o.tie = 0;
    const jsa::RigidAlignment plain = jsa::rigid_align(moving, fixed, o);
    o.tie = 1.25;
    const jsa::RigidAlignment tied = jsa::rigid_align(moving, fixed, o);
    INFO("trial " << trial << ": plain keeps " << dense_kept(plain.rotation) << ", tie rule keeps "
                  << dense_kept(tied.rotation) << ", " << tied.tied << " tied");
    CHECK(tied.tied >= 2);
    CHECK(dense_kept(plain.rotation) < 0.1);  // the lowest Chamfer swaps the ends
    CHECK(dense_kept(tied.rotation) > 0.9);   // the tie rule does not
    CHECK(tied.tie_broken);
  }
}

namespace {

// A one-sided plate: a trapezoid in z = 0 (wider towards +x, so its in-plane
// pose is unique), every normal +z; rows (x, n), centred at the points' mean.
jsa::Block<double> plate(jsa::Index n, uint64_t seed) {
  jsa::Rng rng(seed);
  jsa::Block<double> p = jsa::Block<double>::Zero(n, 6);
  for (jsa::Index i = 0; i < n; ++i) {
    const double x = rng.uniform(-1, 1), half = 0.2 + 0.15 * (x + 1);
    p(i, 0) = x;
    p(i, 1) = rng.uniform(-half, half);
    p(i, 5) = 1;
  }
  p.leftCols(3).rowwise() -= p.leftCols(3).colwise().mean();
  return p;
}

}  // namespace

TEST_CASE("with normal_weight the normals tell a surface from its back", "[model][rigid_align]") {
  // Turned half a turn about x, the plate's points fall on the plate again but
  // its normals face -z: by points alone the true pose and the identity tie;
  // with the normals in the pairs and the score, only the true pose fits.
  const jsa::Block<double> fixed = plate(3000, 1);
  jsa::Block<double> moving = plate(3000, 2);
  Eigen::Matrix3d half_turn = Eigen::Matrix3d::Identity();
  half_turn(1, 1) = half_turn(2, 2) = -1;
  moving.leftCols(3) = (moving.leftCols(3) * half_turn).eval();
  moving.rightCols(3) = (moving.rightCols(3) * half_turn).eval();
  jsa::RigidAlignOptions points_only, with_normals;
  points_only.keep_input = with_normals.keep_input = 0;
  with_normals.normal_weight = 0.2;
  const jsa::RigidAlignment p =
      jsa::rigid_align(moving.leftCols(3), fixed.leftCols(3), points_only);
  const jsa::RigidAlignment n = jsa::rigid_align(moving, fixed, with_normals);
  CHECK(p.runner_up < 1.05 * p.chamfer);  // a tie: the points cannot tell
  CHECK(jsa::rotation_angle_degrees(n.rotation.transpose() * half_turn.transpose()) < 2.0);
  CHECK(n.runner_up > 2 * n.chamfer);
  // Rows of the wrong width are refused, not misread.
  CHECK_THROWS_WITH(jsa::rigid_align(moving.leftCols(3), fixed.leftCols(3), with_normals),
                    Catch::Contains("rows (points, unit normals)"));
}

TEST_CASE("poses within near_factor of the best are reported, one per pose",
          "[model][rigid_align]") {
  // The lumpy body has one pose: the others end at 2-3x its Chamfer.
  const jsa::Block<double> fixed = lumpy(2000, 11);
  const jsa::RigidAlignment one = jsa::rigid_align(lumpy(2000, 12), fixed);
  CHECK(one.near_poses.size() == 1);
  REQUIRE(!one.near_poses.empty());
  CHECK(one.near_poses[0] == one.rotation);
  CHECK(one.near_chamfers[0] == one.chamfer);

  // Two bumps swapped by a half turn about z: that turn maps the body onto
  // itself, so the input's pose and the half turn score alike and both are
  // reported, more than 10 degrees apart, lowest Chamfer first.
  auto two_bumps = [](jsa::Index n, uint64_t seed) {
    jsa::Block<double> p = lumpy(n, seed);
    for (jsa::Index i = 0; i < n; i += 2) {  // every other point: the half-turned copy
      p(i, 0) = -p(i, 0);
      p(i, 1) = -p(i, 1);
    }
    p.rowwise() -= p.colwise().mean();
    return p;
  };
  const jsa::RigidAlignment two = jsa::rigid_align(two_bumps(3000, 13), two_bumps(3000, 14));
  REQUIRE(two.near_poses.size() >= 2);
  CHECK(two.near_chamfers[0] <= two.near_chamfers[1]);
  CHECK(jsa::rotation_angle_degrees(two.near_poses[0].transpose() * two.near_poses[1]) > 10);
  double to_identity = 180, to_half_turn = 180;
  Eigen::Matrix3d half = Eigen::Matrix3d::Identity();
  half(0, 0) = half(1, 1) = -1;
  for (const Eigen::Matrix3d& r : two.near_poses) {
    to_identity = std::min(to_identity, jsa::rotation_angle_degrees(r));
    to_half_turn = std::min(to_half_turn, jsa::rotation_angle_degrees(r.transpose() * half));
  }
  CHECK(to_identity < 3);
  CHECK(to_half_turn < 3);

  jsa::RigidAlignOptions none;
  none.near_factor = 0;
  CHECK(jsa::rigid_align(two_bumps(3000, 13), two_bumps(3000, 14), none).near_poses.empty());
}

TEST_CASE("the canonical frame of a turned copy gives the same canonical points",
          "[model][rigid_align]") {
  const jsa::Block<double> p = lumpy(3000, 21);
  const Eigen::Matrix3d r = jsa::canonical_rotation(p);
  CHECK(r.determinant() == Approx(1).margin(1e-12));
  CHECK((r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  // Longest axis first: the canonical points' variances fall along x, y, z.
  const jsa::Block<double> c = p * r;
  const Eigen::RowVector3d var = c.colwise().squaredNorm();
  CHECK(var(0) > var(1));
  CHECK(var(1) > var(2));
  jsa::Rng rng(22);
  for (int trial = 0; trial < 5; ++trial) {
    const Eigen::Matrix3d q = random_rotation(rng);
    const jsa::Block<double> turned = p * q;
    CHECK((turned * jsa::canonical_rotation(turned) - c).cwiseAbs().maxCoeff() < 1e-9);
  }
}
