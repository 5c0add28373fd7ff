// Atlas::mirror_domain: the same surface, normals flipped, charts swapped.
#include <catch2/catch.hpp>

#include "engine/ops.h"
#include "model/atlas.h"

using namespace jsa;

TEST_CASE("atlas: mirroring the domain keeps every surface point and flips every normal", "[atlas]") {
  AtlasOptions o;
  o.gaussians = 64;
  o.width = 16;
  o.hidden_layers = 3;
  Atlas<double> atlas(o);
  Rng rng(4);
  atlas.initialize(rng);
  Block<double> x(50, 2), x6(50, 6);
  for (Index i = 0; i < x.size(); ++i) x.data()[i] = rng.uniform();
  for (Index i = 0; i < x6.size(); ++i) x6.data()[i] = rng.normal();
  Block<double> swapped = x;
  swapped.col(0).swap(swapped.col(1));

  Tape<double> t;
  SurfacePoints before = atlas.phi.evaluate(t, atlas.params, t.constant(x), true);
  const Block<double> p0 = t.value(before.points), n0 = t.value(before.normals);
  const Block<double> u0 = t.value(atlas.psi.evaluate(t, atlas.params, t.constant(x6)));
  const Block<double> mu0 = atlas.params.value(atlas.domain.means());

  atlas.mirror_domain(atlas.params.values());
  t.clear();
  SurfacePoints after = atlas.phi.evaluate(t, atlas.params, t.constant(swapped), true);
  CHECK((t.value(after.points) - p0).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((t.value(after.normals) + n0).cwiseAbs().maxCoeff() < 1e-12);
  const Block<double> u1 = t.value(atlas.psi.evaluate(t, atlas.params, t.constant(x6)));
  CHECK((u1.col(0) - u0.col(1)).cwiseAbs().maxCoeff() < 1e-12);
  CHECK((u1.col(1) - u0.col(0)).cwiseAbs().maxCoeff() < 1e-12);
  const Block<double> mu1 = atlas.params.value(atlas.domain.means());
  CHECK(mu1.col(0) == mu0.col(1));
  CHECK(mu1.col(1) == mu0.col(0));
  // Twice is the identity.
  std::vector<double> values = atlas.params.values();
  atlas.mirror_domain(values);
  atlas.mirror_domain(values);
  CHECK(values == atlas.params.values());
}
