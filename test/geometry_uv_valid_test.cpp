// The whole pipeline (io/geometry/valid_uv.h) on UVs that are wrong on
// purpose: a fold, a tear, a closed sphere projected flat, and on meshes as they
// come (non-manifold edges and vertices, components, holes, degenerate faces,
// inconsistent orientation). Every result is checked by the independent UV
// report (losses/uv_quality.h): no flipped triangle, no overlap by
// rasterisation, every face kept in order.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "io/geometry/uv_cut.h"
#include "io/geometry/valid_uv.h"
#include "io/mesh_io.h"
#include "losses/metrics/uv_quality.h"
#include "test/geometry_uv_meshes.h"
#include "test/scratch.h"

using namespace jsa;
using test_uv::UvInput;

namespace {

// m with extra vertices (3D and psi UV) and extra faces appended.
UvInput append(const UvInput& m, const Block<double>& positions, const Block<double>& uv,
               const Faces& faces) {
  UvInput out;
  out.positions.resize(m.positions.rows() + positions.rows(), 3);
  out.positions << m.positions, positions;
  out.uv.resize(m.uv.rows() + uv.rows(), 2);
  out.uv << m.uv, uv;
  out.faces.resize(m.faces.rows() + faces.rows(), 3);
  out.faces << m.faces, faces;
  return out;
}

UvQuality check_valid(const UvInput& m, const ValidUv& v) {
  REQUIRE(v.uv_faces.rows() == m.faces.rows());
  REQUIRE(v.uv.allFinite());
  UvQualityOptions qo;
  qo.overlap_resolution = 2048;
  const UvQuality q = measure_uv_quality(m.positions, m.faces, v.uv, v.uv_faces, qo);
  CHECK(q.flipped == 0);
  CHECK_FALSE(q.mirrored);
  CHECK(q.overlap_ratio == 0);
  // Packed into the unit square.
  CHECK(v.uv.minCoeff() >= 0);
  CHECK(v.uv.maxCoeff() <= 1);
  return q;
}

bool warned(const ValidUvStats& s, const std::string& word) {
  return std::any_of(s.warnings.begin(), s.warnings.end(),
                     [&](const std::string& w) { return w.find(word) != std::string::npos; });
}

}  // namespace

TEST_CASE("valid uv: a folded UV map comes out with zero flips and zero overlap",
          "[geometry][uv]") {
  UvInput m = test_uv::flat_grid(20, 10);
  // Fold the right half back over the left: u = 0.5 - |x - 0.5| * 0.8 for x > 0.5.
  for (Index v = 0; v < m.uv.rows(); ++v)
    if (m.uv(v, 0) > 0.5) m.uv(v, 0) = 0.5 - 0.8 * (m.uv(v, 0) - 0.5);
  const UvQuality before = measure_uv_quality(m.positions, m.faces, m.uv, m.faces);
  REQUIRE(before.flipped > 0);  // the input really is folded
  REQUIRE(before.overlap_ratio > 0.2);
  const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
  const UvQuality q = check_valid(m, v);
  // The fold's two sides are two charts, both near-isometric (the plane is developable).
  CHECK(q.charts == 2);
  CHECK(v.stats.mirrored_charts == 1);
  CHECK(q.symmetric_dirichlet < 4.1);
  CHECK(q.seam_length == Approx(1.0).margin(0.11));  // the fold line, one grid column either side
}

TEST_CASE("valid uv: psi's layout is kept (a chart aligned back onto psi's UVs)",
          "[geometry][uv]") {
  UvInput m = test_uv::half_cylinder(16, 8);
  // A valid psi with mild anisotropy and a rotation.
  for (Index v = 0; v < m.uv.rows(); ++v) {
    const double x = m.uv(v, 0), y = m.uv(v, 1);
    m.uv.row(v) << 0.3 + 0.2 * (0.8 * x - 0.6 * y), 0.4 + 0.2 * (0.6 * x + 0.8 * y) * 1.2;
  }
  ValidUvOptions o;
  o.pack_charts = false;
  const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv, o);
  REQUIRE(v.stats.charts == 1);
  CHECK(v.stats.from_psi == 1);
  // One chart, no seams: vt index = local vertex; compare each vertex to psi.
  double worst = 0, extent = (m.uv.colwise().maxCoeff() - m.uv.colwise().minCoeff()).maxCoeff();
  for (Index f = 0; f < m.faces.rows(); ++f)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, (v.uv.row(v.uv_faces(f, k)) - m.uv.row(m.faces(f, k))).norm());
  CHECK(worst < 0.1 * extent);  // the same place, up to the removed anisotropy
  CHECK(worst > 0);             // and the anisotropy was removed
}

TEST_CASE("valid uv: a torn map (a cylinder closed across psi's cut) is cut there",
          "[geometry][uv]") {
  // A full cylinder: uv = (angle / 2 pi, y), so the last column of faces spans the chart.
  const int n = 48, rows = 6;
  UvInput m;
  m.positions.resize(n * (rows + 1), 3);
  m.uv.resize(n * (rows + 1), 2);
  for (int j = 0; j <= rows; ++j)
    for (int i = 0; i < n; ++i) {
      const double a = 2 * M_PI * i / n;
      m.positions.row(j * n + i) << std::cos(a), std::sin(a), double(j) / rows;
      m.uv.row(j * n + i) << double(i) / n, double(j) / rows;
    }
  m.faces.resize(2 * n * rows, 3);
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = j * n + i, b = j * n + (i + 1) % n, c = b + n, d = a + n;
      m.faces.row(2 * (j * n + i)) << a, b, c;
      m.faces.row(2 * (j * n + i) + 1) << a, c, d;
    }
  REQUIRE(measure_uv_quality(m.positions, m.faces, m.uv, m.faces).torn > 0);
  const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
  const UvQuality q = check_valid(m, v);
  CHECK(q.torn == 0);
  // Torn: the 5 inner horizontal edges and the 6 diagonals of the column that
  // straddles psi's cut; every torn edge becomes a seam, a zigzag of length
  // 5 * (2 pi / 48) + 6 * sqrt((2 pi / 48)^2 + (1/6)^2) = 1.925.
  CHECK(v.stats.cut.torn_edges == 2 * rows - 1);
  CHECK(q.charts == 1);
  const double h = 2 * std::sin(M_PI / n), seam = 5 * h + 6 * std::sqrt(h * h + 1.0 / 36);
  CHECK(q.seam_length == Approx(seam));
}

TEST_CASE("valid uv: a closed sphere projected flat becomes disks, all counter-clockwise",
          "[geometry][uv]") {
  const UvInput m = test_uv::sphere(24, 12);
  const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
  const UvQuality q = check_valid(m, v);
  CHECK(q.charts >= 2);
  CHECK(v.stats.single_faces == 0);
}

TEST_CASE("valid uv: the same input gives the same UVs", "[geometry][uv]") {
  const UvInput m = test_uv::sphere(16, 9);
  const ValidUv a = make_valid_uv(m.positions, m.faces, m.uv);
  const ValidUv b = make_valid_uv(m.positions, m.faces, m.uv);
  CHECK(a.uv == b.uv);
  CHECK(a.uv_faces == b.uv_faces);
}

TEST_CASE("valid uv: packing leaves the padding between charts and never overlaps",
          "[geometry][uv]") {
  // Many small disjoint squares (components), each with its own valid psi.
  UvInput m;
  const int pieces = 30;
  m.positions.resize(4 * pieces, 3);
  m.uv.resize(4 * pieces, 2);
  m.faces.resize(2 * pieces, 3);
  for (int p = 0; p < pieces; ++p) {
    const double s = 0.2 + 0.05 * (p % 7), w = 1 + (p % 3);
    for (int k = 0; k < 4; ++k) {
      const double x = (k == 1 || k == 2) ? w * s : 0, y = k >= 2 ? s : 0;
      m.positions.row(4 * p + k) << x + 3 * p, y, 0;
      m.uv.row(4 * p + k) << x, y;  // every square on top of the others in psi
    }
    m.faces.row(2 * p) << 4 * p, 4 * p + 1, 4 * p + 2;
    m.faces.row(2 * p + 1) << 4 * p, 4 * p + 2, 4 * p + 3;
  }
  REQUIRE(measure_uv_quality(m.positions, m.faces, m.uv, m.faces).overlap_ratio > 0.5);
  ValidUvOptions o;
  o.pack.texture_size = 256;
  o.pack.padding = 3;
  const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv, o);
  check_valid(m, v);
  CHECK(v.stats.charts == pieces);
  CHECK(v.stats.padding_texels == 3);
  CHECK(v.stats.packing_efficiency > 0.3);
  // Bounding boxes of the charts are at least the padding apart (in one axis).
  std::vector<Eigen::Vector4d> box(pieces);  // xmin ymin xmax ymax
  for (int p = 0; p < pieces; ++p) {
    box[size_t(p)] << 2, 2, -1, -1;
    for (int f = 2 * p; f < 2 * p + 2; ++f)
      for (int k = 0; k < 3; ++k) {
        const Eigen::RowVector2d t = v.uv.row(v.uv_faces(f, k));
        box[size_t(p)] << std::min(box[size_t(p)](0), t(0)), std::min(box[size_t(p)](1), t(1)),
            std::max(box[size_t(p)](2), t(0)), std::max(box[size_t(p)](3), t(1));
      }
  }
  const double pad = 3.0 / 256;
  for (int a = 0; a < pieces; ++a) {
    CHECK(box[size_t(a)](0) >= pad - 1e-12);
    CHECK(box[size_t(a)](3) <= 1 - pad + 1e-12);
    for (int b = a + 1; b < pieces; ++b) {
      const Eigen::Vector4d A = box[size_t(a)], B = box[size_t(b)];
      const double gap = std::max({B(0) - A(2), A(0) - B(2), B(1) - A(3), A(1) - B(3)});
      CHECK(gap >= pad - 1e-9);
    }
  }
}

TEST_CASE("valid uv: the written OBJ keeps every v value and the face order; seams only split vt",
          "[geometry][uv]") {
  test_support::ScratchDir dir("uv");
  // Coordinates that do not print short, to catch any rounding.
  UvInput m = test_uv::sphere(12, 7);
  for (Index v = 0; v < m.positions.rows(); ++v) m.positions.row(v) *= 1.0 / 3.0 + 1e-9 * double(v);
  Mesh mesh;
  mesh.vertices = m.positions;
  mesh.faces = m.faces;
  const std::string in = dir.path + "/in.obj";
  write_obj(in, mesh);
  const Mesh read = read_shape(in);
  REQUIRE(read.vertices.rows() == m.positions.rows());
  const ValidUv v = make_valid_uv(read.vertices, read.faces, read.vertices.leftCols(2));
  REQUIRE(v.uv.rows() > read.vertices.rows());  // seams split vt
  const std::string out = dir.path + "/out.obj";
  write_obj(out, read, &v.uv, "", "", &v.uv_faces);
  // Parse the output with strtod (correctly rounded): the v values are the
  // values read, bit for bit, and the faces' vertex indices are the input's in order.
  std::ifstream file(out);
  std::string line;
  Index v_lines = 0, f_lines = 0, vt_lines = 0;
  bool v_exact = true, f_same = true;
  while (std::getline(file, line)) {
    if (line.rfind("v ", 0) == 0) {
      const char* c = line.c_str() + 2;
      char* end = nullptr;
      for (int k = 0; k < 3; ++k, c = end)
        v_exact &= std::strtod(c, &end) == read.vertices(v_lines, k);
      ++v_lines;
    } else if (line.rfind("vt ", 0) == 0) {
      ++vt_lines;
    } else if (line.rfind("f ", 0) == 0) {
      std::istringstream in(line.substr(2));
      for (int k = 0; k < 3; ++k) {
        std::string corner;
        in >> corner;
        const int vi = std::stoi(corner.substr(0, corner.find('/'))) - 1;
        const int ti = std::stoi(corner.substr(corner.find('/') + 1)) - 1;
        f_same &= vi == read.faces(f_lines, k) && ti == v.uv_faces(f_lines, k);
      }
      ++f_lines;
    }
  }
  CHECK(v_lines == read.vertices.rows());
  CHECK(v_exact);
  CHECK(f_lines == read.faces.rows());
  CHECK(f_same);
  CHECK(vt_lines == v.uv.rows());
}

TEST_CASE("valid uv: meshes as they come", "[geometry][uv][bad-input]") {
  SECTION("a non-manifold edge (three faces on one edge) is a seam") {
    const UvInput grid = test_uv::flat_grid(4, 4);
    // A fin on the inner diagonal (0, 6) of the first cell: a third face above the plane.
    Block<double> p(1, 3), t(1, 2);
    p << 0.2, 0.0, 0.3;
    t << 0.3, -0.1;
    Faces f(1, 3);
    f << 0, 6, int(grid.positions.rows());
    const UvInput m = append(grid, p, t, f);
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    check_valid(m, v);
    CHECK(v.stats.cut.nonmanifold_edges == 1);
    CHECK(warned(v.stats, "non-manifold"));
  }
  SECTION("a non-manifold vertex (two fans meeting at a point) gets a UV per fan") {
    UvInput m;
    m.positions.resize(5, 3);
    m.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0;
    m.faces.resize(2, 3);
    m.faces << 0, 1, 2, 0, 3, 4;
    m.uv = m.positions.leftCols(2);
    m.uv.row(3) << 1.0, 0.2;  // psi puts the second fan on top of the first
    m.uv.row(4) << 1.0, 1.2;
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    check_valid(m, v);
    CHECK(v.uv_faces(0, 0) != v.uv_faces(1, 0));
    CHECK(v.stats.charts == 2);
  }
  SECTION("several components, each with a hole") {
    UvInput a = test_uv::flat_grid(6, 6), m = a;
    // Punch a hole: drop the 4 faces around the centre vertex (an annulus, not a disk).
    std::vector<int> keep;
    for (Index f = 0; f < a.faces.rows(); ++f) {
      bool centre = false;
      for (int k = 0; k < 3; ++k) centre |= a.faces(f, k) == 3 * 7 + 3;
      if (!centre) keep.push_back(int(f));
    }
    m.faces.resize(Index(keep.size()) * 2, 3);
    m.positions.resize(2 * a.positions.rows(), 3);
    m.uv.resize(2 * a.uv.rows(), 2);
    m.positions << a.positions, (a.positions.rowwise() + Eigen::RowVector3d(5, 0, 0));
    m.uv << a.uv, a.uv;  // the second component right on top of the first in psi
    for (size_t i = 0; i < keep.size(); ++i) {
      m.faces.row(Index(i)) = a.faces.row(keep[i]);
      m.faces.row(Index(i + keep.size())) = a.faces.row(keep[i]).array() + int(a.positions.rows());
    }
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    check_valid(m, v);
    // Each annulus stays one chart, made a disk by one cut from the hole to the
    // outer boundary (a shortest path), not split in pieces.
    CHECK(v.stats.charts == 2);
    CHECK(v.stats.cut.path_cuts == 2);
    CHECK(v.stats.cut.split_charts == 0);
    CHECK(v.stats.cut.boundary_edges > 0);
  }
  SECTION("degenerate faces (a repeated vertex, collinear corners) are skipped with a warning") {
    Faces f(2, 3);
    f << 0, 0, 5,  // a repeated vertex
        0, 1, 2;   // three points on y = 0
    const UvInput m = append(test_uv::flat_grid(3, 3), Block<double>(0, 3), Block<double>(0, 2), f);
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    REQUIRE(v.uv_faces.rows() == m.faces.rows());
    CHECK(v.stats.cut.skipped_faces.size() == 2);
    CHECK(v.face_chart[size_t(m.faces.rows() - 1)] == -1);
    CHECK(warned(v.stats, "degenerate"));
    const UvQuality q = measure_uv_quality(m.positions, m.faces, v.uv, v.uv_faces);
    CHECK(q.flipped == 0);
    CHECK(q.overlap_ratio == 0);
    CHECK(q.degenerate == 2);
  }
  SECTION("inconsistently oriented faces are cut apart and each made counter-clockwise") {
    UvInput m = test_uv::flat_grid(6, 4);
    for (Index f = 0; f < m.faces.rows(); f += 5) std::swap(m.faces(f, 1), m.faces(f, 2));
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    CHECK(v.stats.cut.inconsistent_edges > 0);
    CHECK(warned(v.stats, "inconsistently"));
    // Every face counter-clockwise in UV in its own corner order (the order
    // that defines its 3D normal), whichever way that normal points.
    for (Index f = 0; f < m.faces.rows(); ++f) {
      const Eigen::Vector3d p0 = m.positions.row(m.faces(f, 0)),
                            p1 = m.positions.row(m.faces(f, 1)),
                            p2 = m.positions.row(m.faces(f, 2));
      const double nz = (p1 - p0).cross(p2 - p0).z();
      const Eigen::Vector2d t0 = v.uv.row(v.uv_faces(f, 0)), t1 = v.uv.row(v.uv_faces(f, 1)),
                            t2 = v.uv.row(v.uv_faces(f, 2));
      const double a = (t1 - t0).x() * (t2 - t0).y() - (t1 - t0).y() * (t2 - t0).x();
      CHECK(a > 0);
      CHECK(nz != 0);
    }
    UvQualityOptions qo;
    qo.overlap_resolution = 2048;
    CHECK(measure_uv_quality(m.positions, m.faces, v.uv, v.uv_faces, qo).overlap_ratio == 0);
  }
  SECTION("NaN UVs from psi do not crash: those faces are repaired") {
    UvInput m = test_uv::flat_grid(8, 8);
    m.uv.row(40) << std::nan(""), 0.5;
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    check_valid(m, v);
  }
}
