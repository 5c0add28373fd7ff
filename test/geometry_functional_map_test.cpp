// io/geometry/functional_map: the cotangent Laplacian's spectrum of a sphere
// (4 pi l (l + 1) at unit area, multiplicities 1, 3, 5), an M-orthonormal
// basis, and ZoomOut finding the identity between a strip and the same strip
// folded, from the nearest-in-space map that the fold gets wrong.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/check.h"
#include "io/geometry/builtin_shapes.h"
#include "io/geometry/functional_map.h"
#include "io/geometry/nearest.h"
#include "test/geometry_strip.h"

using jsa::Block;
using jsa::Index;
using test_geometry::strip;

TEST_CASE("the Laplace basis of a sphere has its spectrum and is M-orthonormal",
          "[geometry][functional_map]") {
  const jsa::Mesh sphere = jsa::builtin_shape("sphere", 48);
  const jsa::LaplaceBasis b = jsa::laplace_basis(sphere, 16);
  REQUIRE(b.functions.rows() == sphere.vertices.rows());
  REQUIRE(b.functions.cols() == 16);
  CHECK(std::abs(b.mass.sum() - 1.0) < 1e-12);
  CHECK(std::abs(b.eigenvalues(0)) < 1e-6);
  // Unit area: radius 1 / sqrt(4 pi), lambda_l = 4 pi l (l + 1). The mesh's
  // values approach them from its resolution: within 3% at 48 segments.
  const double pi = 3.14159265358979323846;
  const int l_of[16] = {0, 1, 1, 1, 2, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3};
  for (int j = 1; j < 16; ++j) {
    const double exact = 4 * pi * l_of[j] * (l_of[j] + 1);
    INFO("eigenvalue " << j << ": " << b.eigenvalues(j) << " against " << exact);
    CHECK(std::abs(b.eigenvalues(j) - exact) < 0.03 * exact);
  }
  Eigen::MatrixXd MF = b.functions;
  MF.array().colwise() *= b.mass.array();
  const Eigen::MatrixXd gram = b.functions.transpose() * MF;
  CHECK((gram - Eigen::MatrixXd::Identity(16, 16)).cwiseAbs().maxCoeff() < 1e-8);
  // The same start gives the same basis.
  const jsa::LaplaceBasis again = jsa::laplace_basis(sphere, 16);
  CHECK((again.functions - b.functions).cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("ZoomOut finds the identity between a strip and the strip folded",
          "[geometry][functional_map]") {
  const jsa::Mesh flat = strip(40, 20, false, 0), folded = strip(40, 20, true, 26);
  const jsa::LaplaceBasis a = jsa::laplace_basis(flat, 60), b = jsa::laplace_basis(folded, 60);
  // The same connectivity and edge lengths: the same spectrum.
  CHECK((a.eigenvalues - b.eigenvalues).cwiseAbs().maxCoeff() < 1e-6 * a.eigenvalues.maxCoeff());
  // Start: every vertex of the folded strip to the nearest vertex of the flat
  // one, which sends the folded part onto the crease.
  std::vector<int> start;
  jsa::nearest(folded.vertices, flat.vertices, start);
  // How far, along the strip, each vertex is sent from where it belongs.
  auto mean_error = [&](const std::vector<int>& map) {
    double sum = 0;
    for (size_t v = 0; v < map.size(); ++v)
      sum += (flat.vertices.row(map[v]) - flat.vertices.row(Index(v))).norm();
    return sum / double(map.size());
  };
  const double spacing = 1.0 / 20, before = mean_error(start);
  REQUIRE(before > 2 * spacing);
  jsa::ZoomOutOptions o;
  o.k_start = 4;
  o.k_end = 60;
  o.samples = 400;  // of 861 vertices: the sampled sizes and the full last one
  o.orthogonal = true;
  const double after = mean_error(jsa::zoomout(a, b, start, o));
  INFO("mean error " << before << " before, " << after << " after, grid spacing " << spacing);
  CHECK(after < 0.5 * spacing);
  // Without the orthogonal C the squashed start stays squashed (the reason
  // for ZoomOutOptions::orthogonal): it is no better than a few grid spacings.
  o.orthogonal = false;
  CHECK(mean_error(jsa::zoomout(a, b, start, o)) > 2 * spacing);
}

TEST_CASE("ZoomOut's spatial prior breaks a symmetry the start's way and lets a fold go",
          "[geometry][functional_map]") {
  // The flat strip is symmetric (x -> 2 - x): from a start that is the mirror
  // on most vertices (x < 1.2) and the identity on the rest, plain ZoomOut
  // settles on the mirror; the prior, anchored on the identity, on it.
  const jsa::Mesh flat = strip(40, 20, false, 0);
  const jsa::LaplaceBasis a = jsa::laplace_basis(flat, 40);
  const Index V = flat.vertices.rows();
  Block<double> mirrored = flat.vertices;
  mirrored.col(0) = 2.0 - mirrored.col(0).array();
  std::vector<int> mirror;
  jsa::nearest(mirrored, flat.vertices, mirror);
  std::vector<int> start(static_cast<size_t>(V));
  for (Index v = 0; v < V; ++v)
    start[size_t(v)] = flat.vertices(v, 0) < 1.2 ? mirror[size_t(v)] : int(v);
  auto mean_error = [&](const std::vector<int>& map) {
    double sum = 0;
    for (size_t v = 0; v < map.size(); ++v)
      sum += (flat.vertices.row(map[v]) - flat.vertices.row(Index(v))).norm();
    return sum / double(map.size());
  };
  const double spacing = 1.0 / 20;
  jsa::ZoomOutOptions o;
  o.k_start = 4;
  o.k_end = 40;
  o.samples = 0;
  o.orthogonal = true;
  o.prior_on_target = flat.vertices;  // the anchors: each vertex where it is
  o.prior_on_source = flat.vertices;
  o.prior_weight = 0.3;
  o.prior_until = 20;
  const double with_prior = mean_error(jsa::zoomout(a, a, start, o));
  INFO("mean error from the mixed start " << mean_error(start) << ", with the prior "
                                          << with_prior);
  CHECK(mean_error(start) > 10 * spacing);
  CHECK(with_prior < 0.5 * spacing);
  // Without it, ZoomOut follows the start's majority: the mirror.
  jsa::ZoomOutOptions plain = o;
  plain.prior_weight = 0;
  CHECK(mean_error(jsa::zoomout(a, a, start, plain)) > 10 * spacing);
  // With the anchors on the mirror image instead, the prior settles on the mirror.
  o.prior_on_target = mirrored;
  std::vector<int> mirror_result = jsa::zoomout(a, a, start, o);
  double off_mirror = 0;
  for (Index v = 0; v < V; ++v)
    off_mirror +=
        (flat.vertices.row(mirror_result[size_t(v)]) - mirrored.row(v)).norm() / double(V);
  CHECK(off_mirror < 0.5 * spacing);

  // The prior, only on the first sizes, does not hold a folded part where a
  // nearest-in-space start squashed it (the case of a folded arm): the
  // identity between the strip and the strip folded is still found.
  const jsa::Mesh folded = strip(40, 20, true, 26);
  const jsa::LaplaceBasis b = jsa::laplace_basis(folded, 40);
  std::vector<int> squashed;
  jsa::nearest(folded.vertices, flat.vertices, squashed);
  o.prior_on_target.resize(V, 3);
  for (Index v = 0; v < V; ++v) o.prior_on_target.row(v) = flat.vertices.row(squashed[size_t(v)]);
  o.prior_on_source = flat.vertices;
  const double unfolded = mean_error(jsa::zoomout(a, b, squashed, o));
  INFO("folded strip: " << mean_error(squashed) << " before, " << unfolded << " after");
  CHECK(unfolded < 0.5 * spacing);
}

TEST_CASE("a point cloud has no Laplace basis here", "[geometry][functional_map]") {
  jsa::Mesh cloud;
  cloud.vertices = Block<double>::Random(20, 3);
  CHECK_THROWS_AS(jsa::laplace_basis(cloud, 4), jsa::InputError);
}
