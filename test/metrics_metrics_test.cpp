// surface_metrics (Table 1's Chamfer columns) on sets whose answer is known by
// construction: a grid against itself, shifted, and with flipped normals.
#include "losses/metrics/metrics.h"

#include <catch2/catch.hpp>
#include <cmath>

using namespace jsa;

namespace {

// An n x n grid on the plane z = 0 with spacing h, normals +z.
void grid(int n, double h, Block<double>& points, Block<double>& normals) {
  points.resize(n * n, 3);
  normals.resize(n * n, 3);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      points.row(i * n + j) << i * h, j * h, 0;
      normals.row(i * n + j) << 0, 0, 1;
    }
}

}  // namespace

TEST_CASE("surface_metrics: identical sets score zero", "[metrics]") {
  Block<double> p, n;
  grid(20, 0.1, p, n);
  const SurfaceMetrics m = surface_metrics(p, n, p, n);
  CHECK(m.chamfer_spatial == 0.0);
  CHECK(m.chamfer_normal == 0.0);
  CHECK(m.back_facing == 0.0);
}

TEST_CASE("surface_metrics: a lift along the normal is the spatial distance", "[metrics]") {
  Block<double> p, n;
  grid(20, 0.1, p, n);
  Block<double> q = p;
  q.col(2).array() += 0.03;  // less than half the spacing: each point's nearest is its twin
  const SurfaceMetrics m = surface_metrics(q, n, p, n);
  CHECK(m.chamfer_spatial == Approx(0.03).epsilon(1e-12));
  CHECK(m.chamfer_normal == 0.0);
}

TEST_CASE("surface_metrics: flipped normals count as back-facing and cost 2 each", "[metrics]") {
  Block<double> p, n;
  grid(20, 0.1, p, n);
  Block<double> flipped = n;
  int count = 0;
  for (Index i = 0; i < p.rows(); i += 4, ++count) flipped(i, 2) = -1;  // every fourth point
  const double fraction = double(count) / double(p.rows());
  const SurfaceMetrics m = surface_metrics(p, flipped, p, n);
  CHECK(m.back_facing == Approx(fraction).epsilon(1e-12));
  CHECK(m.chamfer_normal == Approx(2 * fraction).epsilon(1e-12));
  // A 60-degree tilt is not back-facing: |n_p - n_q| = 1, dot = 0.5.
  Block<double> tilted = n;
  tilted.col(0).setConstant(std::sqrt(3.0) / 2);
  tilted.col(2).setConstant(0.5);
  const SurfaceMetrics t = surface_metrics(p, tilted, p, n);
  CHECK(t.back_facing == 0.0);
  CHECK(t.chamfer_normal == Approx(1.0).epsilon(1e-12));
}
