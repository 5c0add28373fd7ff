// Tests for io/mesh_io (with the OBJ, OFF and point-table readers behind it):
// write-then-read round trips, and bad input rejected with one line naming the file.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <functional>

#include "engine/check.h"
#include "io/geometry/builtin_shapes.h"
#include "io/mesh_io.h"
#include "test/scratch.h"

using test_support::message_of;
using test_support::ScratchDir;

namespace {

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// Reading `bytes` as file `name` must throw one line that starts with the path
// and contains `expected`.
void check_rejects(const ScratchDir& dir, const std::string& name, const std::string& bytes,
                   const std::string& expected) {
  const std::string path = dir.file(name, bytes);
  const std::string m = message_of([&] { jsa::read_shape(path); });
  INFO(m);
  CHECK(m.find(path + ":") == 0);
  CHECK(m.find(expected) != std::string::npos);
  CHECK(m.find('\n') == std::string::npos);
}

}  // namespace

TEST_CASE("OBJ round trip keeps vertices, faces, normals and writes uv and materials",
          "[io][mesh_io]") {
  ScratchDir dir;
  const jsa::Mesh torus = jsa::builtin_shape("torus", 12);
  jsa::Block<double> uv = torus.vertices.leftCols(2);
  const std::string path = dir.path + "/torus.obj";
  jsa::write_obj(path, torus, &uv, "torus.mtl", "atlas");
  const std::string text = slurp(path);
  CHECK(text.find("mtllib torus.mtl\n") != std::string::npos);
  CHECK(text.find("usemtl atlas\n") != std::string::npos);
  CHECK(text.find("\nf 1/1/1 ") != std::string::npos);
  CHECK(text.find("\nvt ") != std::string::npos);

  // tinyobjloader::tinyobjloader (the target CMake links) stores floats, so the
  // round trip is exact to float precision only.
  const jsa::Mesh back = jsa::read_shape(path);
  REQUIRE(back.vertices.rows() == torus.vertices.rows());
  CHECK((back.vertices - torus.vertices).cwiseAbs().maxCoeff() < 1e-6);
  CHECK(back.faces == torus.faces);
  REQUIRE(back.normals.rows() == torus.normals.rows());
  CHECK((back.normals - torus.normals).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("OBJ face syntax follows what the mesh has", "[io][mesh_io]") {
  ScratchDir dir;
  jsa::Mesh mesh = jsa::builtin_shape("cube", 8);
  jsa::write_obj(dir.path + "/n.obj", mesh);
  CHECK(slurp(dir.path + "/n.obj").find("\nf 1//1 ") != std::string::npos);
  jsa::Block<double> uv = mesh.vertices.leftCols(2);
  mesh.normals.resize(0, 3);
  jsa::write_obj(dir.path + "/t.obj", mesh, &uv);
  CHECK(slurp(dir.path + "/t.obj").find("\nf 1/1 ") != std::string::npos);
  CHECK(slurp(dir.path + "/t.obj").find("\nvn ") == std::string::npos);
  jsa::write_obj(dir.path + "/p.obj", mesh);
  CHECK(slurp(dir.path + "/p.obj").find("\nf 1 ") != std::string::npos);
  const jsa::Mesh back = jsa::read_shape(dir.path + "/p.obj");
  CHECK(back.faces == mesh.faces);
  CHECK_FALSE(back.has_normals());
}

TEST_CASE("OBJ polygons are triangulated and v+vn without faces is a point cloud",
          "[io][mesh_io]") {
  ScratchDir dir;
  const jsa::Mesh quad = jsa::read_shape(dir.file(
      "quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 2\nf 1//1 2//1 3//1 4//1\n"));
  CHECK(quad.faces.rows() == 2);
  REQUIRE(quad.normals.rows() == 4);
  CHECK(quad.normals(3, 2) == Approx(1));
  const jsa::Mesh cloud =
      jsa::read_shape(dir.file("cloud.obj", "v 0 0 0\nv 1 2 3\nvn 1 0 0\nvn 0 3 0\n"));
  CHECK(cloud.is_point_cloud());
  CHECK(cloud.normals(1, 1) == Approx(1));
}

TEST_CASE("an oriented point cloud round-trips through OBJ v and vn lines", "[io][mesh_io]") {
  ScratchDir dir;
  jsa::Mesh cloud;
  cloud.vertices.resize(2, 3);
  cloud.vertices << 0.5, 1, 2, -1, 0, 3;
  cloud.normals.resize(2, 3);
  cloud.normals << 0, 0, 1, 0.6, 0.8, 0;
  cloud.faces.resize(0, 3);
  jsa::write_obj(dir.path + "/cloud.obj", cloud);
  const jsa::Mesh back = jsa::read_shape(dir.path + "/cloud.obj");
  CHECK(back.is_point_cloud());
  CHECK((back.vertices - cloud.vertices).cwiseAbs().maxCoeff() < 1e-6);
  CHECK((back.normals - cloud.normals).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("OFF files are read: counts on the keyword line, NOFF normals, polygons",
          "[io][mesh_io]") {
  ScratchDir dir;
  const jsa::Mesh square = jsa::read_shape(dir.file(
      "square.off", "OFF 4 1 0\n# a comment\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 255 0 0\n"));
  CHECK(square.vertices.rows() == 4);
  CHECK(square.faces.rows() == 2);
  CHECK(square.faces.row(1) == Eigen::RowVector3i(0, 2, 3));
  const jsa::Mesh tri = jsa::read_shape(
      dir.file("tri.off", "NOFF\n3 1 0\n0 0 0 0 0 5\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n"));
  REQUIRE(tri.normals.rows() == 3);
  CHECK(tri.normals(0, 2) == Approx(1));
}

TEST_CASE("point tables need 6 columns x y z nx ny nz", "[io][mesh_io]") {
  ScratchDir dir;
  const jsa::Mesh cloud =
      jsa::read_shape(dir.file("c.xyz", "# points\n0 0 0 0 0 1\n1 1 1 2 0 0\n"));
  CHECK(cloud.is_point_cloud());
  CHECK(cloud.vertices.rows() == 2);
  CHECK(cloud.normals(1, 0) == Approx(1));
  const jsa::Mesh counted = jsa::read_shape(dir.file("c.pts", "1\n0 0 0 0 1 0\n"));
  CHECK(counted.vertices.rows() == 1);
  check_rejects(dir, "three.txt", "0 0 0\n", "line 1: 3 columns (x y z) but oriented points");
  check_rejects(dir, "five.xyz", "0 0 0 0 1 0\n0 0 0 0 1\n", "line 2: expected 6 numbers");
  check_rejects(dir, "word.xyz", "0 0 zero 0 1 0\n", "line 1: column 3 'zero'");
  check_rejects(dir, "zero.xyz", "0 0 0 0 0 0\n", "normal of point 0: has zero length");
  check_rejects(dir, "comments.xyz", "# nothing\n", "no points");
}

TEST_CASE("files that are not shapes are rejected naming the file", "[io][mesh_io]") {
  ScratchDir dir;
  const std::string missing = dir.path + "/missing.obj";
  CHECK(message_of([&] { jsa::read_shape(missing); }).find(missing + ": cannot open") == 0);
  const std::string folder = dir.path + "/folder.obj";
  std::filesystem::create_directory(folder);
  CHECK(message_of([&] { jsa::read_shape(folder); }).find(folder + ": is a directory") == 0);
  CHECK(message_of([&] { jsa::read_shape(dir.path); }).find(dir.path + ": is a directory") == 0);
  check_rejects(dir, "empty.off", "", "file is empty");
  check_rejects(dir, "shape.stl", "solid x\n", "unknown extension '.stl'");
  check_rejects(dir, "binary.obj", std::string("v 0 0 0\n\x7f\x00\x01garbage", 18),
                "line 2: binary data");
}

TEST_CASE("bad OBJ content is rejected", "[io][mesh_io]") {
  ScratchDir dir;
  check_rejects(dir, "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
                "face 0: vertex index 3 is out of range [0, 3)");
  check_rejects(dir, "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "tinyobjloader");
  check_rejects(dir, "novertex.obj", "# nothing here\n", "no vertices");
  check_rejects(dir, "bare.obj", "v 0 0 0\nv 1 0 0\n", "no faces and no normals");
  check_rejects(dir, "flat.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n",
                "all 1 faces are degenerate");
  check_rejects(dir, "inf.obj", "v 0 0 1e999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
                "vertex 0: coordinate is NaN or infinite");
  check_rejects(dir, "pairs.obj", "v 0 0 0\nv 1 0 0\nvn 0 0 1\n", "expected one normal per point");
}

TEST_CASE("bad OFF content is rejected with the line", "[io][mesh_io]") {
  ScratchDir dir;
  check_rejects(dir, "key.off", "PLY\n3 1 0\n", "line 1: expected 'OFF'");
  check_rejects(dir, "huge.off", "OFF\n1000000000 1 0\n0 0 0\n",
                "line 2: declares 1000000000 vertices");
  check_rejects(dir, "counts.off", "OFF\nthree 1 0\n", "line 2: expected the vertex count");
  check_rejects(dir, "early.off",
                "OFF\n3 1 0\n0.000000 0.000000 0.000000\n1.000000 0.000000 0.000000\n",
                "line 4: file ends early: expected 3 vertices, found 2");
  check_rejects(dir, "nan.off", "OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n",
                "line 4: 'nan' is not a finite number");
  check_rejects(dir, "range.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
                "line 6: vertex index '3' is not an integer in [0, 3)");
  check_rejects(dir, "negative.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n",
                "line 6: vertex index '-1'");
  check_rejects(dir, "line.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
                "line 6: face line must be");
  check_rejects(dir, "short.off", "OFF\n3 1 0\n0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
                "line 3: vertex line has 2 numbers");
}

// Inputs found by test/fuzz/fuzz_read_obj and fuzz_read_xyz, kept as regression tests.
TEST_CASE("fuzz regressions: OBJ normal index past the vn lines, point table without points",
          "[io][mesh_io][fuzz]") {
  ScratchDir dir;
  // Was an ASan heap-buffer-overflow reading attrib.normals in gather_faces.
  check_rejects(dir, "normal_index.obj",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/9\n",
                "a face refers to normal 9 but the file has 1 'vn' lines");
  // Was UBSan "applying non-zero offset 24 to null pointer" in an empty Eigen map.
  check_rejects(dir, "comments.xyz", "2\n# c2\n# comment\n", "no points");
  check_rejects(dir, "only_comment.xyz", "# nothing\n", "no points");
}

// Found by fuzz_read_obj in CI: tinyobjloader's int(1e18) on a `vw` joint id (UBSan).
TEST_CASE("fuzz regressions: OBJ skin-weight lines are ignored", "[io][mesh_io][fuzz]") {
  ScratchDir dir;
  const jsa::Mesh mesh = jsa::read_shape(
      dir.file("weights.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvw 1 0 1e18 0.5\n\tvw 0 1 1\nf 1 2 3\n"));
  CHECK(mesh.vertices.rows() == 3);
  CHECK(mesh.faces.rows() == 1);
}
