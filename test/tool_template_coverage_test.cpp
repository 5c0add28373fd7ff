// The template of a registered collection (model/tool/template_coverage.h): a
// shape that lacks surface the others have cannot cover them, whatever its
// index; the winner's maps are spectral_start's for it.
#include <catch2/catch.hpp>

#include "engine/check.h"
#include "engine/rng.h"
#include "io/geometry/builtin_shapes.h"
#include "io/geometry/surface_sampling.h"
#include "model/tool/template_coverage.h"

using jsa::Block;
using jsa::Index;

namespace {

// The capsule (axis z, radius 0.5) without the faces of a window in half of
// its side: the others' window has no counterpart on it.
jsa::Mesh capsule_with_window() {
  const jsa::Mesh full = jsa::builtin_shape("capsule", 24);
  std::vector<int> keep, index(size_t(full.vertices.rows()), -1);
  for (Index f = 0; f < full.faces.rows(); ++f) {
    Eigen::RowVector3d c = Eigen::RowVector3d::Zero();
    for (int k = 0; k < 3; ++k) c += full.vertices.row(full.faces(f, k)) / 3;
    if (!(c(0) > 0.1 && std::abs(c(2)) < 0.45)) keep.push_back(int(f));
  }
  jsa::Mesh m;
  m.faces.resize(Index(keep.size()), 3);
  int used = 0;
  for (size_t r = 0; r < keep.size(); ++r)
    for (int k = 0; k < 3; ++k) {
      int& v = index[size_t(full.faces(keep[r], k))];
      if (v < 0) v = used++;
      m.faces(Index(r), k) = v;
    }
  m.vertices.resize(used, 3);
  m.normals.resize(used, 3);
  for (size_t v = 0; v < index.size(); ++v)
    if (index[v] >= 0) {
      m.vertices.row(index[v]) = full.vertices.row(Index(v));
      m.normals.row(index[v]) = full.normals.row(Index(v));
    }
  return m;
}

}  // namespace

TEST_CASE("the template whose registration covers the others: not the one with a hole",
          "[tool][template_coverage]") {
  std::vector<jsa::Mesh> meshes{capsule_with_window(), jsa::builtin_shape("capsule", 24),
                                jsa::builtin_shape("capsule", 20)};
  // Flattened (no symmetry of revolution for the maps to slide along); the
  // third longer and meshed differently.
  for (jsa::Mesh& m : meshes) m.vertices.col(1) *= 0.6;
  meshes[2].vertices.col(2) *= 1.1;
  REQUIRE(meshes[0].vertices.rows() < meshes[1].vertices.rows());
  const std::vector<jsa::Normalization> frames(3);  // the shapes are made in their unit frames
  std::vector<Block<double>> pools;
  jsa::Rng rng(7);
  for (const jsa::Mesh& m : meshes) pools.push_back(jsa::sample_surface(m, 3000, rng).points);
  jsa::SpectralStartOptions o;
  o.functions = 20;
  const jsa::CoverageChoice c = jsa::template_by_coverage(meshes, frames, pools, o, 3000);
  REQUIRE(c.sums.size() == 3);
  // Between whole capsules a sample lies a few hundredths from the nearest
  // image (the samples' spacing and the maps' error); the window, a fifth of
  // the surface, adds its depth to every sample in it. Measured: 0.178
  // against 0.129 and 0.139.
  CHECK(c.sums[0] > 1.2 * c.sums[1]);
  CHECK(c.sums[0] > 1.2 * c.sums[2]);
  CHECK(c.shape != 0);
  // The winner's maps are the registration spectral_start gives for it.
  const jsa::SpectralStart again = jsa::spectral_start(meshes, frames, c.shape, o);
  REQUIRE(c.start.images.size() == 3);
  CHECK(c.start.images[size_t(c.shape)].rows() == 0);
  for (size_t j = 0; j < 3; ++j) CHECK(c.start.images[j] == again.images[j]);
  CHECK(c.start.template_vertices == again.template_vertices);
}

TEST_CASE("the coverage choice refuses a point cloud", "[tool][template_coverage]") {
  std::vector<jsa::Mesh> meshes{jsa::builtin_shape("capsule", 16),
                                jsa::builtin_shape("capsule", 16)};
  meshes[1].faces.resize(0, 3);
  const std::vector<jsa::Normalization> frames(2);
  std::vector<Block<double>> pools(2, Block<double>::Random(100, 3));
  CHECK_THROWS_AS(jsa::template_by_coverage(meshes, frames, pools), jsa::InputError);
  CHECK_THROWS_WITH(jsa::template_by_coverage(meshes, frames, pools),
                    Catch::Contains("--template-coverage needs triangle meshes"));
}
