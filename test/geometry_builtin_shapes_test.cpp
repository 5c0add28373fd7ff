// Tests for io/geometry/builtin_shapes: every shape is closed (each edge, welded by
// position, has exactly one twin running the other way), oriented outward with
// the right enclosed volume, and carries unit normals that agree with its faces.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <tuple>

#include "engine/check.h"
#include "io/geometry/builtin_shapes.h"
#include "io/geometry/vertex_normals.h"

namespace {

using PositionKey = std::tuple<long long, long long, long long>;

PositionKey key_of(const jsa::Mesh& mesh, int v) {
  auto q = [](double x) { return std::llround(x * 1e9); };
  return {q(mesh.vertices(v, 0)), q(mesh.vertices(v, 1)), q(mesh.vertices(v, 2))};
}

// True if every directed edge, with vertices identified by position, appears once
// and its reverse appears once: a closed, consistently oriented surface.
bool closed_and_consistent(const jsa::Mesh& mesh) {
  std::map<std::pair<PositionKey, PositionKey>, int> directed;
  for (jsa::Index f = 0; f < mesh.faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      ++directed[{key_of(mesh, mesh.faces(f, k)), key_of(mesh, mesh.faces(f, (k + 1) % 3))}];
  for (const auto& entry : directed) {
    if (entry.second != 1) return false;
    const auto twin = directed.find({entry.first.second, entry.first.first});
    if (twin == directed.end() || twin->second != 1) return false;
  }
  return true;
}

// Divergence theorem: sum over faces of a . (b x c) / 6; positive if oriented outward.
double enclosed_volume(const jsa::Mesh& mesh) {
  double volume = 0;
  for (jsa::Index f = 0; f < mesh.faces.rows(); ++f) {
    const Eigen::RowVector3d a = mesh.vertices.row(mesh.faces(f, 0));
    const Eigen::RowVector3d b = mesh.vertices.row(mesh.faces(f, 1));
    const Eigen::RowVector3d c = mesh.vertices.row(mesh.faces(f, 2));
    volume += a.dot(b.cross(c)) / 6;
  }
  return volume;
}

}  // namespace

TEST_CASE("builtin shapes are closed, outward, with the expected volume", "[io][builtin_shapes]") {
  const double pi = 3.14159265358979323846;
  const std::map<std::string, double> volumes = {
      {"sphere", 4.0 / 3.0 * pi},
      {"torus", 2 * pi * pi * 1.0 * 0.4 * 0.4},
      {"cube", 1.0},
      {"capsule", pi * 0.25 * 1.0 + 4.0 / 3.0 * pi * 0.125}};
  REQUIRE(jsa::builtin_shape_names().size() == volumes.size());
  for (const std::string& name : jsa::builtin_shape_names()) {
    INFO(name);
    const jsa::Mesh mesh = jsa::builtin_shape(name, 64);
    CHECK(mesh.faces.rows() > 100);
    CHECK(closed_and_consistent(mesh));
    // a polyhedron inscribed in a curved surface is slightly smaller
    CHECK(enclosed_volume(mesh) == Approx(volumes.at(name)).epsilon(0.01));
    REQUIRE(mesh.normals.rows() == mesh.vertices.rows());
    const jsa::Block<double> face = jsa::face_normals(mesh.vertices, mesh.faces);
    for (jsa::Index f = 0; f < mesh.faces.rows(); ++f)
      for (int k = 0; k < 3; ++k) {
        const jsa::Index v = mesh.faces(f, k);
        CHECK(mesh.normals.row(v).norm() == Approx(1));
        CHECK(mesh.normals.row(v).dot(face.row(f)) > 0.7);
      }
  }
}

TEST_CASE("the cube's faces are grids on the unit cube with exact face normals",
          "[io][builtin_shapes]") {
  const jsa::Mesh cube = jsa::builtin_shape("cube", 16);  // 4 x 4 cells per face
  CHECK(cube.faces.rows() == 6 * 4 * 4 * 2);
  CHECK(cube.vertices.cwiseAbs().maxCoeff() == 0.5);
  for (jsa::Index v = 0; v < cube.vertices.rows(); ++v) {
    Eigen::Index axis;
    cube.normals.row(v).cwiseAbs().maxCoeff(&axis);
    CHECK(cube.normals.row(v).cwiseAbs().sum() == 1);
    CHECK(cube.vertices(v, axis) == 0.5 * cube.normals(v, axis));
  }
}

TEST_CASE("resolution changes the tessellation", "[io][builtin_shapes]") {
  CHECK(jsa::builtin_shape("sphere", 16).faces.rows() <
        jsa::builtin_shape("sphere", 32).faces.rows());
  CHECK_THROWS_AS(jsa::builtin_shape("sphere", 4), jsa::InputError);
}

TEST_CASE("an unknown builtin shape lists the valid names", "[io][builtin_shapes]") {
  try {
    jsa::builtin_shape("teapot");
    FAIL("no exception");
  } catch (const jsa::InputError& e) {
    const std::string m = e.what();
    CHECK(m.find("'teapot'") != std::string::npos);
    CHECK(m.find("sphere, torus, cube, capsule") != std::string::npos);
  }
}
