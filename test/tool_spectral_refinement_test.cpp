// The spectral refinement of a correspondence map (model/tool/spectral_refinement.h):
// a map that matches by distance in space, and so sends a folded part of one
// strip onto the crease of the other, comes back as the identity; the
// refined map of a pair is computed once and reused.
#include <catch2/catch.hpp>

#include "engine/check.h"
#include "io/geometry/nearest.h"
#include "model/tool/spectral_refinement.h"
#include "test/geometry_strip.h"

using jsa::Block;
using jsa::Index;

namespace {

// Every shape in its own frame as the unit frame (the strips are made there).
std::vector<jsa::Normalization> identity_frames(size_t n) {
  return std::vector<jsa::Normalization>(n);
}

}  // namespace

TEST_CASE("the spectral refinement turns a nearest-in-space map into the identity",
          "[tool][spectral_refinement]") {
  const std::vector<jsa::Mesh> meshes = {test_geometry::strip(40, 20, false, 0),
                                         test_geometry::strip(40, 20, true, 26)};
  int calls = 0;
  // The base map: the nearest vertex in space, blind to the fold.
  const jsa::CorrespondenceMap base = [&](int, int to, const Block<double>& p,
                                          const Block<double>&) {
    ++calls;
    std::vector<int> nn;
    jsa::nearest(p, meshes[size_t(to)].vertices, nn);
    Block<double> q(p.rows(), 3);
    for (Index m = 0; m < p.rows(); ++m) q.row(m) = meshes[size_t(to)].vertices.row(nn[size_t(m)]);
    return q;
  };
  // Every vertex of the folded strip carried to the flat one; the error is
  // measured along the flat strip, against the vertex of the same index.
  const Block<double>& folded = meshes[1].vertices;
  const Block<double> normals = Block<double>::Zero(folded.rows(), 3);
  auto mean_error = [&](const Block<double>& q) {
    double sum = 0;
    for (Index v = 0; v < q.rows(); ++v) sum += (q.row(v) - meshes[0].vertices.row(v)).norm();
    return sum / double(q.rows());
  };
  const double spacing = 1.0 / 20, before = mean_error(base(1, 0, folded, normals));
  REQUIRE(before > 2 * spacing);

  for (const bool both : {false, true}) {
    jsa::SpectralRefinementOptions o;
    o.functions = 40;
    o.k_start = 4;
    o.k_step = 2;
    o.samples = 400;
    o.both_directions = both;
    const jsa::CorrespondenceMap refined =
        jsa::spectral_refinement(base, meshes, identity_frames(2), o);
    calls = 0;
    const double after = mean_error(refined(1, 0, folded, normals));
    INFO("both directions " << both << ": " << before << " before, " << after << " after");
    CHECK(after < 0.5 * spacing);
    // The pair's map is made once: a second query asks the base only for the
    // images the atlas referee needs (both directions), not for the whole map again.
    const int first = calls;
    CHECK(mean_error(refined(1, 0, folded, normals)) == after);
    CHECK(calls - first == (both ? 1 : 0));
  }
}

TEST_CASE("the spectral refinement refuses a point cloud", "[tool][spectral_refinement]") {
  std::vector<jsa::Mesh> meshes = {test_geometry::strip(4, 2, false, 0), jsa::Mesh{}};
  meshes[1].vertices = meshes[0].vertices;
  const jsa::CorrespondenceMap base = [](int, int, const Block<double>& p, const Block<double>&) {
    return p;
  };
  CHECK_THROWS_AS(jsa::spectral_refinement(base, meshes, identity_frames(2)), jsa::InputError);
}

TEST_CASE("the consensus refuses fewer than three shapes", "[tool][spectral_refinement]") {
  const std::vector<jsa::Mesh> meshes(2, test_geometry::strip(4, 2, false, 0));
  const jsa::CorrespondenceMap base = [](int, int, const Block<double>& p, const Block<double>&) {
    return p;
  };
  jsa::SpectralRefinementOptions o;
  o.functions = 4;
  o.consensus = true;
  CHECK_THROWS_AS(jsa::spectral_refinement(base, meshes, identity_frames(2), o), jsa::InputError);
  o.consensus = false;
  CHECK_NOTHROW(jsa::spectral_refinement(base, meshes, identity_frames(2), o));
}

TEST_CASE("the collection's consensus outvotes one pair's mirrored map",
          "[tool][spectral_refinement]") {
  // Four copies of a strip symmetric under x -> 2 - x. The base map is the
  // identity for every pair but 0 -> 1, which it mirrors; the prior keeps
  // ZoomOut on the base's side of the symmetry, so T_01 stays the mirror.
  const std::vector<jsa::Mesh> meshes(4, test_geometry::strip(40, 20, false, 0));
  const Block<double>& flat = meshes[0].vertices;
  const jsa::CorrespondenceMap base = [&](int from, int to, const Block<double>& p,
                                          const Block<double>&) {
    Block<double> q = p;
    if (from == 0 && to == 1) q.col(0) = 2.0 - q.col(0).array();
    return q;
  };
  const Block<double> normals = Block<double>::Zero(flat.rows(), 3);
  auto mean_error = [&](const Block<double>& q) {  // against the identity
    return (q - flat).rowwise().norm().mean();
  };
  REQUIRE(mean_error(base(0, 1, flat, normals)) > 0.4);
  jsa::SpectralRefinementOptions o;
  o.functions = 30;
  o.k_start = 4;
  o.k_step = 2;
  o.samples = 400;
  o.prior_until = 31;  // the prior on every size: ZoomOut follows the base's side
  // Both directions, the atlas as referee: the inverse of T_10 is the identity,
  // but the atlas's own image is the mirror, so the mirror stays.
  const double referee = mean_error(
      jsa::spectral_refinement(base, meshes, identity_frames(4), o)(0, 1, flat, normals));
  o.consensus = true;
  const jsa::CorrespondenceMap voted =
      jsa::spectral_refinement(base, meshes, identity_frames(4), o);
  // The consensus: the atlas and T_01 say mirror; the inverse of T_10 and the
  // maps through shapes 2 and 3 say identity.
  const double consensus = mean_error(voted(0, 1, flat, normals));
  INFO("referee " << referee << ", consensus " << consensus);
  CHECK(referee > 0.4);
  CHECK(consensus < 0.05);
  // A pair no map got wrong stays right.
  CHECK(mean_error(voted(2, 3, flat, normals)) < 0.05);
}
