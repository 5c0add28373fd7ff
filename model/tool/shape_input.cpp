#include "model/tool/shape_input.h"

#include <algorithm>

#include "io/geometry/builtin_shapes.h"
#include "io/geometry/nearest.h"
#include "io/geometry/surface_sampling.h"
#include "io/mesh_io.h"
#include "losses/chamfer.h"

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

Eigen::Matrix3d reference_frame(RunInput& reference) {
  set_rotation(reference, Eigen::Matrix3d::Identity());
  const Eigen::Matrix3d r = canonical_rotation(
      reference.pool.topLeftCorner(std::min<Index>(reference.pool.rows(), 20000), 3));
  set_rotation(reference, r);
  return r;
}

RigidAlignment align_to_reference(RunInput& input, const RunInput& reference,
                                  const RigidAlignOptions& options) {
  // The input's own pose, as far as the file tells: its pose relative to the
  // reference's file, which the reference's frame turns along with it.
  const Eigen::Matrix3d frame = reference.normalization.rotation;
  set_rotation(input, frame);
  RigidAlignment a = rigid_align(input.pool.leftCols(3), reference.pool.leftCols(3), options);
  a.rotation = frame * a.rotation;
  for (Eigen::Matrix3d& r : a.near_poses) r = frame * r;
  set_rotation(input, a.rotation);
  return a;
}

namespace {

// The symmetric Chamfer distance (mean squared, both ways) of two point sets.
double symmetric_chamfer(const Block<double>& a, const Block<double>& b) {
  return chamfer_distance(a, b);
}

Block<double> first_points(const Block<double>& pool, Index samples) {
  return pool.topLeftCorner(std::min(samples, pool.rows()), 3);
}

}  // namespace

void settle_near_ties(std::vector<RunInput>& inputs, std::vector<RigidAlignment>& poses,
                      Index samples) {
  const size_t n = inputs.size();
  for (size_t i = 1; i < n; ++i) poses[i].near_collection.assign(poses[i].near_poses.size(), 0.0);
  for (int round = 0; round < 3; ++round) {
    bool changed = false;
    for (size_t i = 1; i < n; ++i) {
      RigidAlignment& a = poses[i];
      if (a.near_poses.size() < 2 || a.kept_input) continue;  // a file's own pose is trusted
      // Shape i's points in each near pose: its pool turned from the current pose.
      const Block<double> here = first_points(inputs[i].pool, samples);
      size_t pick = 0;
      for (size_t k = 0; k < a.near_poses.size(); ++k) {
        const Block<double> p =
            here * (inputs[i].normalization.rotation.transpose() * a.near_poses[k]);
        double sum = 0;
        for (size_t j = 0; j < n; ++j)
          if (j != i) sum += symmetric_chamfer(p, first_points(inputs[j].pool, samples));
        a.near_collection[k] = sum / double(n - 1);
        if (a.near_collection[k] < a.near_collection[pick]) pick = k;
      }
      if (rotation_angle_degrees(a.near_poses[pick].transpose() * a.rotation) > 10) {
        a.rotation = a.near_poses[pick];
        a.chamfer = a.near_chamfers[pick];
        set_rotation(inputs[i], a.rotation);
        changed = true;
      }
    }
    if (!changed) break;
  }
}

std::vector<RigidAlignment> align_to_first(std::vector<RunInput>& inputs,
                                           const RigidAlignOptions& options) {
  std::vector<RigidAlignment> out(inputs.size());
  if (inputs.empty()) return out;
  out[0].rotation = reference_frame(inputs[0]);
  for (size_t i = 1; i < inputs.size(); ++i)
    out[i] = align_to_reference(inputs[i], inputs[0], options);
  if (inputs.size() > 2) settle_near_ties(inputs, out);
  return out;
}

MedoidChoice medoid_shape(const std::vector<Block<double>>& pools, Index samples) {
  const size_t n = pools.size();
  MedoidChoice c;
  c.sums.assign(n, 0.0);
  if (n < 2) return c;
  std::vector<Block<double>> points(n);
  for (size_t i = 0; i < n; ++i) {
    const Index rows = std::min<Index>(samples, pools[i].rows());
    points[i] = pools[i].topLeftCorner(rows, 3);
  }
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j) {
      const double d = symmetric_chamfer(points[i], points[j]);
      c.sums[i] += d;
      c.sums[j] += d;
    }
  for (size_t i = 1; i < n; ++i)
    if (c.sums[i] < c.sums[size_t(c.shape)]) c.shape = int(i);
  return c;
}

}  // namespace jsa
