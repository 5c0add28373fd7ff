// Tests for io/geometry/vertex_normals: unit face normals and area weighting.
#include <catch2/catch.hpp>

#include "io/geometry/builtin_shapes.h"
#include "io/geometry/vertex_normals.h"

TEST_CASE("face normals are unit, zero for degenerate faces", "[io][vertex_normals]") {
  jsa::Block<double> vertices(4, 3);
  vertices << 0, 0, 0, 2, 0, 0, 0, 3, 0, 4, 0, 0;
  jsa::Faces faces(2, 3);
  faces << 0, 1, 2, 0, 1, 3;  // the second one is a segment
  const jsa::Block<double> normals = jsa::face_normals(vertices, faces);
  CHECK(normals.row(0) == Eigen::RowVector3d(0, 0, 1));
  CHECK(normals.row(1).squaredNorm() == 0);
}

TEST_CASE("vertex normals weigh each face by its area", "[io][vertex_normals]") {
  // Vertex 0 is shared by a big triangle in z = 0 (area 2, normal +z) and a small
  // one in x = 0 (area 0.5, normal +x): the normal is (0.5, 0, 2) normalised.
  jsa::Block<double> vertices(5, 3);
  vertices << 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 1, 0, 0, 0, 1;
  jsa::Faces faces(2, 3);
  faces << 0, 1, 2, 0, 3, 4;
  const jsa::Block<double> normals = jsa::area_weighted_vertex_normals(vertices, faces);
  CHECK(normals.row(0).isApprox(Eigen::RowVector3d(0.5, 0, 2).normalized()));
  CHECK(normals.row(1) == Eigen::RowVector3d(0, 0, 1));
  CHECK(normals.row(4) == Eigen::RowVector3d(1, 0, 0));
}

TEST_CASE("on a sphere the recomputed normals point along the position", "[io][vertex_normals]") {
  const jsa::Mesh sphere = jsa::builtin_shape("sphere", 32);
  const jsa::Block<double> normals =
      jsa::area_weighted_vertex_normals(sphere.vertices, sphere.faces);
  for (jsa::Index v = 0; v < sphere.vertices.rows(); ++v) {
    CHECK(normals.row(v).norm() == Approx(1));
    CHECK(normals.row(v).dot(sphere.vertices.row(v)) > 0.995);
  }
}
