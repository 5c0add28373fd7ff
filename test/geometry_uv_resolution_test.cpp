// The valid-UV pipeline at finer resolutions of the same surface and map: the
// repair works in surface distance, torn edges that end inside a chart are
// closed, and a chart whose flattening overlaps itself hands its map to its
// halves, so the chart count follows the map, not the triangle count
// (docs/uv-quality.md, "Time"). Also: the sparse solver and Tutte's mean value
// weights.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/geometry/sparse_spd.h"
#include "io/geometry/uv_align.h"
#include "io/geometry/uv_cut.h"
#include "io/geometry/uv_injectivity.h"
#include "io/geometry/uv_tutte.h"
#include "io/geometry/valid_uv.h"
#include "test/geometry_uv_meshes.h"

using namespace jsa;
using test_uv::UvInput;

TEST_CASE("valid uv: a sphere projected flat gets the same charts at 4x and 16x the triangles",
          "[geometry][uv]") {
  std::vector<Index> charts;
  for (int n : {24, 48, 96}) {
    const UvInput m = test_uv::sphere(n, n / 2);
    const ValidUv v = make_valid_uv(m.positions, m.faces, m.uv);
    charts.push_back(v.stats.charts);
    WARN("sphere " << n << " x " << n / 2 << ": " << v.stats.charts << " charts");
  }
  CHECK(charts[1] <= charts[0] + 1);
  CHECK(charts[2] <= charts[0] + 1);
}

TEST_CASE(
    "valid uv: torn edges that end inside a chart are glued back, so its boundary stays simple",
    "[geometry][uv]") {
  // One inner vertex of a flat grid thrown far off in psi: its six edges tear
  // (a star of slits, each ending at an inner vertex), its faces are unusable.
  UvInput m = test_uv::flat_grid(12, 12);
  const int v = 6 * 13 + 6;
  m.uv.row(v) << 5, 5;
  const CutResult cut = cut_charts(m.positions, m.faces, m.uv);
  CHECK(cut.torn_edges == 6);
  CHECK(cut.slits_closed == 6);
  REQUIRE(cut.charts.size() == 1);
  CHECK(chart_topology(cut.charts[0]).is_disk());
  // One local vertex per input vertex: no slit left open.
  CHECK(cut.charts[0].vertex.size() == size_t(m.positions.rows()));
  const ValidUv valid = make_valid_uv(m.positions, m.faces, m.uv);
  CHECK(valid.stats.charts == 1);
  CHECK(valid.uv.rows() == m.positions.rows());
  CHECK(valid.stats.energy_end < 4.01);  // the plane flattens isometrically
}

TEST_CASE("tutte: mean value weights reproduce a planar disk up to a similarity",
          "[geometry][uv]") {
  // Floater's mean value weights have linear precision: a flat disk whose
  // boundary is already a regular polygon (so the circle placement is a
  // similarity of it) comes back as itself, up to that similarity, however
  // irregular the inside. Uniform weights would pull every inner vertex to the
  // average of its neighbours instead.
  const int N = 24, R = 6;
  Block<double> p(1 + N * R, 3);
  p.row(0) << 0, 0, 0;
  auto id = [&](int k, int j) { return 1 + (k - 1) * N + ((j % N) + N) % N; };
  for (int k = 1; k <= R; ++k)
    for (int j = 0; j < N; ++j) {
      const double r = std::pow(double(k) / R, 1.5);
      const double a = 2 * M_PI * (j + (k < R ? 0.3 * k : 0.0)) / N;
      p.row(id(k, j)) << r * std::cos(a), r * std::sin(a), 0;
    }
  std::vector<Eigen::Vector3i> f;
  for (int j = 0; j < N; ++j) f.push_back({0, id(1, j), id(1, j + 1)});
  for (int k = 1; k < R; ++k)
    for (int j = 0; j < N; ++j) {
      f.push_back({id(k, j), id(k + 1, j), id(k + 1, j + 1)});
      f.push_back({id(k, j), id(k + 1, j + 1), id(k, j + 1)});
    }
  Faces faces(Index(f.size()), 3);
  for (size_t i = 0; i < f.size(); ++i) faces.row(Index(i)) = f[i].transpose();
  const Block<double> uv = tutte_embedding(p, faces);
  CHECK(count_inverted(faces, uv) == 0);
  const Block<double> flat = p.leftCols(2);
  const Block<double> back = fit_similarity(flat, uv).apply(flat);
  CHECK((back - uv).cwiseAbs().maxCoeff() < 1e-9);
}

TEST_CASE("sparse spd solver: solves a positive definite system, refuses an indefinite one",
          "[geometry][uv]") {
  // A path-graph Laplacian plus the identity: positive definite.
  const int n = 50;
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.push_back({i, i, 3.0});
    if (i + 1 < n) t.push_back({i, i + 1, -1.0}), t.push_back({i + 1, i, -1.0});
  }
  Eigen::SparseMatrix<double> A(n, n);
  A.setFromTriplets(t.begin(), t.end());
  Eigen::MatrixXd b(n, 2);
  for (int i = 0; i < n; ++i) b(i, 0) = std::sin(i), b(i, 1) = i % 3;
  SpdSolver once, many(SpdSolver::Use::many);
  REQUIRE(once.compute(A));
  many.analyze(A);
  REQUIRE(many.factorize(A));
  CHECK((A * once.solve(b) - b).norm() < 1e-10 * b.norm());
  CHECK((A * many.solve(b) - b).norm() < 1e-10 * b.norm());
  // The same pattern with a negative pivot is refused.
  Eigen::SparseMatrix<double> C = A;
  C.coeffRef(n / 2, n / 2) = -5;
  SpdSolver c;
  CHECK_FALSE(c.compute(C));
  CHECK(std::string(SpdSolver::backend()).size() > 0);
}
