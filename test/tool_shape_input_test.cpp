// The pose step of a collection (model/tool/shape_input.h): shapes given in
// any rigid poses come out in the same unit frames.
#include <catch2/catch.hpp>

#include "engine/rng.h"
#include "model/tool/shape_input.h"

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
    Eigen::RowVector3d d(rng.normal(), rng.normal(), rng.normal());
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
  Eigen::Quaterniond q(rng.normal(), rng.normal(), rng.normal(), rng.normal());
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
