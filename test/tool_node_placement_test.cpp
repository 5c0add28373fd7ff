// Where a collection's node displacement starts (model/tool/node_placement.h):
// the centres spread over the template's surface, sigma from their spacing,
// and a shape's t_k,i fitted to a registration so that the displaced surface
// follows where the registration sends the template's points.
#include <catch2/catch.hpp>
#include <cmath>

#include "engine/rng.h"
#include "io/geometry/nearest.h"
#include "model/tool/node_placement.h"
#include "test/small_atlas.h"

using jsa::Block;
using jsa::Index;

namespace {

// A collection of three shapes at random networks, with 64 nodes.
jsa::AtlasOptions three_shapes() {
  jsa::AtlasOptions o = test_support::small_atlas(16);
  o.shapes = 3;
  o.code_size = 4;
  o.deform_nodes = 64;
  o.softplus_beta = 10;
  return o;
}

// A smooth registration of the template's "vertices" (points of its
// surface): shape 1 bends the template (a displacement that varies along
// it); shape 2 (below) is a uniform shift, which the normalised kernels
// reproduce wherever the centres fall (unnormalised ones left 24% of it).
Block<float> bent(const Block<float>& v) {
  Block<float> out = v;
  for (Index r = 0; r < v.rows(); ++r) {
    out(r, 0) += 0.3f * std::sin(3.0f * v(r, 1));
    out(r, 2) += 0.2f * v(r, 0) * v(r, 0);
  }
  return out;
}

// The template's "mesh": 2000 points of the atlas's own surface (shape 0),
// and its registration to shapes 1 (bent) and 2 (shifted).
struct Registration {
  Block<float> vertices;
  std::vector<Block<float>> images;
};

Registration registration_of(jsa::Atlas<float>& atlas) {
  jsa::Rng draw(5);
  Block<double> uv, points, normals;
  jsa::sample_reconstruction(atlas, 2000, draw, uv, points, normals, 0);
  Registration r{points.cast<float>(), std::vector<Block<float>>(3)};
  r.images[1] = bent(r.vertices);
  r.images[2] = r.vertices.rowwise() + Eigen::RowVector3f(0.1f, -0.05f, 0.2f);
  return r;
}

}  // namespace

TEST_CASE("node placement: centres, sigma, and a smooth registration reproduced",
          "[node_placement]") {
  jsa::Atlas<float> atlas(three_shapes());
  jsa::Rng init(3);
  atlas.initialize(init);
  const Registration reg = registration_of(atlas);
  const Block<float>& vertices = reg.vertices;
  const std::vector<Block<float>>& images = reg.images;

  const jsa::NodePlacementReport r = jsa::place_nodes(atlas, 0, &vertices, &images);
  REQUIRE(r.target_rms.size() == 3);
  CHECK(r.sigma > 0);
  CHECK(atlas.params.value(atlas.phi.node_sigma())(0, 0) == Approx(r.sigma));
  // Farthest-point centres are distinct domain points.
  const auto centres = atlas.params.value(atlas.phi.node_centres());
  for (int k = 1; k < 64; ++k) CHECK((centres.row(k) - centres.row(0)).norm() > 0);
  // The template's own nodes stay zero; the others take most of their map.
  const auto t = atlas.params.value(atlas.params.find("nodes.phi"));
  CHECK(t.topRows(64).cwiseAbs().maxCoeff() == 0);
  CHECK(r.target_rms[0] == 0);
  for (int i : {1, 2}) {
    INFO("shape " << i << ": registration RMS " << r.target_rms[size_t(i)] << ", left "
                  << r.residual_rms[size_t(i)]);
    CHECK(r.target_rms[size_t(i)] > 0.05);
    CHECK(r.residual_rms[size_t(i)] < 0.05 * r.target_rms[size_t(i)]);
  }
  // The displaced surfaces: at fresh samples, phi_i - phi_0 is the map's
  // displacement of the nearest template point, up to 5% of it.
  jsa::Rng again(9);
  Block<double> uv2, p0, n0;
  jsa::sample_reconstruction(atlas, 500, again, uv2, p0, n0, 0);
  std::vector<int> nearest;
  jsa::NearestIndex<float>(vertices).query(p0.cast<float>(), nearest);
  for (int i : {1, 2}) {
    Block<double> pi, ni;
    jsa::evaluate_surface(atlas, uv2, pi, ni, i);
    double err = 0, size = 0;
    for (Index s = 0; s < uv2.rows(); ++s) {
      const int v = nearest[size_t(s)];
      const Eigen::RowVector3d want = (images[size_t(i)].row(v) - vertices.row(v)).cast<double>();
      err += (pi.row(s) - p0.row(s) - want).squaredNorm();
      size += want.squaredNorm();
    }
    INFO("shape " << i << ": relative RMS " << std::sqrt(err / size));
    CHECK(std::sqrt(err / size) < 0.05);
  }
  // Without a registration the nodes are placed and start at zero.
  jsa::Atlas<float> plain(three_shapes());
  jsa::Rng init2(3);
  plain.initialize(init2);
  const jsa::NodePlacementReport q = jsa::place_nodes(plain, 1, nullptr, nullptr);
  CHECK(q.sigma > 0);
  CHECK(q.fine_sigma == 0);
  CHECK(plain.params.value(plain.params.find("nodes.phi")).cwiseAbs().maxCoeff() == 0);
}

TEST_CASE("node placement: a second field starts from zero next to a registration",
          "[node_placement]") {
  // Two fields (AtlasOptions::fine_nodes): the first fitted to the
  // registration exactly as without the second, the second placed with its
  // own count and width and started from zero.
  jsa::AtlasOptions o = three_shapes();
  jsa::Atlas<float> one(o);
  o.fine_nodes = 100;
  jsa::Atlas<float> two(o);
  jsa::Rng init(3), init2(3);
  one.initialize(init);
  two.initialize(init2);
  REQUIRE(two.phi.has_nodes(1));
  REQUIRE(!one.phi.has_nodes(1));
  const Registration reg = registration_of(one);
  const Block<float>& vertices = reg.vertices;
  const std::vector<Block<float>>& images = reg.images;
  jsa::NodePlacementOptions wide;
  wide.fine_width = 3;
  const jsa::NodePlacementReport r1 = jsa::place_nodes(one, 0, &vertices, &images, wide);
  jsa::NodePlacementOptions narrow = wide;
  narrow.fine_width = 0.5;
  const jsa::NodePlacementReport r2 = jsa::place_nodes(two, 0, &vertices, &images, narrow);
  // The first field does not see the second.
  CHECK(r2.sigma == r1.sigma);
  CHECK(two.params.value(two.params.find("nodes.phi")) ==
        one.params.value(one.params.find("nodes.phi")));
  // The second: its width, 100 distinct centres, zero displacements.
  REQUIRE(r2.fine_sigma > 0);
  CHECK(two.params.value(two.phi.node_sigma(1))(0, 0) == Approx(r2.fine_sigma));
  const auto fine_centres = two.params.value(two.phi.node_centres(1));
  REQUIRE(fine_centres.rows() == 100);
  for (int k = 1; k < 100; ++k) CHECK((fine_centres.row(k) - fine_centres.row(0)).norm() > 0);
  CHECK(two.params.value(two.params.find("nodes.fine.phi")).cwiseAbs().maxCoeff() == 0);
  // More centres sit closer: at the same width factor the second field is
  // narrower than the first (64 centres), here by the factors' ratio too.
  CHECK(r2.fine_sigma < 0.5 * r2.sigma);
  // The surfaces of the two atlases agree (a zero field moves nothing).
  jsa::Rng again(9);
  Block<double> uv2, p0, n0;
  jsa::sample_reconstruction(one, 300, again, uv2, p0, n0, 0);
  for (int i : {0, 1, 2}) {
    Block<double> a, na, b, nb;
    jsa::evaluate_surface(one, uv2, a, na, i);
    jsa::evaluate_surface(two, uv2, b, nb, i);
    CHECK((a - b).cwiseAbs().maxCoeff() < 1e-5);
  }
}
