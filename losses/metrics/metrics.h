// Reconstruction metrics of the paper's Table 1 (Sec. 4, "Reconstruction
// metrics"), on two sets of M' oriented points (prediction, ground truth):
//  - Chamfer association: each point's nearest neighbour in the other set, in
//    both directions. Spatial = mean distance |p - q| (not squared), averaged
//    over the two directions; Normal = mean |n_p - n_q| of unit normals over the
//    same association. (Table 1 scales normals by alpha = 0.01, so its normal
//    column is alpha times ours.)
//  - Back-facing: the fraction of associated pairs whose normals disagree in
//    orientation (n_p . n_q < 0), over both directions. The normal distance
//    mixes orientation errors (a flipped normal costs up to 2) with small
//    angular errors; this separates them (the paper's Fig. 3 colours them).
#pragma once
#include "engine/block.h"

namespace jsa {

struct SurfaceMetrics {
  double chamfer_spatial = 0;  // mean of both directions of mean nearest-point distance
  double chamfer_normal = 0;   // mean |n_p - n_q| (unit normals) over that association
  double back_facing = 0;      // fraction of those pairs with n_p . n_q < 0
};

SurfaceMetrics surface_metrics(const Block<double>& pred_points, const Block<double>& pred_normals,
                               const Block<double>& true_points, const Block<double>& true_normals);

}  // namespace jsa
