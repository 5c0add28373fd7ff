// UV quality of S: uv -> 3D on shapes whose answers are known by hand: an
// isometric grid and its similar copies, an anisotropic stretch, one flipped
// triangle, stacked copies, a cylinder closed along a seam (torn, or cut with
// duplicated UVs), degenerate triangles; the overlap rasteriser against a naive
// per-pixel oracle and across thread counts.
#include <catch2/catch.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <vector>

#include "engine/check.h"
#include "engine/parallel.h"
#include "engine/rng.h"
#include "losses/metrics/uv_quality.h"

using namespace jsa;

namespace {

struct UvMesh {
  Block<double> positions;  // V x 3
  Faces faces;              // F x 3
  Block<double> uv;         // U x 2
  Faces uv_faces;           // F x 3
};

UvQuality measure(const UvMesh& m, const UvQualityOptions& o = {}) {
  return measure_uv_quality(m.positions, m.faces, m.uv, m.uv_faces, o);
}

// An nx x ny grid of cells over [0, w] x [0, h] in the plane z = 0, each cell
// split along its diagonal into faces 2c and 2c + 1 (c = row * nx + column),
// both counter-clockwise seen from +z; uv = (x, y), per vertex.
UvMesh flat_grid(int nx, int ny, double w = 1, double h = 1) {
  UvMesh m;
  m.positions.resize((nx + 1) * (ny + 1), 3);
  for (int j = 0; j <= ny; ++j) {
    for (int i = 0; i <= nx; ++i) m.positions.row(j * (nx + 1) + i) << w * i / nx, h * j / ny, 0;
  }
  m.faces.resize(2 * nx * ny, 3);
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, b = a + 1, c = b + nx + 1, d = a + nx + 1;
      const int cell = j * nx + i;
      m.faces.row(2 * cell) << a, b, c;
      m.faces.row(2 * cell + 1) << a, c, d;
    }
  }
  m.uv = m.positions.leftCols(2);
  m.uv_faces = m.faces;
  return m;
}

// A cylinder of radius r and height h: n vertices around, m bands of quads, two
// faces per quad, closed in 3D (the last column joins the first). u = angle / 2pi,
// v = z / h. Per-vertex UVs (duplicate_seam = false) make the closing column of
// faces span u from (n-1)/n back to 0, across the whole chart; duplicate_seam
// gives the seam column its own UVs at u = 1, a cut. Seam faces: k = n - 1.
UvMesh cylinder(int n, int m, double r, double h, bool duplicate_seam) {
  const double pi = std::acos(-1.0);
  UvMesh c;
  c.positions.resize(n * (m + 1), 3);
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k < n; ++k) {
      const double angle = 2 * pi * k / n;
      c.positions.row(j * n + k) << r * std::cos(angle), r * std::sin(angle), h * j / m;
    }
  }
  const int columns = duplicate_seam ? n + 1 : n;  // UV columns per ring
  c.uv.resize(columns * (m + 1), 2);
  for (int j = 0; j <= m; ++j) {
    for (int k = 0; k < columns; ++k) c.uv.row(j * columns + k) << double(k) / n, double(j) / m;
  }
  c.faces.resize(2 * n * m, 3);
  c.uv_faces.resize(2 * n * m, 3);
  for (int j = 0; j < m; ++j) {
    for (int k = 0; k < n; ++k) {
      const int f = 2 * (j * n + k);
      const int k1 = (k + 1) % n;
      c.faces.row(f) << j * n + k, j * n + k1, (j + 1) * n + k1;
      c.faces.row(f + 1) << j * n + k, (j + 1) * n + k1, (j + 1) * n + k;
      const int kuv = duplicate_seam ? k + 1 : k1;
      const int a = j * columns + k, b = j * columns + kuv;
      const int cc = (j + 1) * columns + kuv, d = (j + 1) * columns + k;
      c.uv_faces.row(f) << a, b, cc;
      c.uv_faces.row(f + 1) << a, cc, d;
    }
  }
  return c;
}

// Gives face f its own three UV rows (copies of its current ones), so that it
// can be changed without touching its neighbours. Returns the first new row.
int detach_face_uvs(UvMesh& m, int f) {
  const Index first = m.uv.rows();
  m.uv.conservativeResize(first + 3, 2);
  for (int c = 0; c < 3; ++c) {
    m.uv.row(first + c) = m.uv.row(m.uv_faces(f, c));
    m.uv_faces(f, c) = int(first + c);
  }
  return int(first);
}

// Appends one face with the given corner positions and UVs, all new rows.
void add_face(UvMesh& m, const Eigen::Matrix3d& p, const Eigen::Matrix<double, 3, 2>& t) {
  const Index v = m.positions.rows(), u = m.uv.rows(), f = m.faces.rows();
  m.positions.conservativeResize(v + 3, 3);
  m.positions.bottomRows(3) = p;
  m.uv.conservativeResize(u + 3, 2);
  m.uv.bottomRows(3) = t;
  m.faces.conservativeResize(f + 1, 3);
  m.faces.row(f) << int(v), int(v + 1), int(v + 2);
  m.uv_faces.conservativeResize(f + 1, 3);
  m.uv_faces.row(f) << int(u), int(u + 1), int(u + 2);
}

// The mesh twice, disjoint in 3D (second copy lifted by 1 in z), UVs of the
// second copy shifted by `shift`, with their own UV indices.
UvMesh two_copies(const UvMesh& m, const Eigen::RowVector2d& shift) {
  UvMesh d;
  const Index V = m.positions.rows(), U = m.uv.rows(), F = m.faces.rows();
  d.positions.resize(2 * V, 3);
  d.positions << m.positions, m.positions.rowwise() + Eigen::RowVector3d(0, 0, 1);
  d.uv.resize(2 * U, 2);
  d.uv << m.uv, m.uv.rowwise() + shift;
  d.faces.resize(2 * F, 3);
  d.faces << m.faces, m.faces.array() + int(V);
  d.uv_faces.resize(2 * F, 3);
  d.uv_faces << m.uv_faces, m.uv_faces.array() + int(U);
  return d;
}

void require_isometry_numbers(const UvQuality& q) {
  CHECK(q.stretch_l2 == Approx(1).epsilon(1e-12));
  CHECK(q.stretch_linf == Approx(1).epsilon(1e-12));
  CHECK(q.symmetric_dirichlet == Approx(4).epsilon(1e-12));
  CHECK(q.conformal_distortion == Approx(1).epsilon(1e-12));
}

// The obvious overlap ratio: every pixel centre of the same normalised square
// tested against every drawn triangle (closed, by edge-function signs). Agrees
// with the scanline version except on centres exactly on an edge, which random
// coordinates do not hit.
double naive_overlap(const UvMesh& m, int resolution) {
  Eigen::RowVector2d lo = m.uv.colwise().minCoeff(), hi = m.uv.colwise().maxCoeff();
  const double to_pixels = resolution / (hi - lo).maxCoeff();
  long long covered = 0, overlapped = 0;
  for (int j = 0; j < resolution; ++j) {
    for (int i = 0; i < resolution; ++i) {
      const Eigen::Vector2d x(i + 0.5, j + 0.5);
      int hits = 0;
      for (Index f = 0; f < m.uv_faces.rows(); ++f) {
        Eigen::Vector2d c[3];
        for (int k = 0; k < 3; ++k)
          c[k] = ((m.uv.row(m.uv_faces(f, k)) - lo) * to_pixels).transpose();
        double s[3];
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector2d e = c[(k + 1) % 3] - c[k], d = x - c[k];
          s[k] = e.x() * d.y() - e.y() * d.x();
        }
        const bool inside =
            (s[0] >= 0 && s[1] >= 0 && s[2] >= 0) || (s[0] <= 0 && s[1] <= 0 && s[2] <= 0);
        hits += inside;
      }
      covered += hits >= 1;
      overlapped += hits >= 2;
    }
  }
  return double(overlapped) / double(covered);
}

}  // namespace

TEST_CASE("uv quality: an isometric flat grid scores the ideal on every count", "[uv]") {
  const UvMesh m = flat_grid(6, 4, 2.0, 1.0);
  const UvQuality q = measure(m);
  CHECK(q.triangles == 48);
  CHECK(q.area_3d == Approx(2.0));
  CHECK(q.area_uv == Approx(2.0));
  CHECK(q.uv_scale == Approx(1.0));
  CHECK(q.measured == 48);
  CHECK(q.degenerate == 0);
  CHECK(q.torn == 0);
  CHECK(q.torn_faces.empty());
  CHECK(q.flipped == 0);
  CHECK_FALSE(q.mirrored);
  require_isometry_numbers(q);
  CHECK(q.overlap_ratio == 0);
  CHECK(q.seam_length == 0);
  CHECK(q.charts == 1);
  CHECK(q.charts_without_torn == 1);
}

TEST_CASE("uv quality: shared edges through pixel centres are never overlap", "[uv]") {
  // 8 x 8 cells: at resolution 64 the diagonals pass through pixel centres; at 4
  // and 12 the vertical and horizontal edges and some vertices do too.
  const UvMesh m = flat_grid(8, 8);
  for (int resolution : {1, 4, 12, 64, 1000}) {
    UvQualityOptions o;
    o.overlap_resolution = resolution;
    INFO("resolution " << resolution);
    CHECK(measure(m, o).overlap_ratio == 0);
  }
}

TEST_CASE("uv quality: similar copies of the UVs give the same numbers", "[uv]") {
  const UvMesh m = flat_grid(5, 3, 1.5, 1.0);
  const UvQuality ref = measure(m);

  SECTION("scaled, rotated and moved") {
    UvMesh s = m;
    const double a = 0.3;
    Eigen::Matrix2d rot;
    rot << std::cos(a), -std::sin(a), std::sin(a), std::cos(a);
    s.uv = ((3.7 * m.uv) * rot.transpose()).rowwise() + Eigen::RowVector2d(5, -2);
    const UvQuality q = measure(s);
    CHECK(q.area_uv == Approx(3.7 * 3.7 * ref.area_uv));
    CHECK(q.uv_scale == Approx(1 / 3.7));
    CHECK(q.flipped == 0);
    CHECK_FALSE(q.mirrored);
    require_isometry_numbers(q);
    CHECK(q.overlap_ratio == 0);
    CHECK(q.charts == 1);
  }
  SECTION("mirrored: the majority orientation is negative, nothing is flipped") {
    UvMesh s = m;
    s.uv.col(0) *= -0.01;
    s.uv.col(1) *= 0.01;
    const UvQuality q = measure(s);
    CHECK(q.mirrored);
    CHECK(q.flipped == 0);
    CHECK(q.flipped_area_fraction == 0);
    require_isometry_numbers(q);
    CHECK(q.overlap_ratio == 0);
  }
}

TEST_CASE("uv quality: uv = (2x, y) has singular values sqrt2 and 1/sqrt2", "[uv]") {
  // UV area is twice the 3D area, so the UVs are scaled by 1/sqrt2 to
  // (sqrt2 x, y / sqrt2), and S: (s, t) -> (s / sqrt2, sqrt2 t, 0):
  // Gamma = sqrt2, gamma = 1/sqrt2.
  UvMesh m = flat_grid(4, 4);
  m.uv.col(0) *= 2;
  const UvQuality q = measure(m);
  CHECK(q.uv_scale == Approx(1 / std::sqrt(2.0)));
  CHECK(q.stretch_linf == Approx(std::sqrt(2.0)));
  CHECK(q.stretch_l2 == Approx(std::sqrt((2 + 0.5) / 2)));    // sqrt(1.25)
  CHECK(q.symmetric_dirichlet == Approx(2 + 0.5 + 0.5 + 2));  // 5
  CHECK(q.conformal_distortion == Approx(2));
  CHECK(q.flipped == 0);
  CHECK(q.torn == 0);
}

TEST_CASE("uv quality: distortion of random triangles against Sander's formulas and an SVD",
          "[uv]") {
  // Separate random triangles, random UVs. Oracle: Sander et al.'s explicit
  // S_s, S_t (their Eq. 1, with the scaled UVs), then Eigen's SVD of [S_s, S_t],
  // independent of the closed-form eigenvalues the library uses.
  Rng rng(11);
  const int F = 12;
  UvMesh m;
  m.positions.resize(3 * F, 3);
  m.uv.resize(3 * F, 2);
  for (Index i = 0; i < m.positions.size(); ++i) m.positions.data()[i] = rng.uniform(-1, 1);
  for (Index i = 0; i < m.uv.size(); ++i) m.uv.data()[i] = rng.uniform(0, 1);
  m.faces.resize(F, 3);
  for (int f = 0; f < F; ++f) m.faces.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  m.uv_faces = m.faces;
  UvQualityOptions o;
  o.torn_ratio = 1e9;  // judge every triangle, however skewed
  const UvQuality q = measure(m, o);
  REQUIRE(q.measured == F);

  double area3 = 0, area_uv = 0;
  for (int f = 0; f < F; ++f) {
    const Eigen::Vector3d p0 = m.positions.row(3 * f), p1 = m.positions.row(3 * f + 1);
    const Eigen::Vector3d p2 = m.positions.row(3 * f + 2);
    const Eigen::Vector2d e1 = m.uv.row(3 * f + 1) - m.uv.row(3 * f);
    const Eigen::Vector2d e2 = m.uv.row(3 * f + 2) - m.uv.row(3 * f);
    area3 += 0.5 * (p1 - p0).cross(p2 - p0).norm();
    area_uv += 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
  }
  const double k = std::sqrt(area3 / area_uv);
  double l2 = 0, linf = 0, dirichlet = 0, conformal = 0;
  for (int f = 0; f < F; ++f) {
    Eigen::Vector3d p[3];
    double s[3], t[3];
    for (int c = 0; c < 3; ++c) {
      p[c] = m.positions.row(3 * f + c).transpose();
      s[c] = k * m.uv(3 * f + c, 0);
      t[c] = k * m.uv(3 * f + c, 1);
    }
    const double two_a = (s[1] - s[0]) * (t[2] - t[0]) - (s[2] - s[0]) * (t[1] - t[0]);
    const Eigen::Vector3d Ss =
        (p[0] * (t[1] - t[2]) + p[1] * (t[2] - t[0]) + p[2] * (t[0] - t[1])) / two_a;
    const Eigen::Vector3d St =
        (p[0] * (s[2] - s[1]) + p[1] * (s[0] - s[2]) + p[2] * (s[1] - s[0])) / two_a;
    Eigen::Matrix<double, 3, 2> J;
    J << Ss, St;
    const Eigen::Vector2d sv = Eigen::JacobiSVD<Eigen::Matrix<double, 3, 2>>(J).singularValues();
    const double w = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).norm();
    const double G = sv(0), g = sv(1);
    l2 += w * (G * G + g * g) / 2;
    linf = std::max(linf, G);
    dirichlet += w * (G * G + g * g + 1 / (G * G) + 1 / (g * g));
    conformal += w * G / g;
  }
  CHECK(q.stretch_l2 == Approx(std::sqrt(l2 / area3)).epsilon(1e-9));
  CHECK(q.stretch_linf == Approx(linf).epsilon(1e-9));
  CHECK(q.symmetric_dirichlet == Approx(dirichlet / area3).epsilon(1e-9));
  CHECK(q.conformal_distortion == Approx(conformal / area3).epsilon(1e-9));
  CHECK(q.conformal_distortion > 1.2);  // far from conformal: the check is not vacuous

  SECTION("and the same numbers for UVs in other units") {
    UvMesh scaled = m;
    scaled.uv *= 1e-3;
    const UvQuality r = measure(scaled, o);
    CHECK(r.stretch_l2 == Approx(q.stretch_l2).epsilon(1e-9));
    CHECK(r.stretch_linf == Approx(q.stretch_linf).epsilon(1e-9));
    CHECK(r.symmetric_dirichlet == Approx(q.symmetric_dirichlet).epsilon(1e-9));
    CHECK(r.conformal_distortion == Approx(q.conformal_distortion).epsilon(1e-9));
  }
}

TEST_CASE("uv quality: one flipped triangle is found with its share of the area", "[uv]") {
  // Face 2 * (1 * 4 + 1) lies in cell (1, 1), away from the border. Its own UV
  // rows with corners 0 and 1 swapped: same UV footprint, opposite orientation.
  UvMesh m = flat_grid(4, 4);
  const int f = 2 * (1 * 4 + 1);
  const int first = detach_face_uvs(m, f);
  std::swap(m.uv_faces(f, 0), m.uv_faces(f, 1));
  REQUIRE(first == 25);
  const UvQuality q = measure(m);
  CHECK(q.flipped == 1);
  REQUIRE(q.flipped_faces.size() == 1);
  CHECK(q.flipped_faces[0] == f);
  CHECK(q.flipped_area_fraction == Approx(1.0 / 32));  // one of 32 equal triangles
  CHECK_FALSE(q.mirrored);
  CHECK(q.torn == 0);
  CHECK(q.overlap_ratio == 0);  // it still covers its own place only
  // Its three edges are interior in 3D and now cut in UV: legs 1/4, diagonal sqrt2/4.
  CHECK(q.seam_length == Approx(0.25 + 0.25 + std::sqrt(2.0) / 4));
  CHECK(q.charts == 2);
}

TEST_CASE("uv quality: two copies on the same UVs overlap everywhere", "[uv]") {
  const UvMesh m = flat_grid(6, 6);
  SECTION("exactly on top of each other") {
    const UvQuality q = measure(two_copies(m, {0, 0}));
    CHECK(q.overlap_ratio == Approx(1).margin(1e-3));
    CHECK(q.charts == 2);
    CHECK(q.flipped == 0);
    require_isometry_numbers(q);
  }
  SECTION("shifted by half a width: overlap 1/2 of a union of 3/2") {
    UvQualityOptions o;
    o.overlap_resolution = 600;
    const UvQuality q = measure(two_copies(m, {0.5, 0}), o);
    CHECK(q.overlap_ratio == Approx(1.0 / 3).margin(2e-3));
  }
}

TEST_CASE("uv quality: the overlap rasteriser agrees with a per-pixel oracle", "[uv]") {
  // Random triangles, each with its own UVs; the 3D positions are irrelevant
  // to overlap but must not make anything torn, so they copy the UVs.
  Rng rng(7);
  UvMesh m;
  const int F = 25;
  m.uv.resize(3 * F, 2);
  for (Index i = 0; i < m.uv.size(); ++i) m.uv.data()[i] = rng.uniform(0, 1);
  m.positions = Block<double>::Zero(3 * F, 3);
  m.positions.leftCols(2) = m.uv;
  m.faces.resize(F, 3);
  for (int f = 0; f < F; ++f) m.faces.row(f) << 3 * f, 3 * f + 1, 3 * f + 2;
  m.uv_faces = m.faces;
  UvQualityOptions o;
  o.overlap_resolution = 96;
  const UvQuality q = measure(m, o);
  REQUIRE(q.torn == 0);
  const double oracle = naive_overlap(m, o.overlap_resolution);
  INFO("scanline " << q.overlap_ratio << ", oracle " << oracle);
  CHECK(oracle > 0.05);
  CHECK(q.overlap_ratio == Approx(oracle).margin(3e-4));  // about one pixel in 3000

  SECTION("and does not depend on the thread count") {
    const int threads = max_threads();
    o.overlap_resolution = 512;
    set_threads(1);
    const UvQuality one = measure(m, o);
    set_threads(2);
    const UvQuality two = measure(m, o);
    set_threads(threads);
    CHECK(one.overlap_ratio == two.overlap_ratio);
    CHECK(one.stretch_l2 == two.stretch_l2);
    CHECK(one.symmetric_dirichlet == two.symmetric_dirichlet);
  }
}

TEST_CASE("uv quality: a cylinder with per-vertex UVs is torn along its seam", "[uv]") {
  // n = 64 around, m = 4 bands, r = 1, h = 2. After scaling, the closing
  // column's horizontal UV edges are ~ (n-1)/n * 2.5 long against a 3D chord of
  // 2 sin(pi/n) ~ 0.098: a ratio of ~25 > 10. Every other edge has ratio < 2.
  const int n = 64, bands = 4;
  const UvMesh c = cylinder(n, bands, 1.0, 2.0, false);
  const UvQuality q = measure(c);
  std::vector<int> seam_faces;
  for (int j = 0; j < bands; ++j) {
    seam_faces.push_back(2 * (j * n + n - 1));
    seam_faces.push_back(2 * (j * n + n - 1) + 1);
  }
  CHECK(q.torn == 2 * bands);
  CHECK(q.torn_faces == seam_faces);
  CHECK(q.torn_area_fraction == Approx(1.0 / n));  // one column of n equal ones
  CHECK(q.measured == 2 * n * bands - 2 * bands);
  CHECK(q.flipped == 0);  // the seam faces run backwards, but torn ones are not judged
  CHECK(q.seam_length == 0);
  CHECK(q.charts == 1);
  CHECK(q.charts_without_torn == 1);
  CHECK(q.overlap_ratio == 0);  // torn faces would cover the whole chart; they are not drawn

  SECTION("a stricter torn_ratio tears nothing more, a loose one tears nothing") {
    UvQualityOptions o;
    o.torn_ratio = 3;
    CHECK(measure(c, o).torn == 2 * bands);
    o.torn_ratio = 1000;
    const UvQuality loose = measure(c, o);
    CHECK(loose.torn == 0);
    CHECK(loose.flipped == 2 * bands);  // now judged: they run against the majority
    CHECK(loose.overlap_ratio > 0.9);
  }
}

TEST_CASE("uv quality: a cylinder cut along its seam has seam length = height", "[uv]") {
  // Height 2 pi r makes (u, v) = (angle / 2pi, z / h) an isometry up to scale.
  const int n = 48, bands = 5;
  const double radius = 0.5, height = 2 * std::acos(-1.0) * radius;
  const UvQuality q = measure(cylinder(n, bands, radius, height, true));
  CHECK(q.seam_length == Approx(height).epsilon(1e-12));
  CHECK(q.torn == 0);
  CHECK(q.flipped == 0);
  CHECK(q.degenerate == 0);
  CHECK(q.overlap_ratio == 0);
  CHECK(q.charts == 1);
  // The flat quads' chords are a little shorter than the arcs u measures.
  CHECK(q.stretch_l2 == Approx(1).margin(0.01));
}

TEST_CASE("uv quality: degenerate triangles are counted and left out", "[uv]") {
  UvMesh m = flat_grid(4, 4);
  SECTION("zero area on both sides: the rest is still an isometry") {
    Eigen::Matrix3d p;
    p << 0, 0, 1, 1, 0, 1, 0.5, 0, 1;  // collinear
    Eigen::Matrix<double, 3, 2> t;
    t << 0.2, 0.2, 0.8, 0.2, 0.5, 0.2;  // collinear, same lengths
    add_face(m, p, t);
    const UvQuality q = measure(m);
    CHECK(q.degenerate == 1);
    CHECK(q.measured == 32);
    CHECK(q.torn == 0);
    CHECK(q.flipped == 0);
    require_isometry_numbers(q);
  }
  SECTION("a UV triangle collapsed to a point") {
    Eigen::Matrix3d p;
    p << 0, 0, 1, 0.1, 0, 1, 0, 0.1, 1;
    Eigen::Matrix<double, 3, 2> t;
    t << 0.5, 0.5, 0.5, 0.5, 0.5, 0.5;
    add_face(m, p, t);
    const UvQuality q = measure(m);
    CHECK(q.degenerate == 1);
    CHECK(q.measured == 32);
    CHECK(std::isfinite(q.symmetric_dirichlet));
    // The grid keeps its shape; only the global scale moved: Gamma = gamma = 1/uv_scale.
    CHECK(q.stretch_l2 == Approx(1 / q.uv_scale));
    CHECK(q.conformal_distortion == Approx(1));
  }
}

TEST_CASE("uv quality: JSON, text and input errors", "[uv]") {
  const UvMesh m = flat_grid(2, 2);
  const nlohmann::json j = nlohmann::json::parse(to_json(measure(m)));
  CHECK(j.at("triangles") == 8);
  CHECK(j.at("stretch_l2").get<double>() == Approx(1));
  CHECK(j.at("torn_faces").is_array());
  CHECK(j.at("charts") == 1);
  const std::string text = to_text(measure(m));
  CHECK(text.find("uv -> 3D") != std::string::npos);
  CHECK(text.find("stretch L2") != std::string::npos);

  SECTION("nothing measured: distortion is NaN, null in JSON") {
    UvMesh flat = m;
    flat.uv.setZero();
    const UvQuality q = measure(flat);
    CHECK(q.degenerate == 8);
    CHECK(q.measured == 0);
    CHECK(std::isnan(q.stretch_l2));
    CHECK(nlohmann::json::parse(to_json(q)).at("stretch_l2").is_null());
    CHECK(q.overlap_ratio == 0);
  }
  SECTION("bad input names the field") {
    UvMesh bad = m;
    bad.uv_faces(3, 1) = 99;
    CHECK_THROWS_AS(measure(bad), InputError);
    CHECK_THROWS_WITH(measure(bad), Catch::Contains("uv_faces row 3"));
    bad = m;
    bad.uv_faces.conservativeResize(7, 3);
    CHECK_THROWS_WITH(measure(bad), Catch::Contains("uv_faces has 7"));
  }
}
