#include "model/tool/shape_input.h"

#include "io/geometry/builtin_shapes.h"
#include "io/geometry/surface_sampling.h"
#include "io/mesh_io.h"

namespace jsa {

Mesh load_shape(const std::string& spec) {
  const std::string prefix = "builtin:";
  if (spec.rfind(prefix, 0) == 0) return builtin_shape(spec.substr(prefix.size()));
  return read_shape(spec);
}

RunInput load_run_input(const std::string& spec, Index pool_size, uint64_t seed) {
  RunInput in;
  in.mesh = load_shape(spec);
  Rng rng(seed, 2);
  SurfaceSamples s = sample_surface(in.mesh, pool_size, rng);
  in.normalization = normalization_of(s.points);
  in.pool.resize(s.points.rows(), 6);
  in.pool.leftCols(3) = in.normalization.to_unit(s.points);
  in.pool.rightCols(3) = s.normals;
  return in;
}

}  // namespace jsa
