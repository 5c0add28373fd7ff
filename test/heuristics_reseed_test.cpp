// Moving the Gaussians of back-facing flaps (model/heuristics/reseed.h). The atlas is
// wrapped outward around a sphere; the targets say the lower half faces the
// other way (their normals point inward there), so on the lower half every
// component is "on a flap" and the upper half is the correct surface. The lower
// half's components must move to the upper half's border with it, the others
// must stay, and only the moved means lose their Adam moments.
#include <catch2/catch.hpp>
#include <cmath>

#include "model/heuristics/reseed.h"
#include "model/heuristics/wrap.h"
#include "model/tool/domain_mesh.h"
#include "model/tool/trainer.h"
#include "test/sphere_pool.h"

using namespace jsa;
using test_support::sphere_pool;

namespace {

// z of phi at the K means, in the unit frame.
std::vector<double> heights(Atlas<float>& atlas) {
  const Block<double> mu = atlas.params.value(atlas.domain.means()).cast<double>();
  Block<double> points, normals;
  evaluate_surface(atlas, mu, points, normals);
  std::vector<double> z(size_t(points.rows()));
  for (Index k = 0; k < points.rows(); ++k) z[size_t(k)] = points(k, 2);
  return z;
}

// An atlas with K Gaussians wrapped outward around the unit sphere (model/heuristics/wrap.h),
// and its targets: `samples` points of the sphere, rows [x, alpha n].
struct WrappedSphere {
  WrappedSphere(int gaussians, Index samples, int wrap_steps) : atlas(options(gaussians)) {
    Rng init(7);
    atlas.initialize(init);
    pool = sphere_pool(samples, 8).cast<float>();
    pool.rightCols(3) *= float(atlas.options().alpha);
    Rng wrap_rng(9);
    wrap_initialize(atlas, {pool}, wrap_steps, 1000, 2e-3, wrap_rng);
  }
  static AtlasOptions options(int gaussians) {
    AtlasOptions o;
    o.gaussians = gaussians;
    o.width = 32;
    o.hidden_layers = 3;
    return o;
  }
  Atlas<float> atlas;
  Block<float> pool;
};

}  // namespace

TEST_CASE("reseed_flipped_means: a flipped half's components move to the border of the other half",
          "[reseed]") {
  WrappedSphere sphere(1024, 20000, 800);
  Atlas<float>& atlas = sphere.atlas;
  Block<float>& pool = sphere.pool;
  const int K = atlas.options().gaussians;
  // The lower half's targets face inward.
  for (Index i = 0; i < pool.rows(); ++i)
    if (pool(i, 2) < 0) pool.row(i).rightCols(3) *= -1.0f;

  const std::vector<double> z0 = heights(atlas);
  const std::vector<float> before = atlas.params.values();
  std::vector<float> m(atlas.params.size(), 1.0f), v(atlas.params.size(), 2.0f);
  Rng rng(3);
  const ReseedReport r = reseed_flipped_means(atlas, {pool}, {0}, rng, {&m, &v});
  const std::vector<double> z1 = heights(atlas);
  INFO("moved " << r.flipped << " of " << K << ", back-facing " << r.back_facing);
  // Half the sphere is flipped: about half the components, and of the samples.
  CHECK(r.back_facing > 0.4);
  CHECK(r.back_facing < 0.6);
  CHECK(r.flipped > 400);
  CHECK(r.flipped < 624);

  const auto mu = atlas.params.value(atlas.domain.means());
  const size_t offset = atlas.params.entry(atlas.domain.means()).offset;
  int moved = 0, moved_from_below = 0, stayed_below = 0;
  for (Index k = 0; k < mu.rows(); ++k) {
    const bool same = mu(k, 0) == before[offset + size_t(2 * k)] &&
                      mu(k, 1) == before[offset + size_t(2 * k) + 1];
    const double z_before = z0[size_t(k)], z_after = z1[size_t(k)];
    if (same) {
      // A component well below the equator cannot have stayed.
      if (z_before < -0.2) ++stayed_below;
      CHECK(m[offset + size_t(2 * k)] == 1.0f);
      CHECK(v[offset + size_t(2 * k) + 1] == 2.0f);
    } else {
      ++moved;
      if (z_before < 0) ++moved_from_below;
      // Moved to the correct half's border with the holes: near or above the equator.
      CHECK(z_after > -0.25);
      CHECK(m[offset + size_t(2 * k)] == 0.0f);
      CHECK(m[offset + size_t(2 * k) + 1] == 0.0f);
      CHECK(v[offset + size_t(2 * k)] == 0.0f);
    }
  }
  CHECK(moved == r.flipped);
  CHECK(moved_from_below >= moved * 95 / 100);
  CHECK(stayed_below == 0);
  // Only the means changed: phi and psi are untouched.
  for (size_t i = 0; i < before.size(); ++i)
    if (i < offset || i >= offset + size_t(2 * mu.rows()))
      REQUIRE(atlas.params.values()[i] == before[i]);

  // The moved components sit on the border (about half their samples cross it),
  // so the back-facing fraction of all samples drops from 1/2 to about 1/4.
  Rng again(4);
  std::vector<float> none;
  const ReseedReport second = reseed_flipped_means(atlas, {pool}, {0}, again, {&none});
  INFO("second pass: moved " << second.flipped << ", back-facing " << second.back_facing);
  CHECK(second.back_facing < 0.35);
}

TEST_CASE("reseed_flipped_means: a correct atlas is left alone; the trainer's schedule",
          "[reseed]") {
  WrappedSphere sphere(256, 5000, 600);
  Atlas<float>& atlas = sphere.atlas;
  const Block<float>& pool = sphere.pool;
  const std::vector<float> before = atlas.params.values();
  Rng rng(3);
  const ReseedReport r = reseed_flipped_means(atlas, {pool}, {0}, rng, {});
  CHECK(r.flipped == 0);
  CHECK(atlas.params.values() == before);
  CHECK_THROWS(reseed_flipped_means(atlas, {pool, pool}, {0}, rng, {}));

  // In training: moves happen on the schedule only, seeded (same runs agree).
  FitOptions f;
  f.atlas.gaussians = 64;
  f.atlas.width = 16;
  f.atlas.hidden_layers = 2;
  f.points = 200;
  f.iterations = 40;
  f.reseed_every = 10;
  // The lower half faces inward: a random start's sheet is wrong somewhere.
  Block<double> half_inward = sphere_pool(2000, 11);
  for (Index i = 0; i < half_inward.rows(); ++i)
    if (half_inward(i, 2) < 0) half_inward.row(i).rightCols(3) *= -1.0;
  Trainer a(f, half_inward), b(f, half_inward);
  for (int i = 0; i < 40; ++i) {
    a.step();
    b.step();
  }
  CHECK(a.atlas().params.values() == b.atlas().params.values());
  CHECK(a.reseeded() > 0);
  CHECK(a.reseeded() == b.reseeded());
  f.reseed_every = 0;
  Trainer c(f, half_inward);
  for (int i = 0; i < 40; ++i) c.step();
  CHECK(c.reseeded() == 0);
}
