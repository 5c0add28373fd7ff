// The pose step of a collection (model/tool/shape_input.h): shapes given in
// any rigid poses come out in the same unit frames.
#include <catch2/catch.hpp>

#include "engine/rng.h"
#include "model/tool/shape_input.h"
#include "test/normal_draws.h"

using namespace jsa;

namespace {

// An asymmetric body: an ellipsoid of radii 1, 0.6, 0.35 with a bump, as
// N x 6 pool rows (the normals are not used by the pose step; set to the
// radial direction).
RunInput body(Index n, uint64_t seed, double bump_x) {
  Rng rng(seed);
  RunInput in;
  in.pool.resize(n, 6);
  const Eigen::RowVector3d bump = Eigen::RowVector3d(bump_x, 0.5, 0.4).normalized();
  for (Index i = 0; i < n; ++i) {
    Eigen::RowVector3d d = test_support::normal_vector3(rng).transpose();
    d.normalize();
    const double lift = 1 + 0.5 * std::exp(-8 * (d - bump).squaredNorm());
    const double x[3] = {lift * d(0), lift * 0.6 * d(1), lift * 0.35 * d(2)};
    for (int k = 0; k < 3; ++k) {
      in.pool(i, k) = x[k];
      in.pool(i, 3 + k) = d(k);
    }
  }
  in.pool.leftCols(3).rowwise() -= in.pool.leftCols(3).colwise().mean();
  return in;
}

Eigen::Matrix3d random_rotation(Rng& rng) {
  Eigen::Quaterniond q = test_support::normal_quaternion(rng);
  q.normalize();
  return q.toRotationMatrix();
}

// The same inputs as stored in files turned by q: pool and normalisation, as
// load_run_input would give for a turned file (its rows turned, no rotation yet).
RunInput turned(const RunInput& in, const Eigen::Matrix3d& q) {
  RunInput out = in;
  out.pool.leftCols(3) = (in.pool.leftCols(3) * q).eval();
  out.pool.rightCols(3) = (in.pool.rightCols(3) * q).eval();
  return out;
}

}  // namespace

TEST_CASE("pose step: a collection in other poses gets the same unit frames", "[pose]") {
  const std::vector<RunInput> stored{body(3000, 1, 0.6), body(3000, 2, 0.5), body(3000, 3, 0.7)};
  std::vector<RunInput> a = stored;
  const std::vector<RigidAlignment> ra = align_to_first(a);
  Rng rng(4);
  std::vector<RunInput> b;
  for (const RunInput& in : stored) b.push_back(turned(in, random_rotation(rng)));
  const std::vector<RigidAlignment> rb = align_to_first(b);
  for (size_t i = 0; i < stored.size(); ++i) {
    INFO("shape " << i);
    // The reference's frame is its own (not the identity), and every pool is
    // where the stored collection's is: the reference exactly, the others up
    // to the ICP's convergence from other starts (0.01 at radius 1: 0.6 deg).
    CHECK((a[i].pool - b[i].pool).cwiseAbs().maxCoeff() < (i == 0 ? 1e-9 : 1e-2));
    CHECK(ra[i].rotation.determinant() == Approx(1).margin(1e-9));
    CHECK(rb[i].rotation.determinant() == Approx(1).margin(1e-9));
  }
  CHECK(rotation_angle_degrees(ra[0].rotation) > 1);  // the stored body is not in its axes
}

TEST_CASE("pose step: a near tie is settled by the rest of the collection", "[pose]") {
  // Shape 0 is symmetric under a half turn about z (two bumps), so it cannot
  // tell shape 1's two poses apart; shapes 2 and 3 (one bump, as shape 1) can.
  Eigen::Matrix3d half = Eigen::Matrix3d::Identity();
  half(0, 0) = half(1, 1) = -1;
  RunInput reference = body(3000, 11, 0.6);
  for (Index i = 0; i < reference.pool.rows(); i += 2)
    reference.pool.row(i) =
        (reference.pool.row(i) * Eigen::DiagonalMatrix<double, 6>(-1, -1, 1, -1, -1, 1)).eval();
  std::vector<RunInput> inputs{reference, body(3000, 12, 0.6), body(3000, 13, 0.6),
                               body(3000, 14, 0.6)};
  std::vector<RigidAlignment> poses(4);
  // Shape 1 stands half turned, and both poses are listed as near ties.
  set_rotation(inputs[1], half);
  poses[1].rotation = half;
  poses[1].near_poses = {half, Eigen::Matrix3d::Identity()};
  poses[1].near_chamfers = {0.01, 0.0101};
  settle_near_ties(inputs, poses);
  CHECK(rotation_angle_degrees(poses[1].rotation) < 1e-9);
  CHECK(rotation_angle_degrees(inputs[1].normalization.rotation) < 1e-9);
  REQUIRE(poses[1].near_collection.size() == 2);
  CHECK(poses[1].near_collection[1] < 0.8 * poses[1].near_collection[0]);
  // Its pool is back in the pose the others share.
  CHECK((inputs[1].pool - body(3000, 12, 0.6).pool).cwiseAbs().maxCoeff() < 1e-12);

  // A shape whose own input pose was kept is trusted and stays.
  std::vector<RunInput> again{reference, body(3000, 12, 0.6), body(3000, 13, 0.6),
                              body(3000, 14, 0.6)};
  set_rotation(again[1], half);
  poses[1].rotation = half;
  poses[1].kept_input = true;
  settle_near_ties(again, poses);
  CHECK(rotation_angle_degrees(poses[1].rotation.transpose() * half) < 1e-9);
}
