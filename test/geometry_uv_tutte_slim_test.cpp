// Tutte's embedding is bijective on disks; the flip-free step of the line
// search is the exact largest step; SLIM lowers the symmetric Dirichlet energy
// from a bijective start and never inverts a triangle.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/geometry/uv_cut.h"
#include "io/geometry/uv_injectivity.h"
#include "io/geometry/uv_slim.h"
#include "io/geometry/uv_tutte.h"
#include "test/geometry_uv_meshes.h"

using namespace jsa;

TEST_CASE("tutte: a curved disk lands on a circle with every triangle positive", "[geometry][uv]") {
  const test_uv::UvInput m = test_uv::half_cylinder(12, 7);
  const Block<double> uv = tutte_embedding(m.positions, m.faces);
  CHECK(count_inverted(m.faces, uv) == 0);
  CHECK_FALSE(boundary_self_intersects(m.faces, uv));
  // Boundary vertices sit on one circle around the origin.
  const auto loops = boundary_loops(m.faces, m.positions.rows());
  REQUIRE(loops.size() == 1);
  const double r0 = uv.row(loops[0][0]).norm();
  for (int v : loops[0]) CHECK(uv.row(v).norm() == Approx(r0).epsilon(1e-12));
}

TEST_CASE("tutte: a mesh that is not a disk is refused", "[geometry][uv]") {
  const test_uv::UvInput s = test_uv::sphere(8, 6);  // closed: no boundary loop
  CHECK_THROWS_AS(tutte_embedding(s.positions, s.faces), InputError);
}

TEST_CASE("line search: the flip-free step is the largest step that keeps every triangle positive",
          "[geometry][uv]") {
  const test_uv::UvInput m = test_uv::flat_grid(6, 5);
  Rng rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    Block<double> d(m.uv.rows(), 2);
    for (Index i = 0; i < d.rows(); ++i) d.row(i) << rng.normal(), rng.normal();
    d *= 0.3;
    const double t = max_injective_step(m.faces, m.uv, d);
    REQUIRE(std::isfinite(t));
    REQUIRE(t > 0);
    // Just below t nothing inverts; just above, some triangle does.
    CHECK(count_inverted(m.faces, m.uv + (1 - 1e-6) * t * d) == 0);
    CHECK(count_inverted(m.faces, m.uv + (1 + 1e-6) * t * d) > 0);
  }
  // A translation never inverts anything: no finite cap.
  Block<double> shift(m.uv.rows(), 2);
  shift.col(0).setConstant(1.0);
  shift.col(1).setConstant(-2.0);
  CHECK(std::isinf(max_injective_step(m.faces, m.uv, shift)));
}

TEST_CASE("slim: from Tutte on a curved disk, the energy drops and no triangle inverts",
          "[geometry][uv]") {
  const test_uv::UvInput m = test_uv::half_cylinder(16, 9);
  Block<double> uv = tutte_embedding(m.positions, m.faces);
  const std::vector<TriangleFrame> frames = triangle_frames(m.positions, m.faces);
  const double before = symmetric_dirichlet(frames, m.faces, uv);
  SlimOptions o;
  o.max_iterations = 50;
  o.tolerance = 1e-8;
  const SlimReport r = slim_symmetric_dirichlet(m.positions, m.faces, uv, o);
  CHECK(r.energy_start == Approx(before));
  CHECK(count_inverted(m.faces, uv) == 0);
  CHECK(r.energy_end < before);
  // The half cylinder is developable: the optimum is an isometry (D = 4).
  CHECK(r.energy_end < 4.05);
  CHECK(symmetric_dirichlet(frames, m.faces, uv) == Approx(r.energy_end));
}

TEST_CASE("slim: symmetric Dirichlet is 4 on an isometry and infinite once a triangle inverts",
          "[geometry][uv]") {
  const test_uv::UvInput m = test_uv::flat_grid(3, 3);
  const std::vector<TriangleFrame> frames = triangle_frames(m.positions, m.faces);
  CHECK(symmetric_dirichlet(frames, m.faces, m.uv) == Approx(4.0));
  Block<double> bad = m.uv;
  bad.row(5) << 2.0, 2.0;  // an inner vertex dragged outside: its fan inverts
  CHECK(std::isinf(symmetric_dirichlet(frames, m.faces, bad)));
}

TEST_CASE("slim: an iterate the caller refuses is shortened, not the end of the descent",
          "[geometry][uv]") {
  // A flat grid laid out at half its size (D = 2 (1/4 + 4) = 8.5): SLIM's
  // first step goes nearly all the way to the isometry. The caller refuses any
  // layout wider than 0.75 of the grid (standing in for a boundary that would
  // cross itself), so the full step is refused; shorter ones are taken.
  const test_uv::UvInput m = test_uv::flat_grid(6, 5);
  const Block<double> start = 0.5 * m.positions.leftCols(2);
  const double width = m.positions.col(0).maxCoeff() - m.positions.col(0).minCoeff();
  auto narrow = [&](const Block<double>& uv) {
    return uv.col(0).maxCoeff() - uv.col(0).minCoeff() <= 0.75 * width;
  };
  Block<double> uv = start;
  const SlimReport r = slim_symmetric_dirichlet(m.positions, m.faces, uv, {}, narrow);
  CHECK(r.energy_start == Approx(8.5).epsilon(1e-9));
  CHECK(r.iterations >= 1);
  CHECK(r.energy_end < r.energy_start);
  CHECK(narrow(uv));
  CHECK(count_inverted(m.faces, uv) == 0);
  // Unrefused, the same start reaches the isometry (D = 4).
  Block<double> free = start;
  const SlimReport f = slim_symmetric_dirichlet(m.positions, m.faces, free);
  CHECK(f.energy_end == Approx(4).epsilon(1e-3));
}
