// Built against an installed jsatlas (find_package, jsatlas::model and
// jsatlas::io): makes a small atlas, evaluates phi and its normals at a few
// domain points, and reads back a mesh it wrote, so the link line needs the
// private readers of jsatlas::io too. Prints "consumer ok" and exits 0 when every number is finite.
#include <cstdio>
#include <exception>

#include "io/geometry/builtin_shapes.h"
#include "io/mesh_io.h"
#include "losses/chamfer.h"
#include "model/atlas.h"

int main(int argc, char** argv) try {
  jsa::AtlasOptions options;
  options.gaussians = 64;
  options.width = 16;
  options.hidden_layers = 2;
  jsa::Atlas<float> atlas(options);
  jsa::Rng rng(1);
  atlas.initialize(rng);

  jsa::Tape<float> tape;
  const jsa::Var x = atlas.domain.sample(tape, atlas.params, 5, rng);  // 5 x 2 points of P
  const jsa::SurfacePoints s = atlas.phi.evaluate(tape, atlas.params, x, /*with_jacobian=*/true);
  const jsa::Block<float>& phi6 = tape.value(s.phi6);  // 5 x 6 [phi(x), n]
  for (jsa::Index i = 0; i < phi6.rows(); ++i)
    std::printf("phi(% .3f, % .3f) = (% .4f % .4f % .4f)\n", tape.value(x)(i, 0),
                tape.value(x)(i, 1), phi6(i, 0), phi6(i, 1), phi6(i, 2));

  const std::string path = argc > 1 ? argv[1] : "consumer_cube.obj";
  const jsa::Mesh cube = jsa::builtin_shape("cube", 8);
  jsa::write_obj(path, cube);
  const jsa::Mesh back = jsa::read_shape(path);
  const double cd = jsa::chamfer_distance(cube.vertices, back.vertices);
  std::printf("cube: %lld vertices written and read back, Chamfer %.2e\n",
              static_cast<long long>(back.vertices.rows()), cd);

  const bool ok = phi6.allFinite() && back.vertices.rows() == cube.vertices.rows() && cd < 1e-10;
  std::printf("%s\n", ok ? "consumer ok" : "consumer FAILED");
  return ok ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "consumer: %s\n", e.what());
  return 1;
}
