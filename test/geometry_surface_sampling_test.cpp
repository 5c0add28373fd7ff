// Tests for io/geometry/surface_sampling: triangles drawn in proportion to area, points
// uniform inside a triangle and on the surface, unit normals, determinism, and
// resampling of oriented point clouds. Count checks use a binomial tolerance of
// 5 standard deviations, so a correct sampler fails about once in 10^6 runs.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/geometry/builtin_shapes.h"
#include "io/geometry/surface_sampling.h"

namespace {

// |count - n p| within 5 binomial standard deviations.
bool binomially_close(double count, double n, double p) {
  return std::abs(count - n * p) <= 5 * std::sqrt(n * p * (1 - p));
}

// Triangle A (area 0.5) at z = 0 and triangle B (area 1.5) at z = 5, both facing +z.
jsa::Mesh two_triangles_one_to_three() {
  jsa::Mesh mesh;
  const double s = std::sqrt(3.0);
  mesh.vertices.resize(6, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 5, s, 0, 5, 0, s, 5;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 3, 4, 5;
  mesh.normals.resize(0, 3);
  return mesh;
}

}  // namespace

TEST_CASE("triangles are chosen in proportion to their area", "[io][surface_sampling]") {
  const jsa::Mesh mesh = two_triangles_one_to_three();
  jsa::Rng rng(1);
  const jsa::Index n = 40000;
  const jsa::SurfaceSamples samples = jsa::sample_surface(mesh, n, rng);
  const double on_small = (samples.points.col(2).array() == 0).count();
  const double on_large = ((samples.points.col(2).array() - 5).abs() < 1e-12).count();
  CHECK(on_small + on_large == n);
  CHECK(binomially_close(on_small, n, 0.25));
  for (jsa::Index i = 0; i < n; ++i) CHECK(samples.normals.row(i) == Eigen::RowVector3d(0, 0, 1));
}

TEST_CASE("points are uniform inside a triangle and lie in it", "[io][surface_sampling]") {
  jsa::Mesh mesh = two_triangles_one_to_three();
  mesh.vertices.conservativeResize(3, 3);
  mesh.faces.conservativeResize(1, 3);
  jsa::Rng rng(2);
  const jsa::Index n = 40000;
  const jsa::SurfaceSamples samples = jsa::sample_surface(mesh, n, rng);
  const auto x = samples.points.col(0).array(), y = samples.points.col(1).array();
  CHECK((x >= 0).all());
  CHECK((y >= 0).all());
  CHECK((x + y <= 1 + 1e-15).all());
  CHECK((samples.points.col(2).array() == 0).all());
  // The corner triangle x + y < 1/2 holds 1/4 of the area; without the sqrt
  // trick it would receive 1/2 of the points. x < 1/2 holds 3/4 of the area.
  CHECK(binomially_close((x + y < 0.5).count(), n, 0.25));
  CHECK(binomially_close((x < 0.5).count(), n, 0.75));
}

TEST_CASE("cube samples lie on the faces, spread evenly, with the face normal",
          "[io][surface_sampling]") {
  const jsa::Mesh cube = jsa::builtin_shape("cube", 16);
  jsa::Rng rng(3);
  const jsa::Index n = 30000;
  const jsa::SurfaceSamples samples = jsa::sample_surface(cube, n, rng);
  int per_face[3][2] = {{0, 0}, {0, 0}, {0, 0}};
  for (jsa::Index i = 0; i < n; ++i) {
    const Eigen::RowVector3d p = samples.points.row(i);
    CHECK(p.cwiseAbs().maxCoeff() == Approx(0.5).margin(1e-12));
    Eigen::Index axis;
    p.cwiseAbs().maxCoeff(&axis);
    const int side = p(axis) > 0;
    ++per_face[axis][side];
    CHECK(samples.normals(i, axis) == Approx(side ? 1 : -1));
    CHECK(samples.normals.row(i).norm() == Approx(1));
  }
  for (auto& axis : per_face)
    for (int count : axis) CHECK(binomially_close(count, n, 1.0 / 6));
}

TEST_CASE("sphere samples use interpolated unit vertex normals", "[io][surface_sampling]") {
  const jsa::Mesh sphere = jsa::builtin_shape("sphere", 32);
  jsa::Rng rng(4);
  const jsa::SurfaceSamples samples = jsa::sample_surface(sphere, 5000, rng);
  for (jsa::Index i = 0; i < samples.points.rows(); ++i) {
    const double radius = samples.points.row(i).norm();
    CHECK(radius <= 1 + 1e-12);
    CHECK(radius > 0.99);  // inscribed polyhedron of a unit sphere
    CHECK(samples.normals.row(i).norm() == Approx(1));
    CHECK(samples.normals.row(i).dot(samples.points.row(i) / radius) > 0.999);
  }
}

TEST_CASE("sampling is deterministic in the generator state", "[io][surface_sampling]") {
  const jsa::Mesh torus = jsa::builtin_shape("torus", 16);
  jsa::Rng a(9), b(9), c(10);
  const jsa::SurfaceSamples first = jsa::sample_surface(torus, 100, a);
  const jsa::SurfaceSamples again = jsa::sample_surface(torus, 100, b);
  const jsa::SurfaceSamples other = jsa::sample_surface(torus, 100, c);
  CHECK(first.points == again.points);
  CHECK(first.normals == again.normals);
  CHECK(first.points != other.points);
  CHECK(a.state() == b.state());
}

TEST_CASE("a point cloud is resampled with replacement, keeping its normals",
          "[io][surface_sampling]") {
  jsa::Mesh cloud;
  cloud.vertices.resize(4, 3);
  cloud.vertices << 0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0;
  cloud.normals.resize(4, 3);
  cloud.normals << 0, 0, 1, 0, 1, 0, 1, 0, 0, 0, 0, -1;
  cloud.faces.resize(0, 3);
  jsa::Rng rng(5);
  const jsa::Index n = 8000;
  const jsa::SurfaceSamples samples = jsa::sample_surface(cloud, n, rng);
  int hits[4] = {0, 0, 0, 0};
  for (jsa::Index i = 0; i < n; ++i) {
    const int k = int(samples.points(i, 0));
    REQUIRE(samples.points.row(i) == cloud.vertices.row(k));
    CHECK(samples.normals.row(i) == cloud.normals.row(k));
    ++hits[k];
  }
  for (int count : hits) CHECK(binomially_close(count, n, 0.25));
}
