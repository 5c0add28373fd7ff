// The pose step's tie-break by fitting (model/tool/pose_by_fit.h): between a
// shape's own pose and its half turn, the short fit from the reference's atlas
// ends lower in the right one, the same way every time.
#include <catch2/catch.hpp>

#include "engine/parallel.h"
#include "model/tool/pose_by_fit.h"
#include "test/sphere_pool.h"

using namespace jsa;

namespace {

// An egg along x: the unit sphere stretched by 1.8 in x on the x > 0 side and
// squeezed to 0.6 in y and z (a linear map per half, A; normals by A^-T), so a
// half turn about z puts the long end where the short one was.
Block<double> egg(Index n, uint64_t seed) {
  Block<double> pool = test_support::sphere_pool(n, seed);
  for (Index i = 0; i < n; ++i) {
    const double sx = pool(i, 0) > 0 ? 1.8 : 1.0;
    const Eigen::Vector3d a(sx, 0.6, 0.6);
    for (int k = 0; k < 3; ++k) {
      pool(i, k) *= a(k);
      pool(i, 3 + k) /= a(k);
    }
    pool.row(i).rightCols(3).normalize();
  }
  pool.leftCols(3).rowwise() -= pool.leftCols(3).colwise().mean();
  pool.leftCols(3) /= pool.leftCols(3).rowwise().norm().maxCoeff();
  return pool;
}

FitOptions small_options() {
  FitOptions o;
  o.atlas.gaussians = 128;
  o.atlas.width = 32;
  o.atlas.hidden_layers = 3;
  o.points = 256;
  o.threads = 1;
  o.orient_every = 0;
  return o;
}

}  // namespace

TEST_CASE("pose by fit: the shape's own pose beats its half turn, deterministically",
          "[trainer][pose]") {
  set_threads(1);
  const Block<double> reference = egg(4000, 1), shape = egg(4000, 2);
  Eigen::Matrix3d half = Eigen::Matrix3d::Identity();
  half(0, 0) = half(1, 1) = -1;  // about z
  PoseFitOptions p;
  p.template_steps = 400;
  p.steps = 150;
  p.scored = 50;
  p.by_surface = true;
  // The half turn listed first, so the lowest index cannot win by default.
  const std::vector<Eigen::Matrix3d> candidates{half, Eigen::Matrix3d::Identity()};
  const PoseFitChoice c = choose_pose_by_fit(small_options(), reference, shape, candidates, p);
  REQUIRE(c.losses.size() == 2);
  INFO("loss: half turn " << c.losses[0] << ", own pose " << c.losses[1]
                          << "; L_6D: " << c.surfaces[0] << ", " << c.surfaces[1]);
  CHECK(c.chosen == 1);
  CHECK(c.surfaces[1] < 0.8 * c.surfaces[0]);  // not a coin toss (1.5x at this seed)
  CHECK(c.losses[1] < c.losses[0]);            // the training loss agrees, by less
  const PoseFitChoice again = choose_pose_by_fit(small_options(), reference, shape, candidates, p);
  CHECK(again.losses == c.losses);
  CHECK(again.surfaces == c.surfaces);
  // A candidate's score does not depend on its place in the list (the first
  // fits the reference, the others start from its saved state).
  const PoseFitChoice swapped =
      choose_pose_by_fit(small_options(), reference, shape, {candidates[1], candidates[0]}, p);
  CHECK(swapped.losses == std::vector<double>{c.losses[1], c.losses[0]});
  CHECK(swapped.chosen == 0);

  // Several shapes share the reference's fit: the same scores as one at a time,
  // and a shape with a single candidate is left alone.
  const std::vector<PoseFitChoice> both = choose_poses_by_fit(
      small_options(), reference, {shape, shape}, {candidates, {candidates[0]}}, p);
  CHECK(both[0].losses == c.losses);
  CHECK(both[1].losses.empty());
  CHECK(both[1].chosen == 0);
}
