// Tests for io/ply_reader (through read_shape): ascii, binary little and big endian
// written byte by byte here, mixed property types, polygons, extra elements, and
// every kind of broken file we promise to reject with a one-line message.
#include <unistd.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/mesh_io.h"
#include "test/scratch.h"

using test_support::message_of;
using test_support::ScratchDir;

namespace {

// Appends `value` in the given byte order (this test assumes a little-endian host,
// which it checks below).
template <class T>
void put(std::string& out, T value, bool big_endian) {
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, &value, sizeof(T));
  if (big_endian) std::reverse(raw, raw + sizeof(T));
  out.append(reinterpret_cast<const char*>(raw), sizeof(T));
}

bool host_is_little_endian() {
  const std::uint16_t probe = 1;
  unsigned char first;
  std::memcpy(&first, &probe, 1);
  return first == 1;
}

// A unit right-angle pyramid: 5 vertices (float x y z, a uchar colour, double
// normals), one square base (a quad) and four triangles, plus an `edge` element
// that the reader must skip. Corners are listed with a uchar count and int indices.
const float kCorners[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0.5f, 0.5f, 1}};
const int kPolygons[5][4] = {
    {0, 3, 2, 1}, {0, 1, 4, -1}, {1, 2, 4, -1}, {2, 3, 4, -1}, {3, 0, 4, -1}};

std::string pyramid_header(const std::string& format) {
  return "ply\nformat " + format +
         " 1.0\ncomment made in a test\nelement vertex 5\nproperty float x\n"
         "property float y\nproperty float z\nproperty uchar red\nproperty double nx\n"
         "property double ny\nproperty double nz\nelement face 5\n"
         "property list uchar int vertex_indices\nelement edge 1\nproperty int vertex1\n"
         "property int vertex2\nend_header\n";
}

std::string pyramid_binary(bool big_endian) {
  std::string out = pyramid_header(big_endian ? "binary_big_endian" : "binary_little_endian");
  for (const auto& c : kCorners) {
    for (float x : c) put(out, x, big_endian);
    put<std::uint8_t>(out, 200, big_endian);
    for (float x : c) put<double>(out, 2.0 * (x - 0.5), big_endian);  // not unit: reader normalises
  }
  for (const auto& polygon : kPolygons) {
    const std::uint8_t n = polygon[3] < 0 ? 3 : 4;
    put(out, n, big_endian);
    for (int k = 0; k < n; ++k) put<std::int32_t>(out, polygon[k], big_endian);
  }
  put<std::int32_t>(out, 0, big_endian);
  put<std::int32_t>(out, 1, big_endian);
  return out;
}

std::string pyramid_ascii() {
  std::string out = pyramid_header("ascii");
  for (const auto& c : kCorners) {
    for (float x : c) out += std::to_string(x) + " ";
    out += "200";
    for (float x : c) out += " " + std::to_string(2.0 * (x - 0.5));
    out += "\n";
  }
  for (const auto& polygon : kPolygons) {
    const int n = polygon[3] < 0 ? 3 : 4;
    out += std::to_string(n);
    for (int k = 0; k < n; ++k) out += " " + std::to_string(polygon[k]);
    out += "\n";
  }
  return out + "0 1\n";
}

void check_pyramid(const jsa::Mesh& mesh) {
  REQUIRE(mesh.vertices.rows() == 5);
  REQUIRE(mesh.faces.rows() == 6);  // the quad is fanned into two triangles
  for (int v = 0; v < 5; ++v)
    for (int c = 0; c < 3; ++c) CHECK(mesh.vertices(v, c) == Approx(kCorners[v][c]));
  CHECK(mesh.faces.row(0) == Eigen::RowVector3i(0, 3, 2));
  CHECK(mesh.faces.row(1) == Eigen::RowVector3i(0, 2, 1));
  CHECK(mesh.faces.row(5) == Eigen::RowVector3i(3, 0, 4));
  REQUIRE(mesh.normals.rows() == 5);
  for (int v = 0; v < 5; ++v) {
    CHECK(mesh.normals.row(v).norm() == Approx(1));
    const Eigen::RowVector3d expected =
        (Eigen::RowVector3d(kCorners[v][0], kCorners[v][1], kCorners[v][2]).array() - 0.5)
            .matrix()
            .normalized();
    CHECK((mesh.normals.row(v) - expected).norm() < 1e-6);
  }
}

}  // namespace

TEST_CASE("PLY ascii, binary little endian and big endian read the same mesh", "[io][ply]") {
  REQUIRE(host_is_little_endian());
  ScratchDir dir;
  check_pyramid(jsa::read_shape(dir.file("ascii.ply", pyramid_ascii())));
  check_pyramid(jsa::read_shape(dir.file("le.ply", pyramid_binary(false))));
  check_pyramid(jsa::read_shape(dir.file("be.PLY", pyramid_binary(true))));
}

TEST_CASE("PLY integer coordinates, uint lists and 'vertex_index' are read", "[io][ply]") {
  ScratchDir dir;
  std::string out =
      "ply\r\nformat binary_big_endian 1.0\r\nelement vertex 3\r\nproperty short x\r\n"
      "property int16 y\r\nproperty int z\r\nelement face 1\r\n"
      "property list int uint vertex_index\r\nend_header\n";
  const std::int16_t xy[3][2] = {{0, 0}, {-4, 0}, {0, 2}};
  for (const auto& p : xy) {
    put(out, p[0], true);
    put(out, p[1], true);
    put<std::int32_t>(out, 7, true);
  }
  put<std::int32_t>(out, 3, true);
  for (std::uint32_t k : {0u, 1u, 2u}) put(out, k, true);
  const jsa::Mesh mesh = jsa::read_shape(dir.file("ints.ply", out));
  REQUIRE(mesh.vertices.rows() == 3);
  CHECK(mesh.vertices(1, 0) == -4);
  CHECK(mesh.vertices(2, 1) == 2);
  CHECK(mesh.vertices(2, 2) == 7);
  CHECK(mesh.faces.rows() == 1);
  CHECK_FALSE(mesh.has_normals());
}

TEST_CASE("a PLY with vertices and normals but no faces is an oriented point cloud", "[io][ply]") {
  ScratchDir dir;
  const std::string path = dir.file(
      "cloud.ply",
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty float nx\nproperty float ny\nproperty float nz\nend_header\n"
      "0 0 0 0 0 3\n1 2 3 0 -1 0\n");
  const jsa::Mesh mesh = jsa::read_shape(path);
  CHECK(mesh.is_point_cloud());
  REQUIRE(mesh.normals.rows() == 2);
  CHECK(mesh.normals(0, 2) == Approx(1));
  CHECK(mesh.vertices(1, 2) == 3);
}

TEST_CASE("write_ply_points round-trips through read_shape", "[io][ply]") {
  ScratchDir dir;
  jsa::Block<double> points(3, 3), normals(3, 3);
  points << 0.1, 0.2, 1.0 / 3.0, -5, 6, 7, 1e-9, 2e9, -3;
  normals << 1, 0, 0, 0, 1, 0, 0, 0, -1;
  const std::string path = dir.path + "/points.ply";
  jsa::write_ply_points(path, points, normals);
  const jsa::Mesh mesh = jsa::read_shape(path);
  CHECK(mesh.vertices == points);  // 17 digits: exact
  CHECK(mesh.normals == normals);
}

TEST_CASE("broken PLY files are rejected with one line naming the file and the place",
          "[io][ply]") {
  ScratchDir dir;
  auto rejects = [&](const std::string& name, const std::string& bytes,
                     const std::string& expected) {
    const std::string path = dir.file(name, bytes);
    const std::string m = message_of([&] { jsa::read_shape(path); });
    INFO(m);
    CHECK(m.find(path + ":") == 0);
    CHECK(m.find(expected) != std::string::npos);
    CHECK(m.find('\n') == std::string::npos);
  };
  const std::string full = pyramid_binary(false);

  SECTION("truncated binary body") {
    rejects("cut.ply", full.substr(0, full.size() - 6), "truncated");
  }
  SECTION("a header declaring 10^9 vertices in a tiny file, caught before allocating") {
    std::string huge = full;
    huge.replace(huge.find("vertex 5"), 8, "vertex 1000000000");
    rejects("huge.ply", huge, "declares 1000000000 'vertex' rows");
  }
  SECTION("binary garbage") {
    std::string garbage;
    for (int i = 0; i < 256; ++i) garbage += char((i * 37 + 11) % 256);
    rejects("garbage.ply", garbage, "line 1: not a PLY file");
  }
  SECTION("no end_header") {
    rejects("open.ply", "ply\nformat ascii 1.0\nelement vertex 1\n", "no 'end_header'");
  }
  SECTION("unknown property type") {
    rejects("type.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\nend_header\n",
            "line 4: unknown or missing PLY property type");
  }
  SECTION("unknown format") {
    rejects("fmt.ply", "ply\nformat utf8 1.0\nend_header\n", "line 2: expected 'format");
  }
  SECTION("vertex without z") {
    rejects("noz.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "end_header\n0 0\n",
            "line 3: element 'vertex' has no scalar property 'z'");
  }
  SECTION("face index out of range") {
    std::string bad = pyramid_ascii();
    bad.replace(bad.find("\n3 1 2 4\n"), 9, "\n3 1 2 5\n");
    rejects("range.ply", bad, "field 'vertex_indices'): vertex index 5");
  }
  SECTION("negative face index in binary") {
    std::string bad = full;
    const std::size_t faces = full.size() - 8 - (17 + 4 * 13);  // first face row
    bad[faces + 1] = char(0xff), bad[faces + 2] = char(0xff), bad[faces + 3] = char(0xff),
                bad[faces + 4] = char(0xff);
    rejects("negative.ply", bad,
            "element 'face' row 0 field 'vertex_indices': vertex index -1 is out of range");
  }
  SECTION("NaN coordinate") {
    std::string bad = full;
    const std::size_t body = full.find("end_header\n") + 11;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::memcpy(&bad[body + 4], &nan, 4);  // vertex 0, field y
    rejects("nan.ply", bad, "element 'vertex' row 0 field 'y': value is NaN or infinite");
  }
  SECTION("negative list length") {
    std::string bad = pyramid_ascii();
    bad.replace(bad.find("\n3 1 2 4\n"), 9, "\n-3 1 2 4\n");
    rejects("minus.ply", bad, "negative list length -3");
  }
  SECTION("ascii row with too few values") {
    std::string bad = pyramid_ascii();
    bad.replace(bad.find("\n3 1 2 4\n"), 9, "\n3 1 2\n");
    rejects("short.ply", bad, "too few values");
  }
  SECTION("a face with two corners") {
    std::string bad = pyramid_ascii();
    bad.replace(bad.find("\n3 1 2 4\n"), 9, "\n2 1 2\n");
    rejects("two.ply", bad, "at least 3 vertex indices");
  }
  SECTION("only a 'face' element") {
    rejects("novertex.ply",
            "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n"
            "end_header\n",
            "no 'vertex' element");
  }
  SECTION("vertices but neither faces nor normals") {
    rejects("bare.ply",
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
            "property float z\nend_header\n0 0 0\n",
            "no faces and no normals");
  }
}

TEST_CASE("corrupted PLY and OFF files only ever raise InputError", "[io][ply]") {
  // Flip, delete or truncate bytes of valid files at random: the reader must
  // either accept the result or throw InputError, never crash or throw anything else.
  ScratchDir dir;
  const std::string sources[] = {pyramid_binary(false), pyramid_binary(true), pyramid_ascii(),
                                 "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"};
  const std::string names[] = {"fuzz.ply", "fuzz.ply", "fuzz.ply", "fuzz.off"};
  jsa::Rng rng(11);
  int rejected = 0, trials = 0;
  for (int s = 0; s < 4; ++s)
    for (int trial = 0; trial < 300; ++trial, ++trials) {
      std::string bytes = sources[s];
      const int edits = 1 + int(rng.below(3));
      for (int e = 0; e < edits && !bytes.empty(); ++e) {
        const std::size_t at = rng.below(bytes.size());
        switch (rng.below(3)) {
          case 0:
            bytes[at] = char(rng.below(256));
            break;
          case 1:
            bytes.erase(at, 1);
            break;
          default:
            bytes.resize(at);
            break;
        }
      }
      const std::string path = dir.file(names[s], bytes);
      try {
        jsa::read_shape(path);
      } catch (const jsa::InputError& e) {
        ++rejected;
        CHECK(std::string(e.what()).find(path) == 0);
      }
    }
  CHECK(rejected > trials / 4);  // the corruption does get noticed
}

// Inputs found by test/fuzz/fuzz_read_ply, kept as regression tests.
TEST_CASE("fuzz regressions: PLY list lengths past int64 and rows without properties",
          "[io][ply][fuzz]") {
  ScratchDir dir;
  const std::string vertex_header =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  SECTION("an ascii list length of -1e300 is reported, not converted to an integer") {
    // Was UBSan "-1e+300 is outside the range of representable values of type 'long'".
    const std::string path = dir.file(
        "huge_negative_list.ply",
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty list uchar float junk\n"
        "property float x\nproperty float y\nproperty float z\nend_header\n-1e300 0 0 0\n");
    const std::string m = message_of([&] { jsa::read_shape(path); });
    INFO(m);
    CHECK(m.find("field 'junk'): negative list length -1e+300") != std::string::npos);
  }
  SECTION("an element without properties takes no ascii lines") {
    // Rows of an element with no properties used to swallow the next element's lines.
    const std::string path =
        dir.file("empty_element.ply", "ply\nformat ascii 1.0\nelement nothing 2\n" + vertex_header +
                                          "element face 1\nproperty list uchar int vertex_indices\n"
                                          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    const jsa::Mesh mesh = jsa::read_shape(path);
    CHECK(mesh.vertices.rows() == 3);
    CHECK(mesh.faces.rows() == 1);
  }
  SECTION("a binary element of 10^15 rows without properties is read at once") {
    std::string bytes = "ply\nformat binary_little_endian 1.0\nelement nothing 1000000000000000\n" +
                        vertex_header +
                        "element face 1\nproperty list uchar int vertex_indices\n"
                        "end_header\n";
    const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    bytes.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
    const std::int32_t face[3] = {0, 1, 2};
    bytes += char(3);
    bytes.append(reinterpret_cast<const char*>(face), sizeof face);
    const jsa::Mesh mesh = jsa::read_shape(dir.file("empty_rows.ply", bytes));
    CHECK(mesh.faces.rows() == 1);
  }
}
