// Whether a collection starts from its registration (model/tool/
// registration_check.h): the round trips are the ones written out here by
// hand, copies of one surface (bent, meshed finer) come back near where they
// started and another topology does not, and the registration kept is
// spectral_start's.
#include <catch2/catch.hpp>

#include "engine/check.h"
#include "io/geometry/builtin_shapes.h"
#include "io/geometry/nearest.h"
#include "model/tool/registration_check.h"

using jsa::Block;
using jsa::Index;

namespace {

// The capsule (axis z) flattened in y: no symmetry of revolution for the maps
// to slide along.
jsa::Mesh flat_capsule(int resolution) {
  jsa::Mesh m = jsa::builtin_shape("capsule", resolution);
  m.vertices.col(1) *= 0.6;
  return m;
}

// Mean over a's rows of |a(back(there(v))) - a(v)|, by brute force.
double round_trip(const Block<double>& a, const Block<double>& b) {
  double sum = 0;
  for (Index v = 0; v < a.rows(); ++v) {
    Index there = 0, back = 0;
    (b.rowwise() - a.row(v)).rowwise().squaredNorm().minCoeff(&there);
    (a.rowwise() - b.row(there)).rowwise().squaredNorm().minCoeff(&back);
    sum += (a.row(back) - a.row(v)).norm();
  }
  return sum / double(a.rows());
}

}  // namespace

TEST_CASE("copies of one surface: the round trips are the maps', and short",
          "[tool][registration]") {
  // Shape 1 is shape 0 bent along its axis (x += 0.4 z^2, near isometric for
  // a thin strip of the side, not exactly), shape 2 the same meshed finer.
  std::vector<jsa::Mesh> meshes{flat_capsule(20), flat_capsule(20), flat_capsule(24)};
  for (Index v = 0; v < meshes[1].vertices.rows(); ++v) {
    const double z = meshes[1].vertices(v, 2);
    meshes[1].vertices(v, 0) += 0.4 * z * z;
  }
  const std::vector<jsa::Normalization> frames(3);  // the shapes are made in their unit frames
  jsa::SpectralStartOptions o;
  o.functions = 20;
  const jsa::RegistrationCheck c = jsa::check_registration(meshes, frames, 0, 2.0, o);
  REQUIRE(c.spatial_trip.size() == 3);
  REQUIRE(c.spectral_trip.size() == 3);
  CHECK(c.spatial_trip[0] == 0);  // the template itself
  CHECK(c.spectral_trip[0] == 0);
  for (size_t i = 1; i < 3; ++i)
    CHECK(c.spatial_trip[i] ==
          Approx(round_trip(meshes[0].vertices, meshes[i].vertices)).epsilon(1e-12));
  CHECK(c.spatial == Approx((c.spatial_trip[1] + c.spatial_trip[2]) / 2).epsilon(1e-12));
  CHECK(c.spectral == Approx((c.spectral_trip[1] + c.spectral_trip[2]) / 2).epsilon(1e-12));
  INFO("spectral " << c.spectral << ", spatial " << c.spatial);
  // The same surface meshed finer: the maps invert each other up to the
  // meshes' spacing (measured 0.048 of the unit radius, the bent copy 0.061).
  CHECK(c.spectral_trip[2] < 0.1);
  CHECK(c.spectral_trip[1] < 0.1);
  // The rule itself: trusted exactly when spectral <= ratio * spatial.
  const double ratio = c.spectral / c.spatial;
  CHECK_FALSE(jsa::check_registration(meshes, frames, 0, 0.9 * ratio, o).trusted);
  CHECK(jsa::check_registration(meshes, frames, 0, 1.1 * ratio, o).trusted);
  // The registration kept is spectral_start's from the same template.
  const jsa::SpectralStart again = jsa::spectral_start(meshes, frames, 0, o);
  REQUIRE(c.start.images.size() == 3);
  for (size_t j = 0; j < 3; ++j) CHECK(c.start.images[j] == again.images[j]);
  CHECK(c.start.template_vertices == again.template_vertices);
}

TEST_CASE("maps onto another topology do not come back", "[tool][registration]") {
  // A capsule and a torus: no map between them can be inverted, and the round
  // trip through ZoomOut's lands far away (measured 0.64 of the unit radius,
  // ten times the capsules' above).
  const std::vector<jsa::Mesh> meshes{flat_capsule(20), jsa::builtin_shape("torus", 20)};
  jsa::SpectralStartOptions o;
  o.functions = 20;
  const jsa::RegistrationCheck c =
      jsa::check_registration(meshes, std::vector<jsa::Normalization>(2), 0, 2.0, o);
  CHECK(c.spectral_trip[1] > 0.3);
  CHECK(c.spectral > c.spatial);
}

TEST_CASE("the registration check refuses a point cloud", "[tool][registration]") {
  std::vector<jsa::Mesh> meshes{flat_capsule(16), flat_capsule(16)};
  meshes[1].faces.resize(0, 3);
  const std::vector<jsa::Normalization> frames(2);
  CHECK_THROWS_AS(jsa::check_registration(meshes, frames, 0, 2.0), jsa::InputError);
  // The message names the flag that asked for the spectra.
  CHECK_THROWS_WITH(jsa::check_registration(meshes, frames, 0, 2.0),
                    Catch::Contains("--auto-register needs triangle meshes"));
}
