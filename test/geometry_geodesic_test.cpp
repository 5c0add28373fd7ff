// Shortest paths along a mesh's edges (io/geometry/geodesic.h): their lengths
// on a grid in closed form, unchanged when the grid is folded along a grid
// line, and the farthest-point choice of sources.
#include <catch2/catch.hpp>
#include <cmath>

#include "io/geometry/geodesic.h"
#include "test/geometry_strip.h"

TEST_CASE("geodesic: shortest paths along a strip's edges, flat and folded",
          "[geometry][geodesic]") {
  const int nx = 12, ny = 5;
  const double side = 1.0 / ny;
  const jsa::Mesh flat = test_geometry::strip(nx, ny, false, 0);
  const jsa::Mesh folded = test_geometry::strip(nx, ny, true, 7);
  const jsa::EdgeGraph g = jsa::edge_graph(flat.vertices, jsa::face_edges(flat));
  const jsa::EdgeGraph h = jsa::edge_graph(folded.vertices, jsa::face_edges(folded));
  REQUIRE(g.size() == flat.vertices.rows());
  std::vector<double> d, e;
  jsa::distances_from(g, 0, d);
  jsa::distances_from(h, 0, e);
  // Vertex (i, j) is i * (ny + 1) + j; every square has the diagonal (i, j) -
  // (i + 1, j + 1), so the path takes min(i, j) diagonals and |i - j| sides.
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j) {
      const size_t v = size_t(i * (ny + 1) + j);
      const double expected = (std::min(i, j) * std::sqrt(2.0) + std::abs(i - j)) * side;
      CHECK(d[v] == Approx(expected).margin(1e-12));
      CHECK(e[v] == Approx(d[v]).margin(1e-12));  // a fold keeps every edge's length
    }
  CHECK(jsa::surface_area(flat) == Approx(double(nx) / ny).epsilon(1e-12));
  CHECK(jsa::surface_area(folded) == Approx(double(nx) / ny).epsilon(1e-12));
}

TEST_CASE("geodesic: farthest points along the surface", "[geometry][geodesic]") {
  const int nx = 12, ny = 5;
  const jsa::Mesh flat = test_geometry::strip(nx, ny, false, 0);
  const jsa::EdgeGraph g = jsa::edge_graph(flat.vertices, jsa::face_edges(flat));
  std::vector<std::vector<double>> from;
  const std::vector<int> chosen = jsa::farthest_nodes(g, 3, from);
  REQUIRE(chosen.size() == 3);
  REQUIRE(from.size() == 3);
  // The first is the far corner from vertex 0 (12, 5); the second the vertex
  // farthest from it, the corner (0, 0) itself.
  CHECK(chosen[0] == nx * (ny + 1) + ny);
  CHECK(chosen[1] == 0);
  // Each row of distances is that of its source, and the third source is the
  // vertex whose nearer distance to the first two is largest.
  std::vector<double> d;
  double best = -1;
  for (int k = 0; k < 3; ++k) {
    jsa::distances_from(g, chosen[size_t(k)], d);
    CHECK(d == from[size_t(k)]);
  }
  int argmax = -1;
  for (jsa::Index v = 0; v < g.size(); ++v) {
    const double nearer = std::min(from[0][size_t(v)], from[1][size_t(v)]);
    if (nearer > best) {
      best = nearer;
      argmax = int(v);
    }
  }
  CHECK(chosen[2] == argmax);
  // More sources than nodes: every node once.
  CHECK(jsa::farthest_nodes(g, 1000, from).size() == size_t(g.size()));
}
