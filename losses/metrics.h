// Reconstruction metrics of the paper's Table 1 (Sec. 4, "Reconstruction
// metrics"), on two sets of M' oriented points (prediction, ground truth):
//  - Chamfer association: each point's nearest neighbour in the other set, in
//    both directions. Spatial = mean distance |p - q| (not squared), averaged
//    over the two directions; Normal = mean |n_p - n_q| of unit normals over the
//    same association. (Table 1 scales normals by alpha = 0.01, so its normal
//    column is alpha times ours.)
#pragma once
#include "engine/block.h"

namespace jsa {

struct SurfaceMetrics {
  double chamfer_spatial = 0;  // mean of both directions of mean nearest-point distance
  double chamfer_normal = 0;   // mean |n_p - n_q| (unit normals) over that association
};

SurfaceMetrics surface_metrics(const Block<double>& pred_points, const Block<double>& pred_normals,
                               const Block<double>& true_points, const Block<double>& true_normals);

}  // namespace jsa
