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
  in.pool.rightCols(3) = in.normalization.normals_to_unit(s.normals);
  return in;
}

void set_rotation(RunInput& input, const Eigen::Matrix3d& rotation) {
  // Undo the rotation the pool has, then apply the new one.
  const Eigen::Matrix3d change = input.normalization.rotation.transpose() * rotation;
  input.pool.leftCols(3) = (input.pool.leftCols(3) * change).eval();
  input.pool.rightCols(3) = (input.pool.rightCols(3) * change).eval();
  input.normalization.rotation = rotation;
}

std::vector<RigidAlignment> align_to_first(std::vector<RunInput>& inputs,
                                           const RigidAlignOptions& options) {
  std::vector<RigidAlignment> out(inputs.size());
  if (inputs.empty()) return out;
  for (size_t i = 1; i < inputs.size(); ++i) {
    set_rotation(inputs[i], Eigen::Matrix3d::Identity());
    out[i] = rigid_align(inputs[i].pool.leftCols(3), inputs[0].pool.leftCols(3), options);
    set_rotation(inputs[i], out[i].rotation);
  }
  return out;
}

}  // namespace jsa
