// Tests for io/geometry/normalization: the unit-ball placement and its inverse.
#include <catch2/catch.hpp>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/geometry/normalization.h"

TEST_CASE("to_unit centres at the mean and puts the farthest point at norm 1",
          "[io][normalization]") {
  jsa::Rng rng(7);
  jsa::Block<double> points(200, 3);
  for (jsa::Index i = 0; i < points.rows(); ++i)
    points.row(i) << rng.uniform(3, 9), rng.uniform(-20, -10), rng.normal();
  const jsa::Normalization n = jsa::normalization_of(points);
  const jsa::Block<double> unit = n.to_unit(points);
  CHECK(unit.colwise().mean().norm() < 1e-12);
  CHECK(unit.rowwise().norm().maxCoeff() == Approx(1).epsilon(1e-12));
  CHECK(n.center.isApprox(points.colwise().mean()));
  CHECK((n.from_unit(unit) - points).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((n.to_unit(n.from_unit(unit)) - unit).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("known values: two points", "[io][normalization]") {
  jsa::Block<double> points(2, 3);
  points << 1, 0, 0, 5, 0, 0;
  const jsa::Normalization n = jsa::normalization_of(points);
  CHECK(n.center == Eigen::RowVector3d(3, 0, 0));
  CHECK(n.scale == 2);
  CHECK(n.to_unit(points)(0, 0) == -1);
}

TEST_CASE("a shape without extent is rejected, naming its source", "[io][normalization]") {
  jsa::Block<double> same = jsa::Block<double>::Constant(4, 3, 2.5);
  try {
    jsa::normalization_of(same, "dot.xyz");
    FAIL("no exception");
  } catch (const jsa::InputError& e) {
    CHECK(std::string(e.what()).find("dot.xyz: all 4 points coincide") == 0);
  }
  CHECK_THROWS_AS(jsa::normalization_of(jsa::Block<double>(0, 3)), jsa::InputError);
}

TEST_CASE("a rotation turns points and normals, and from_unit undoes it", "[io][normalization]") {
  jsa::Rng rng(11);
  jsa::Block<double> points(50, 3), normals(50, 3);
  for (jsa::Index i = 0; i < points.rows(); ++i) {
    points.row(i) << rng.normal(), rng.normal() + 4, rng.normal();
    normals.row(i) << rng.normal(), rng.normal(), rng.normal();
  }
  jsa::Normalization n = jsa::normalization_of(points);
  const jsa::Block<double> plain = n.to_unit(points);
  n.rotation = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const jsa::Block<double> unit = n.to_unit(points);
  // The rotation comes after centring and scaling: norms in the unit frame are kept.
  CHECK((unit.rowwise().norm() - plain.rowwise().norm()).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((unit - plain * n.rotation).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((n.from_unit(unit) - points).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((n.normals_from_unit(n.normals_to_unit(normals)) - normals).cwiseAbs().maxCoeff() < 1e-12);
  // A normal keeps its angle to the surface's points: dot products are unchanged.
  CHECK((n.normals_to_unit(normals).row(3).dot(unit.row(3)) - normals.row(3).dot(plain.row(3))) ==
        Approx(0).margin(1e-12));
}
