// Tests for io/mesh_validation: what is an error, what is only a warning, and how
// normals are normalised or recomputed.
#include <catch2/catch.hpp>
#include <functional>

#include "engine/check.h"
#include "io/mesh_validation.h"
#include "test/scratch.h"

using test_support::message_of;
using test_support::ScratchDir;

namespace {

// Two triangles sharing the edge 1-2, in the plane z = 0, both facing +z.
jsa::Mesh two_triangles() {
  jsa::Mesh mesh;
  mesh.vertices.resize(4, 3);
  mesh.vertices << 0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 1, 3, 2;
  mesh.normals.resize(0, 3);
  return mesh;
}

bool has_warning(const jsa::Mesh& mesh, const std::string& text) {
  for (const std::string& w : mesh.warnings)
    if (w.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("a clean mesh passes without warnings", "[io][mesh_validation]") {
  jsa::Mesh mesh = two_triangles();
  jsa::validate_mesh("m.obj", mesh);
  CHECK(mesh.warnings.empty());
}

TEST_CASE("several components, non-manifold edges and degenerate faces are warnings",
          "[io][mesh_validation]") {
  jsa::Mesh mesh = two_triangles();
  mesh.vertices.conservativeResize(8, 3);
  mesh.vertices.bottomRows(4) << 0, 0, 5, 1, 0, 5, 0, 1, 5, 0.5, 0.5, 9;
  mesh.faces.conservativeResize(5, 3);
  mesh.faces.bottomRows(3) << 4, 5, 6, 1, 2, 7, 0, 0, 1;  // island, fin on edge 1-2, sliver
  jsa::validate_mesh("m.obj", mesh);
  CHECK(has_warning(mesh, "2 connected components"));
  CHECK(has_warning(mesh, "1 non-manifold edges"));
  CHECK(has_warning(mesh, "1 degenerate"));
}

TEST_CASE("normals are normalised and zero ones recomputed from the faces",
          "[io][mesh_validation]") {
  jsa::Mesh mesh = two_triangles();
  mesh.normals.resize(4, 3);
  mesh.normals << 0, 0, 3, 0, 0, 0, 0, 4, 0, 0, 0, 0.5;
  jsa::validate_mesh("m.obj", mesh);
  CHECK(mesh.normals.row(0) == Eigen::RowVector3d(0, 0, 1));
  CHECK(mesh.normals.row(1).isApprox(Eigen::RowVector3d(0, 0, 1)));  // recomputed
  CHECK(mesh.normals.row(2) == Eigen::RowVector3d(0, 1, 0));
  CHECK(has_warning(mesh, "1 zero-length normals recomputed"));
}

TEST_CASE("invalid meshes are rejected naming the file and the element", "[io][mesh_validation]") {
  auto rejects = [](jsa::Mesh mesh, const std::string& expected) {
    const std::string m = message_of([&] { jsa::validate_mesh("bad.off", mesh); });
    INFO(m);
    CHECK(m.find("bad.off") == 0);
    CHECK(m.find(expected) != std::string::npos);
  };
  jsa::Mesh empty;
  rejects(empty, "no vertices");
  jsa::Mesh nan = two_triangles();
  nan.vertices(3, 1) = std::nan("");
  rejects(nan, "bad.off:vertex 3: coordinate is NaN");
  jsa::Mesh negative = two_triangles();
  negative.faces(1, 2) = -2;
  rejects(negative, "bad.off:face 1: vertex index -2 is out of range [0, 4)");
  jsa::Mesh flat = two_triangles();
  flat.vertices.col(1).setZero();
  rejects(flat, "all 2 faces are degenerate");
  jsa::Mesh mismatched = two_triangles();
  mismatched.normals = jsa::Block<double>::Ones(3, 3);
  rejects(mismatched, "3 normals for 4 vertices");
  jsa::Mesh infinite_normal = two_triangles();
  infinite_normal.normals = jsa::Block<double>::Ones(4, 3);
  infinite_normal.normals(2, 0) = INFINITY;
  rejects(infinite_normal, "normal of vertex 2");
  jsa::Mesh cloud = two_triangles();
  cloud.faces.resize(0, 3);
  rejects(cloud, "no faces and no normals");
  cloud.normals = jsa::Block<double>::Ones(4, 3);
  cloud.normals.row(1).setZero();
  rejects(cloud, "normal of point 1: has zero length");
}
