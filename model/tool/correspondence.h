// Correspondences through a joint atlas (paper Sec. 4, "Correspondence metric"):
// a point p on shape I goes to q = phi_J(psi_I(p)) on shape J. Runs without a
// chart (ablation rows 6-9) use the paper's nearest-sample rule instead: sample
// P, map the samples to shape I by phi_I, take the one whose image is nearest
// to p, and map that 2D point by phi_J.
#pragma once
#include <functional>
#include <vector>

#include "io/geometry/mesh.h"
#include "io/geometry/normalization.h"
#include "model/atlas.h"

namespace jsa {

struct CorrespondenceOptions {
  bool use_chart = true;          // false: the nearest-sample rule (no psi)
  Index nearest_samples = 20000;  // samples of P for the nearest-sample rule
  uint64_t seed = 0;
  // Chart rule: damped Gauss-Newton steps that move u = psi_I(p) to the nearest
  // point of phi_I(u) to p before mapping by phi_J (0: psi alone, the paper's rule).
  // psi is trained to invert phi; these steps finish the inversion it has not
  // reached (beyond the paper; docs/collections.md).
  int refine_steps = 0;
};

// p_unit: N x 3 points and n: N x 3 unit normals on shape `from`, in its unit
// frame. Returns N x 3 points on shape `to`, in its unit frame.
Block<double> correspond(Atlas<float>& atlas, int from, int to, const Block<double>& p_unit,
                         const Block<double>& normals, const CorrespondenceOptions& o);

// Vertex normals of a mesh: from the file, or area-weighted from the faces.
Block<double> vertex_normals_of(const Mesh& mesh);

struct KeypointError {
  double mean = 0;  // mean |q - q_gt| over all ordered pairs, unit frame of the target
  // mean |q - q_gt|^2, the same pairs: the paper's "L2" (Sec. 4.2) is written
  // as a mean distance, but its Table 1 does not state units, and a mean
  // squared distance is the other common reading (docs/collections.md).
  double mean_squared = 0;
  std::vector<double> within;  // fraction of keypoints within each threshold
  std::vector<double> thresholds;
  Index pairs = 0, keypoints = 0;
  // [I][J] mean error; on the diagonal the self-map's, I's keypoints carried
  // to I itself, which no consistency between shapes can remove: phi_I's
  // reconstruction at the keypoints and (chart rule) psi_I's inversion of it.
  std::vector<std::vector<double>> pair_mean;
  double self_mean = 0;               // the diagonal's mean (not in `mean`)
  std::vector<double> keypoint_mean;  // [m] keypoint m's error, mean over the pairs
  std::vector<double> keypoint_self;  // [m] keypoint m's self-map error, mean over the shapes
};

// Any model's correspondence map: points p_unit (N x 3, unit frame of shape
// `from`) with their unit normals -> N x 3 points on shape `to`, its unit frame.
using CorrespondenceMap = std::function<Block<double>(int from, int to, const Block<double>& p_unit,
                                                      const Block<double>& normals)>;

// The paper's metric for `map`: keypoints of every shape I carried to every
// other shape J, the error measured against J's own keypoints (unit frame of J),
// averaged over all ordered pairs. meshes/frames/keypoints per shape of the
// collection, keypoints[i][k] a vertex of meshes[i].
KeypointError keypoint_error(const CorrespondenceMap& map, const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames,
                             const std::vector<std::vector<int>>& keypoints,
                             const std::vector<double>& thresholds = {0.01, 0.02, 0.05, 0.1});

// The same for a joint atlas, its map being correspond() above.
KeypointError keypoint_error(Atlas<float>& atlas, const std::vector<Mesh>& meshes,
                             const std::vector<Normalization>& frames,
                             const std::vector<std::vector<int>>& keypoints,
                             const CorrespondenceOptions& o,
                             const std::vector<double>& thresholds = {0.01, 0.02, 0.05, 0.1});

}  // namespace jsa
